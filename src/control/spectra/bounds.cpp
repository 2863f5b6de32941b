// Root-free regions of Δ(s) (spectrum.hpp: root_bounds) and the neutral-chain bound ln|B4/A4|/T.
//
// Write the zeros of Δ as zeros of f = c_D·D + c_N·N (C = K N/D, loop.hpp):
//   plain loop  c_D = M,     c_N = ρ e^{−sτ}                                  (ρ = K/γ, M = 1 or 1 + s/γ)
//   Smith       c_D = M M̂,   c_N = (K/γ̂) M (1 − e^{−sτ_c}) + ρ M̂ e^{−s(τ_m+τ)}
// so |c_N/c_D| ≤ κ with κ from |e^{−sτ}| = e^{−τ Re s} and |γ + s| ≥ max(|Im s|, γ + Re s).
// Finite bank: D = 1 + a0/s + Σ_{k kept} G_k, N = Σ_{k rejected} G_k, G_k = (a_k s − b_k kΩ)/(s² + k²Ω²):
//   Re s ≥ σ > 0:          |G_k| ≤ |a_k|/σ + |b_k| kΩ/σ²
//   |s| ≥ r > kΩ:          |G_k| ≤ (|a_k| r + |b_k| kΩ)/(r − kΩ)²   (decreasing in r)
// and f ≠ 0 where 1 − Σ_kept − |a0|/|s| > κ Σ_rejected.
// N = ∞ bank (u = πs/Ω, x = Re u, L = αs + βΩ), Δ ∝ c_D [main + P1] + c_N P2 with
//   main = (Ω/π) sinh u + α cosh u = ½ e^u (Ω/π + α)(1 − R e^{−2u}),  R = B4/A4,
//   P1 = πβ φ(u) − (2π/Ω) L ψ(u),  P2 = (2π/Ω) L ψ(u),  φ = (u cosh u − sinh u)/u²,  ψ = sinh u/(u² + π²);
//   |main|/cosh x ≥ |Ω/π + α| (1 − |R| e^{−2x})/(1 + e^{−2x})  (increasing in x, valid right of the chain),
//   |φ|/cosh x ≤ 1/|u| + 1/|u|²,  |ψ|/cosh x ≤ 1/(|u|² − π²).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "afmkit/core/numbers.hpp"
#include "spectra_detail.hpp"

namespace afmkit::control {

using spectra_detail::LoopView;

namespace {
using afmkit::numbers::infinity;

double inv_plant_factor(PlantKind kind, double rate, double re_min, double im_abs_min) {
  if (kind == PlantKind::Static) return 1.0;
  const double lower = std::max(im_abs_min, rate + re_min);  // |γ + s| ≥ …
  return lower > 0.0 ? rate / lower : infinity;
}

// Upper bound of |c_N/c_D| for Re s ≥ re_min, |Im s| ≥ im_abs_min.
double kappa(const LoopSpec& loop, const LoopView& v, double re_min, double im_abs_min) {
  const double rho = loop.gain_ratio();
  const double inv_m = inv_plant_factor(loop.plant_kind, loop.plant_rate, re_min, im_abs_min);
  if (!v.smith) return rho * std::exp(-re_min * loop.delay) * inv_m;
  const SmithPredictor& sp = *v.smith;
  const double inv_mh = inv_plant_factor(sp.model_kind, sp.model_rate, re_min, im_abs_min);
  return sp.gain() / sp.model_rate * (1.0 + std::exp(-re_min * sp.correction_delay())) * inv_mh +
         rho * std::exp(-re_min * (sp.measurement_delay() + loop.delay)) * inv_m;
}

// Finite bank: true if f has no zero in {Re s ≥ sigma} (half_plane) or {|s| ≥ r, Re s ≥ sigma, |Im s| ≥ r}.
bool finite_root_free(const LoopSpec& loop, const LoopView& v, double sigma, double r, bool half_plane) {
  const OscillatorBank& b = *v.bank;
  const double omega = b.rotation_frequency();
  double kept = 0.0, rej = 0.0;
  for (int k = 1; k <= b.harmonics(); ++k) {
    const double ak = std::abs(b.a(k)), bk = std::abs(b.b(k)) * k * omega;
    double g;
    if (half_plane) {
      g = ak / sigma + bk / (sigma * sigma);
    } else {
      if (r <= k * omega) return false;
      g = (ak * r + bk) / ((r - k * omega) * (r - k * omega));
    }
    (b.is_rejected(k) ? rej : kept) += g;
  }
  const double a0 = std::abs(b.a0()) / (half_plane ? sigma : r);
  const double kap = half_plane ? kappa(loop, v, sigma, 0.0) : kappa(loop, v, sigma, r);
  return 1.0 - kept - a0 > kap * rej;
}

bool infinite_root_free(const LoopSpec& loop, const LoopView& v, double sigma, double r, bool half_plane) {
  const InfiniteBank& b = *v.infinite;
  const double omega = b.rotation_frequency, pi = std::numbers::pi;
  const double a4 = 1.0 + pi * b.alpha / omega, b4 = 1.0 - pi * b.alpha / omega;
  if (a4 == 0.0) return false;
  const double rr = std::abs(b4 / a4);
  const double x = pi * sigma / omega;
  const double y = std::exp(-2.0 * x);
  if (rr * y >= 1.0) return false;
  const double main = std::abs(omega / pi + b.alpha) * (1.0 - rr * y) / (1.0 + y);
  const double u = half_plane ? x : pi * r / omega;
  if (u <= pi) return false;
  const double lb = std::abs(b.alpha) * (omega / pi) * u + std::abs(b.beta) * omega;
  const double psi = 1.0 / (u * u - pi * pi);
  const double p1 = pi * std::abs(b.beta) * (1.0 / u + 1.0 / (u * u)) + (2.0 * pi / omega) * lb * psi;
  const double p2 = (2.0 * pi / omega) * lb * psi;
  const double kap = half_plane ? kappa(loop, v, sigma, 0.0) : kappa(loop, v, sigma, r);
  return main - p1 > kap * p2;
}

bool root_free(const LoopSpec& loop, const LoopView& v, double sigma, double r, bool half_plane) {
  return v.bank ? finite_root_free(loop, v, sigma, r, half_plane) : infinite_root_free(loop, v, sigma, r, half_plane);
}

// Smallest x in [x0, x_cap] (to ~2 %) with pred(x) true, assuming pred is monotone; NaN if none.
template <class P>
double monotone_threshold(P&& pred, double x0, double x_cap) {
  double hi = x0;
  while (!pred(hi)) {
    hi *= 2.0;
    if (hi > x_cap) return std::numeric_limits<double>::quiet_NaN();
  }
  double lo = hi == x0 ? x0 : 0.5 * hi;
  if (lo == hi) return hi;
  for (int i = 0; i < 8; ++i) {
    const double mid = 0.5 * (lo + hi);
    (pred(mid) ? hi : lo) = mid;
  }
  return hi;
}
}  // namespace

std::optional<double> neutral_spectrum_bound(const LoopSpec& loop) {
  const LoopView v = spectra_detail::view(loop);
  if (!v.infinite) return std::nullopt;
  const double pi = std::numbers::pi, omega = v.infinite->rotation_frequency;
  const double a4 = 1.0 + pi * v.infinite->alpha / omega, b4 = 1.0 - pi * v.infinite->alpha / omega;
  if (a4 == 0.0) return infinity;
  if (b4 == 0.0) return -infinity;
  return std::log(std::abs(b4 / a4)) / (2.0 * pi / omega);
}

RootBounds root_bounds(const LoopSpec& loop, double min_real) {
  const LoopView v = spectra_detail::view(loop);
  const double omega = v.omega;
  RootBounds out;
  out.real_max = out.imag_max = std::numeric_limits<double>::quiet_NaN();
  if (!std::isfinite(min_real)) return out;
  const double x0 = std::max({min_real, 0.0}) + 0.25 * omega;
  // the half-plane test is monotone in σ (all bounds decrease)
  const double sigma_max = monotone_threshold(
      [&](double s) { return root_free(loop, v, s, 0.0, true); }, x0, 1e7 * omega);
  if (!std::isnan(sigma_max)) {
    int kmax = v.bank ? v.bank->harmonics() : 1;
    const double r0 = (kmax + 1) * omega;
    const double w = monotone_threshold([&](double r) { return root_free(loop, v, min_real, r, false); }, r0,
                                        1e8 * omega);
    if (!std::isnan(w)) {
      out.real_max = std::max(sigma_max, min_real + 0.25 * omega);
      out.imag_max = w;
      out.proven = true;
    }
  }
  return out;
}

}  // namespace afmkit::control
