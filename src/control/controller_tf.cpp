#include "afmkit/control/controller_tf.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "afmkit/control/loop.hpp"
#include "afmkit/core/validate.hpp"
#include "scaled_dual.hpp"

namespace afmkit::control {

using cplx = std::complex<double>;

namespace {
constexpr cplx kI(0.0, 1.0);
// s² + k²Ω² as (s − ikΩ)(s + ikΩ): exact zero only at the pole, accurate near it.
cplx shifted_square(cplx s, double kw) { return (s - kI * kw) * (s + kI * kw); }
cplx limit_value(const Controller& c, cplx s) { return controller_response(c, s); }
}  // namespace

cplx single_oscillator_tf(double omega, double a, double b, double gain, cplx s) {
  validate::positive("rotation_frequency", omega);
  validate::finite("a", a);
  validate::finite("b", b);
  validate::positive("gain", gain);
  const cplx den = shifted_square(s, omega);
  if (den == 0.0) return {std::numeric_limits<double>::infinity(), 0.0};
  return gain * (a * s - b * omega) / den;
}

TransferFunction single_oscillator_tf(double omega, double a, double b, double gain) {
  validate::positive("rotation_frequency", omega);
  validate::finite("a", a);
  validate::finite("b", b);
  validate::positive("gain", gain);
  return tf({gain * a, -gain * b * omega}, {1.0, 0.0, omega * omega});
}

cplx bank_tf(const OscillatorBank& bank, cplx s) {
  const double w = bank.rotation_frequency();
  cplx num = 0.0, den = 1.0;
  if (bank.a0() != 0.0) {
    if (s == 0.0) return limit_value(bank, s);
    den += bank.a0() / s;
  }
  for (int k = 1; k <= bank.harmonics(); ++k) {
    const cplx q = shifted_square(s, k * w);
    if (q == 0.0) return limit_value(bank, s);
    const cplx h = (bank.a(k) * s - bank.b(k) * k * w) / q;
    if (bank.is_rejected(k)) num += h;
    else den += h;
  }
  return bank.gain() * num / den;
}

cplx couplings_tf(double omega, int n, double alpha, double beta, double gain, cplx s) {
  validate::positive("rotation_frequency", omega);
  validate::in_range("harmonics", static_cast<long>(n), 1L, 100000L);
  validate::finite("alpha", alpha);
  validate::finite("beta", beta);
  validate::positive("gain", gain);
  auto h = [&](int k) { return 2.0 * (alpha * s + beta * omega) / shifted_square(s, k * omega); };  // (26)
  bool singular = s == 0.0;
  for (int k = 1; k <= n && !singular; ++k) singular = shifted_square(s, k * omega) == 0.0;
  if (singular) return limit_value(OscillatorBank::with_couplings(omega, n, alpha, beta, gain), s);
  cplx den = 1.0 + alpha / s;  // 1 + H0 (27)
  for (int k = 2; k <= n; ++k) den += h(k);
  return gain * h(1) / den;
}

Eigen::VectorXcd complex_form_states(const OscillatorBank& bank, cplx s) {
  const int n = bank.harmonics();
  const double w = bank.rotation_frequency();
  Eigen::VectorXcd g(2 * n + 1), dinv_g(2 * n + 1);
  cplx wt_dinv_g = 0.0;
  for (int k = -n; k <= n; ++k) {
    cplx gk;
    if (k == 0) gk = bank.a0();
    else if (k > 0) gk = 0.5 * cplx(bank.a(k), bank.b(k));        // g_k = (a_k + i b_k)/2
    else gk = 0.5 * cplx(bank.a(-k), -bank.b(-k));                 // g_{−k} = g_k*
    g(k + n) = gk;
    dinv_g(k + n) = gk / (s - kI * (k * w));                       // 𝒟^{-1} g (eq. 36)
    const bool kept = k == 0 || !bank.is_rejected(std::abs(k));     // w_k = 1 unless k ∈ ±R
    if (kept) wt_dinv_g += dinv_g(k + n);
  }
  // (37): 𝓜^{-1} g = 𝒟^{-1} g − 𝒟^{-1} g (wᵀ𝒟^{-1} g)/(1 + wᵀ𝒟^{-1} g) = 𝒟^{-1} g /(1 + wᵀ𝒟^{-1} g)
  return dinv_g - dinv_g * (wt_dinv_g / (1.0 + wt_dinv_g));
}

cplx complex_form_tf(const OscillatorBank& bank, cplx s) {
  const int n = bank.harmonics();
  const double w = bank.rotation_frequency();
  for (int k = -n; k <= n; ++k)
    if (s == kI * (k * w)) return limit_value(bank, s);
  const Eigen::VectorXcd h = complex_form_states(bank, s);
  cplx x = 0.0;
  for (int k : bank.rejected()) x += h(k + n) + h(-k + n);  // x_k = η_k + η_{−k}
  return bank.gain() * x;                                    // (38)–(39): U = −K x, C = −U/M
}

cplx qn_tf(double omega, int n, double alpha, double beta, double gain, cplx s) {
  validate::positive("rotation_frequency", omega);
  validate::in_range("harmonics", static_cast<long>(n), 1L, 100000L);
  validate::finite("alpha", alpha);
  validate::finite("beta", beta);
  validate::positive("gain", gain);
  bool singular = s == 0.0;
  for (int k = 1; k <= n && !singular; ++k) singular = shifted_square(s, k * omega) == 0.0;
  if (singular) return limit_value(OscillatorBank::with_couplings(omega, n, alpha, beta, gain), s);
  // Q_N and Q_N' by the product rule (dual numbers), with a common scale.
  detail::Scaled q{detail::Dual::variable(s), 0.0};
  for (int k = 1; k <= n; ++k) {
    const double kw2 = (k * omega) * (k * omega);
    q = q * detail::Dual(shifted_square(s, k * omega) / kw2, 2.0 * s / kw2);
  }
  const cplx log_derivative = q.x.d / q.x.v;  // Q_N'/Q_N
  const cplx h1 = 2.0 * (alpha * s + beta * omega) / shifted_square(s, omega);
  const cplx den = 1.0 + alpha / s + (alpha + beta * omega / s) * (log_derivative - 1.0 / s) - h1;  // (28)
  return gain * h1 / den;
}

namespace {
// coth(w) stable for large |Re w| (eq. 30 with z = e^{−2w} or e^{2w}).
cplx coth(cplx w) {
  if (w.real() >= 0.0) {
    const cplx z = std::exp(-2.0 * w);
    return (1.0 + z) / (1.0 - z);
  }
  const cplx z = std::exp(2.0 * w);
  return -(1.0 + z) / (1.0 - z);
}
bool at_harmonic(cplx s, double omega) {  // s = ikΩ for some integer k (exactly)
  if (s.real() != 0.0) return false;
  const double k = std::round(s.imag() / omega);
  return s.imag() == k * omega;
}
}  // namespace

cplx infinite_tf(const InfiniteBank& bank, cplx s) {
  const double w = bank.rotation_frequency, pi = std::numbers::pi;
  if (at_harmonic(s, w)) return limit_value(bank, s);
  const cplx h1 = 2.0 * (bank.alpha * s + bank.beta * w) / shifted_square(s, w);
  const cplx f = 1.0 + (pi / w) * (bank.alpha + bank.beta * w / s) * coth(pi * s / w) - bank.beta * w / (s * s);
  return bank.gain * h1 / (f - h1);  // (29)
}

cplx infinite_tf_quasi(const InfiniteBank& bank, cplx s) {
  // cancelled double zeros of 𝒜 − ℬe^{−sT} at s = 0, ±iΩ (docs/theory-control.md#infinite-bank): take the limit
  if (at_harmonic(s, bank.rotation_frequency) && std::abs(s.imag()) <= bank.rotation_frequency)
    return limit_value(bank, s);
  const auto a = bank.a_coefficients(), b = bank.b_coefficients();
  const auto n = bank.n_coefficients();
  auto horner = [&](const auto& c) {
    cplx v = 0.0;
    for (auto it = c.rbegin(); it != c.rend(); ++it) v = v * s + *it;
    return v;
  };
  const cplx an = horner(a), bn = horner(b), nn = horner(n);
  const double t = bank.period();
  cplx num, den;
  if (s.real() >= 0.0) {
    const cplx z = std::exp(-s * t);
    num = nn * (1.0 - z);
    den = an - bn * z;
  } else {  // divide by z = e^{−sT} (large)
    const cplx zi = std::exp(s * t);
    num = nn * (zi - 1.0);
    den = an * zi - bn;
  }
  if (den == 0.0) return limit_value(bank, s);  // cancelled zeros at s = 0, ±iΩ (docs/theory-control.md#infinite-bank)
  return num / den;  // (31)
}

}  // namespace afmkit::control
