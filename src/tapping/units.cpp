#include "afmkit/tapping/units.hpp"

#include <cmath>
#include <numbers>

#include "afmkit/core/validate.hpp"

namespace afmkit::tapping {

PhysicalCantilever::PhysicalCantilever(double k, double f0, double q, double a_free, double ratio)
    : spring_constant(validate::positive("spring_constant", k)),
      resonance_frequency(validate::positive("resonance_frequency", f0)),
      quality_factor(validate::positive("quality_factor", q)),
      free_amplitude(validate::positive("free_amplitude", a_free)),
      frequency_ratio(validate::positive("frequency_ratio", ratio)) {}

Drive PhysicalCantilever::drive() const {
  const Cantilever c = cantilever();
  const double gain = std::abs(c.transfer({0.0, frequency_ratio}));  // |L(iω)|, ω_n = 1
  return {free_amplitude / gain, frequency_ratio};
}

impact::ForceLaw PhysicalCantilever::normalised_law(const impact::ForceLaw& physical) const {
  return physical.scaled(1.0 / spring_constant, 2.0 * std::numbers::pi * resonance_frequency * 1e3);
}

UnitScales PhysicalCantilever::scales() const {
  UnitScales s;
  s.length = 1.0;
  s.force = spring_constant;
  s.energy = spring_constant;
  s.time = 1.0 / (2.0 * std::numbers::pi * resonance_frequency * 1e3);
  s.length_unit = "nm";
  s.force_unit = "nN";
  s.energy_unit = "aJ";
  s.time_unit = "s";
  return s;
}

}  // namespace afmkit::tapping
