// Diagnosis of docs/theory-control.md#neutral-realisation: roots of the neutral realisation (32)–(33) of the N = ∞
// controller that are not poles of the reduced closed loop. The realisation's characteristic quasi-polynomial (seed-2
// eq. 31 coefficients of InfiniteBank)
//   Δ_N = c_D (𝒜 − ℬ e^{−sT}) + c_N 𝒩 (1 − e^{−sT})
// (plain loop: c_D = M, c_N = e^{−sτ}/γ; Smith: c_D = M M̂, c_N = M(1 − e^{−sτ_c})/γ̂ + M̂ e^{−s(τ_m+τ)}/γ)
// is compared with the reduced Δ of loop.hpp by counting the zeros of both in small boxes around 0 and ±iΩ:
// the difference of the counts is the multiplicity of the structural root.
#include <array>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "spectra_detail.hpp"

namespace afmkit::control {

using spectra_detail::cplx;
using spectra_detail::Eval;

namespace {
// value and derivative of a polynomial Σ c_j s^j
template <std::size_t N>
Eval poly(const std::array<double, N>& c, cplx s) {
  cplx v = 0.0, d = 0.0;
  for (std::size_t j = N; j-- > 0;) {
    d = d * s + v;
    v = v * s + c[j];
  }
  return {v, d};
}
Eval mul(Eval a, Eval b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
Eval add(Eval a, Eval b) { return {a.v + b.v, a.d + b.d}; }
Eval scale(double c, Eval a) { return {c * a.v, c * a.d}; }
Eval expo(cplx s, double tau) {  // e^{−sτ}
  const cplx e = std::exp(-s * tau);
  return {e, -tau * e};
}
Eval plant(PlantKind kind, double rate, cplx s) {
  if (kind == PlantKind::Static) return {1.0, 0.0};
  return {1.0 + s / rate, 1.0 / rate};
}

Eval realisation(const LoopSpec& loop, const InfiniteBank& bank, const SmithPredictor* sp, cplx s) {
  const double period = bank.period();
  const Eval z = expo(s, period);
  const Eval a = poly(bank.a_coefficients(), s), b = poly(bank.b_coefficients(), s), n = poly(bank.n_coefficients(), s);
  const Eval den = add(a, scale(-1.0, mul(b, z)));               // 𝒜 − ℬ e^{−sT}
  const Eval num = mul(n, add(Eval{1.0, 0.0}, scale(-1.0, z)));  // 𝒩 (1 − e^{−sT})
  const Eval m = plant(loop.plant_kind, loop.plant_rate, s);
  if (!sp) return add(mul(m, den), mul(scale(1.0 / loop.plant_rate, expo(s, loop.delay)), num));
  const Eval mh = plant(sp->model_kind, sp->model_rate, s);
  const Eval corr = scale(1.0 / sp->model_rate, mul(m, add(Eval{1.0, 0.0}, scale(-1.0, expo(s, sp->correction_delay())))));
  const Eval meas = scale(1.0 / loop.plant_rate, mul(mh, expo(s, sp->measurement_delay() + loop.delay)));
  return add(mul(mul(m, mh), den), mul(add(corr, meas), num));
}
}  // namespace

std::vector<StructuralRoot> neutral_realisation_roots(const LoopSpec& loop) {
  const auto v = spectra_detail::view(loop);
  std::vector<StructuralRoot> out;
  if (!v.infinite) return out;
  const double omega = v.omega;
  const auto f = [&](cplx s) { return realisation(loop, *v.infinite, v.smith, s); };
  const spectra_detail::Evaluator reduced(loop);
  for (const cplx centre : {cplx(0.0, 0.0), cplx(0.0, omega), cplx(0.0, -omega)}) {
    double r = 0.0123 * omega;
    for (int attempt = 0; attempt < 6; ++attempt, r *= 0.61) {
      const Box box{centre.real() - r, centre.real() + 1.07 * r, centre.imag() - 0.93 * r, centre.imag() + r};
      const auto wn = spectra_detail::winding(f, box, omega);
      const auto wr = spectra_detail::winding(reduced, box);
      if (!wn.ok || !wr.ok) continue;
      const int m = wn.count - wr.count;
      if (m > 0) {
        out.push_back({centre, m,
                       fmt::format("neutral realisation (32)-(33): cancelled factor s^2(s^2+Omega^2) of "
                                   "C_inf = N(1-e^(-sT))/(A-B e^(-sT)) (seed-2 eq. 31, docs/theory-control.md#neutral-realisation); "
                                   "root on the imaginary "
                                   "axis, multiplicity {} by the argument principle: marginal stability",
                                   m)});
      }
      break;
    }
  }
  return out;
}

}  // namespace afmkit::control
