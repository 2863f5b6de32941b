#pragma once
// e^{iu} for the small angles of the drive clock (the adaptive stepper's steps, the observer's quadrature panels):
// the Taylor series of cos u and sin u to degree 16/17, below 1e-19 for |u| ≤ small_angle_limit — cheaper than
// std::cos/std::sin and exact to rounding there.
#include <cmath>
#include <complex>

namespace afmkit::tapping::detail {

inline constexpr double small_angle_limit = 0.35;

/// cos u + i sin u for |u| ≤ small_angle_limit (Horner in u²; beyond it the series is not accurate: callers fall
/// back to the library functions).
inline std::complex<double> small_angle_phasor(double u) {
  const double u2 = u * u;
  // C(u) = Σ (−u²)^k/(2k)!, S(u) = u Σ (−u²)^k/(2k+1)!, k ≤ 8
  double c = 1.0 / 20922789888000.0, s = 1.0 / 355687428096000.0;  // 1/16!, 1/17!
  constexpr double even[8] = {1.0 / 87178291200.0, 1.0 / 479001600.0, 1.0 / 3628800.0, 1.0 / 40320.0,
                              1.0 / 720.0,         1.0 / 24.0,        1.0 / 2.0,       1.0};
  constexpr double odd[8] = {1.0 / 1307674368000.0, 1.0 / 6227020800.0, 1.0 / 39916800.0, 1.0 / 362880.0,
                             1.0 / 5040.0,          1.0 / 120.0,        1.0 / 6.0,        1.0};
  for (int k = 0; k < 8; ++k) {
    c = even[k] - u2 * c;
    s = odd[k] - u2 * s;
  }
  return {c, u * s};
}

/// cos u + i sin u for |u| ≤ stage_angle_limit, the rotations of a step's stages from its middle (|u| ≤ ωh/2):
/// the series to degree 12/13 (below 1e-19 there), two Horner steps fewer than small_angle_phasor.
inline constexpr double stage_angle_limit = 0.27;
inline std::complex<double> stage_angle_phasor(double u) {
  const double u2 = u * u;
  double c = 1.0 / 479001600.0, s = 1.0 / 6227020800.0;  // 1/12!, 1/13!
  constexpr double even[6] = {1.0 / 3628800.0, 1.0 / 40320.0, 1.0 / 720.0, 1.0 / 24.0, 1.0 / 2.0, 1.0};
  constexpr double odd[6] = {1.0 / 39916800.0, 1.0 / 362880.0, 1.0 / 5040.0, 1.0 / 120.0, 1.0 / 6.0, 1.0};
  for (int k = 0; k < 6; ++k) {
    c = even[k] - u2 * c;
    s = odd[k] - u2 * s;
  }
  return {c, u * s};
}

/// e^{iu} for any u: the stages' series within stage_angle_limit, std::polar beyond (the image engine's lock-in and
/// the orbit analysis both rotate by the stages' offsets from a step's middle).
inline std::complex<double> stage_rotation(double u) {
  if (!(std::abs(u) <= stage_angle_limit)) return std::polar(1.0, u);
  return stage_angle_phasor(u);
}

}  // namespace afmkit::tapping::detail
