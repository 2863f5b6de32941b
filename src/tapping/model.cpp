#include "afmkit/tapping/model.hpp"

#include <cmath>
#include <numbers>

#include "afmkit/core/validate.hpp"

namespace afmkit::tapping {

Cantilever::Cantilever(double wn, double q)
    : natural_frequency(validate::positive("natural_frequency", wn)),
      quality_factor(validate::positive("quality_factor", q)) {}

std::complex<double> Cantilever::transfer(std::complex<double> s) const {
  const double wn = natural_frequency;
  return 1.0 / (s * s + 2.0 * damping_ratio() * wn * s + wn * wn);
}

Drive::Drive(double a, double w)
    : amplitude(validate::positive("drive_amplitude", a)), frequency(validate::positive("drive_frequency", w)) {}

double Drive::period() const { return 2.0 * std::numbers::pi / frequency; }

TappingModel::TappingModel(Cantilever c, Drive d, impact::ForceLaw f, double l)
    : cantilever(c), drive(d), law(std::move(f)), separation(validate::finite("separation", l)) {}

double TappingModel::free_amplitude() const {
  return drive.amplitude * std::abs(cantilever.transfer({0.0, drive.frequency}));
}

TappingModel TappingModel::with_separation(double l) const {
  TappingModel m = *this;
  m.separation = validate::finite("separation", l);
  return m;
}

}  // namespace afmkit::tapping
