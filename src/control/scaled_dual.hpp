#pragma once
// Private to src/control: forward-mode dual numbers over ℂ (value, d/ds) with a common exponential scale,
// so that Δ(s) and Δ'(s) of the characteristic function can be formed exactly (up to rounding) where the
// value itself would overflow a double. A Scaled x represents (v, d)·e^{ls}.
#include <algorithm>
#include <cmath>
#include <complex>

namespace afmkit::control::detail {

using cplx = std::complex<double>;

struct Dual {
  cplx v{0.0, 0.0};  // value
  cplx d{0.0, 0.0};  // derivative with respect to s
  constexpr Dual() = default;
  constexpr Dual(cplx value, cplx derivative = {0.0, 0.0}) : v(value), d(derivative) {}
  static Dual variable(cplx s) { return {s, 1.0}; }
};

inline Dual operator+(Dual a, Dual b) { return {a.v + b.v, a.d + b.d}; }
inline Dual operator-(Dual a, Dual b) { return {a.v - b.v, a.d - b.d}; }
inline Dual operator-(Dual a) { return {-a.v, -a.d}; }
inline Dual operator*(Dual a, Dual b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
inline Dual operator*(cplx c, Dual a) { return {c * a.v, c * a.d}; }
inline Dual operator*(double c, Dual a) { return {c * a.v, c * a.d}; }
inline Dual operator/(Dual a, Dual b) { return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)}; }
inline Dual operator+(Dual a, cplx c) { return {a.v + c, a.d}; }

/// (v, d)·e^{ls}; ls real.
struct Scaled {
  Dual x;
  double ls = 0.0;
};

/// Renormalise so that max(|v|, |d|) is O(1) when it leaves [1e-100, 1e100].
inline Scaled normalised(Scaled a) {
  const double m = std::max(std::abs(a.x.v), std::abs(a.x.d));
  if (m > 0.0 && std::isfinite(m) && (m > 1e100 || m < 1e-100)) {
    a.x = (1.0 / m) * a.x;
    a.ls += std::log(m);
  }
  return a;
}
inline Scaled operator*(Scaled a, Scaled b) { return normalised({a.x * b.x, a.ls + b.ls}); }
inline Scaled operator*(Scaled a, Dual b) { return normalised({a.x * b, a.ls}); }
inline Scaled operator+(Scaled a, Scaled b) {
  if (a.x.v == 0.0 && a.x.d == 0.0) return b;
  if (b.x.v == 0.0 && b.x.d == 0.0) return a;
  if (a.ls >= b.ls) return normalised({a.x + std::exp(b.ls - a.ls) * b.x, a.ls});
  return normalised({std::exp(a.ls - b.ls) * a.x + b.x, b.ls});
}

/// e^{−sτ} as a Scaled dual: magnitude e^{−τ Re s} kept in the scale.
inline Scaled delay_factor(cplx s, double tau) {
  if (tau == 0.0) return {Dual(1.0, 0.0), 0.0};
  const cplx phase = std::exp(cplx(0.0, -tau * s.imag()));
  return {Dual(phase, -tau * phase), -tau * s.real()};
}

/// Plain value of a Scaled (may overflow to inf).
inline cplx rescale(cplx z, double ls) {
  if (z == 0.0 || ls == 0.0) return z;
  const double m = std::abs(z);
  return (z / m) * std::exp(std::log(m) + ls);
}
inline cplx value_of(const Scaled& a) { return rescale(a.x.v, a.ls); }
inline cplx derivative_of(const Scaled& a) { return rescale(a.x.d, a.ls); }

}  // namespace afmkit::control::detail
