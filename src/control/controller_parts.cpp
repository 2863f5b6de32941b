#include "controller_parts.hpp"

#include <cmath>
#include <limits>
#include <numbers>

namespace afmkit::control::detail {

namespace {
constexpr double kSeriesRadius = 0.5;

// φ(w) and φ'(w) by series: φ = Σ_{n≥1} 2n/(2n+1)! w^{2n−1}.
void phi_series(cplx w, cplx& value, cplx& derivative) {
  const cplx w2 = w * w;
  cplx term = 1.0;  // w^{2n−2}
  double fact = 6.0; // (2n+1)!
  value = 0.0;
  derivative = 0.0;
  for (int n = 1; n <= 14; ++n) {
    const double c = 2.0 * n / fact;
    derivative += c * (2.0 * n - 1.0) * term;  // d/dw w^{2n−1}
    value += c * term * w;
    term *= w2;
    fact *= (2.0 * n + 2.0) * (2.0 * n + 3.0);
  }
}
cplx sinhc_series(cplx w) {
  const cplx w2 = w * w;
  cplx term = 1.0, sum = 0.0;
  double fact = 1.0;
  for (int n = 0; n <= 14; ++n) {
    sum += term / fact;
    term *= w2;
    fact *= (2.0 * n + 2.0) * (2.0 * n + 3.0);
  }
  return sum;
}
}  // namespace

Dual phi(Dual w) {
  cplx v, dv;
  if (std::abs(w.v) < kSeriesRadius) {
    phi_series(w.v, v, dv);
  } else {
    const cplx sh = std::sinh(w.v), ch = std::cosh(w.v);
    v = (w.v * ch - sh) / (w.v * w.v);
    dv = sh / w.v - 2.0 * v / w.v;
  }
  return {v, dv * w.d};
}

Dual chi(Dual x) {
  // χ(x) = coth x − 1/x = Σ_{n≥1} 2^{2n} B_{2n} x^{2n−1}/(2n)!  (|x| < π), χ'(x) = 1 − coth²x + 1/x²
  cplx v, dv;
  if (std::abs(x.v) < kSeriesRadius) {
    static constexpr double bern[12] = {1.0 / 6,        -1.0 / 30,          1.0 / 42,      -1.0 / 30,
                                        5.0 / 66,       -691.0 / 2730,      7.0 / 6,       -3617.0 / 510,
                                        43867.0 / 798,  -174611.0 / 330,    854513.0 / 138, -236364091.0 / 2730};
    const cplx x2 = x.v * x.v;
    cplx pw = 1.0;  // x^{2n−2}
    double fact = 2.0, two_pow = 4.0;  // (2n)!, 2^{2n}
    v = 0.0;
    dv = 0.0;
    for (int n = 1; n <= 12; ++n) {
      const double c = two_pow * bern[n - 1] / fact;
      v += c * pw * x.v;
      dv += c * (2.0 * n - 1.0) * pw;
      pw *= x2;
      fact *= (2.0 * n + 1.0) * (2.0 * n + 2.0);
      two_pow *= 4.0;
    }
  } else {
    const cplx ct = std::cosh(x.v) / std::sinh(x.v);
    v = ct - 1.0 / x.v;
    dv = 1.0 - ct * ct + 1.0 / (x.v * x.v);
  }
  return {v, dv * x.d};
}

Dual sinhc(Dual w) {
  cplx v;
  if (std::abs(w.v) < kSeriesRadius) v = sinhc_series(w.v);
  else v = std::sinh(w.v) / w.v;
  return {v, phi(Dual(w.v, 1.0)).v * w.d};
}

BankParts bank_parts(const OscillatorBank& bank, cplx s) {
  const double omega = bank.rotation_frequency();
  const bool drop_integrator = bank.a0() == 0.0;  // x0 disconnected: divide d and kn by s
  Dual p(1.0), s_keep(0.0), s_rej(0.0);
  double ls = 0.0;
  for (int k = 1; k <= bank.harmonics(); ++k) {
    const double kw2 = (k * omega) * (k * omega);
    const cplx ikw(0.0, k * omega);
    const Dual q((s - ikw) * (s + ikw) / kw2, 2.0 * s / kw2);  // q_k = 1 + s²/(k²Ω²), exact zero at ±ikΩ
    const double ak = bank.a(k), bk = bank.b(k);
    // ℓ_k = s (a_k s − b_k kΩ)/(k²Ω²), or ℓ_k/s without the integrator
    const Dual l = drop_integrator ? Dual((ak * s - bk * k * omega) / kw2, ak / kw2)
                                   : Dual(s * (ak * s - bk * k * omega) / kw2, (2.0 * ak * s - bk * k * omega) / kw2);
    if (bank.is_rejected(k)) {
      s_rej = s_rej * q + l * p;
      s_keep = s_keep * q;
    } else {
      s_keep = s_keep * q + l * p;
      s_rej = s_rej * q;
    }
    p = p * q;
    auto l1 = [](cplx z) { return std::abs(z.real()) + std::abs(z.imag()); };  // cheap size measure
    const double m = std::max({l1(p.v), l1(p.d), l1(s_keep.v), l1(s_keep.d), l1(s_rej.v), l1(s_rej.d)});
    if (m > 1e100 || (m > 0.0 && m < 1e-100)) {
      const double inv = 1.0 / m;
      p = inv * p;
      s_keep = inv * s_keep;
      s_rej = inv * s_rej;
      ls += std::log(m);
    }
  }
  BankParts out;
  out.d = (drop_integrator ? p : (Dual::variable(s) + cplx(bank.a0())) * p) + s_keep;
  out.kn = bank.gain() * s_rej;
  out.ls = ls;
  return out;
}

BankParts bank_parts(const InfiniteBank& bank, cplx s) {
  const double omega = bank.rotation_frequency, alpha = bank.alpha, beta = bank.beta;
  const double pi = std::numbers::pi;
  const Dual w(pi * s / omega, pi / omega);
  const double r = std::abs(w.v.real());
  Dual sh, ch, ph;
  double ls = 0.0;
  if (r <= 30.0) {
    sh = Dual(std::sinh(w.v), std::cosh(w.v) * w.d);
    ch = Dual(std::cosh(w.v), std::sinh(w.v) * w.d);
    ph = phi(w);
  } else {  // scaled by e^{−r}
    ls = r;
    const cplx ep = std::exp(w.v - r), em = std::exp(-w.v - r);
    const cplx shs = 0.5 * (ep - em), chs = 0.5 * (ep + em);
    sh = Dual(shs, chs * w.d);
    ch = Dual(chs, shs * w.d);
    const cplx v = (w.v * chs - shs) / (w.v * w.v);
    ph = Dual(v, (shs / w.v - 2.0 * v / w.v) * w.d);
  }
  const Dual q_inf = (omega / pi) * sh;  // Q∞ = (Ω/π) sinh(πs/Ω)
  const Dual h(2.0 * (alpha * s + beta * omega), 2.0 * alpha);  // numerator of H1
  const Dual sv = Dual::variable(s);
  const cplx iw(0.0, omega);
  BankParts out;
  out.ls = ls;
  // Near s = ±iΩ: Q∞ has a simple zero and F∞ − H1 is regular but is a difference of two poles in the
  // literal form; with δ = s ∓ iΩ, x = πδ/Ω (coth has period iπ):
  //   Q∞ = −(Ω/π) sinh x,   σ = Q∞/(s² + Ω²) = −sinhc(x)/(s ± iΩ),
  //   F∞ − H1 = 1 − βΩ/s² − (αs + βΩ)/(s(s ± iΩ)) + (α + βΩ/s)(π/Ω) χ(x),   χ(x) = coth x − 1/x.
  for (const cplx centre : {iw, -iw}) {
    if (std::abs(s - centre) < 0.25 * omega) {
      const Dual x(pi * (s - centre) / omega, pi / omega);
      const Dual q_near = (-omega / pi) * Dual(std::sinh(x.v), std::cosh(x.v) * x.d);
      const Dual sigma = -sinhc(x) / (sv + centre);
      const Dual lin = alpha * sv + cplx(beta * omega);
      const Dual regular = Dual(1.0) - Dual(beta * omega) / (sv * sv) - lin / (sv * (sv + centre)) +
                           (pi / omega) * ((Dual(alpha) + Dual(beta * omega) / sv) * chi(x));
      out.d = q_near * regular;
      out.kn = bank.gain * (h * sigma);
      return out;
    }
  }
  const Dual sigma = q_inf / Dual(s * s + omega * omega, 2.0 * s);  // σ = Q∞/(s² + Ω²)
  out.d = q_inf + alpha * ch + (beta * pi) * ph - h * sigma;  // Q∞ (F∞ − H1), φ-form regular at s = 0
  out.kn = bank.gain * (h * sigma);
  return out;
}

BankParts bank_parts(const Bank& bank, cplx s) {
  return std::visit([&](const auto& b) { return bank_parts(b, s); }, bank);
}

cplx ratio(const Dual& num, const Dual& den) {
  if (den.v == 0.0) {
    if (num.v == 0.0) return num.d / den.d;  // common simple zero (degenerate banks)
    return {std::numeric_limits<double>::infinity(), 0.0};
  }
  return num.v / den.v;
}

}  // namespace afmkit::control::detail
