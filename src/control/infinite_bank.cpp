#include "afmkit/control/infinite_bank.hpp"

#include <numbers>

#include "afmkit/core/validate.hpp"

namespace afmkit::control {

InfiniteBank::InfiniteBank(double omega, double a, double b, double k)
    : rotation_frequency(validate::positive("rotation_frequency", omega)),
      alpha(validate::finite("alpha", a)),
      beta(validate::finite("beta", b)),
      gain(validate::positive("gain", k)) {}

double InfiniteBank::period() const { return 2.0 * std::numbers::pi / rotation_frequency; }

std::array<double, 5> InfiniteBank::a_coefficients() const {
  const double w = rotation_frequency, pi = std::numbers::pi;
  return {-beta * w * w * w, pi * beta * w * w, w * w + pi * alpha * w - 3.0 * beta * w, pi * beta - 2.0 * alpha,
          1.0 + pi * alpha / w};
}

std::array<double, 5> InfiniteBank::b_coefficients() const {
  const double w = rotation_frequency, pi = std::numbers::pi;
  return {-beta * w * w * w, -pi * beta * w * w, w * w - pi * alpha * w - 3.0 * beta * w, -pi * beta - 2.0 * alpha,
          1.0 - pi * alpha / w};
}

std::array<double, 4> InfiniteBank::n_coefficients() const {
  return {0.0, 0.0, 2.0 * gain * beta * rotation_frequency, 2.0 * gain * alpha};
}

double InfiniteBank::neutral_ratio() const {
  const double w = rotation_frequency, pi = std::numbers::pi;
  return (w - pi * alpha) / (w + pi * alpha);
}

}  // namespace afmkit::control
