// Delay-free roots of the seed-2 loop and the bank's eigenvalues without dense matrices (seed-2 eqs. 19, 22;
// docs/theory-control.md#oscillator-bank, #stability-tau0): both are the roots of a polynomial known only through its
// logarithmic derivative, evaluated in O(N) per point from the pole-free forms of loop.hpp, and found all at once by
// the Aberth–Ehrlich iteration started from the first-order root positions ikΩ − g_k (seed-2 eq. 45;
// g_k = (a_k + i b_k)/2, Appendix A eq. 34).
// Cost: O(N) per logarithmic derivative, O(N²) per sweep (the Aberth sums), a few sweeps.
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include <fmt/format.h>

#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/stability_tau0.hpp"
#include "afmkit/core/error.hpp"
#include "bank_sums.hpp"

namespace afmkit::control {

namespace {
using cplx = std::complex<double>;

inline cplx reciprocal(cplx z) {
  const double n = z.real() * z.real() + z.imag() * z.imag();
  return {z.real() / n, -z.imag() / n};
}
inline bool finite(cplx z) { return std::isfinite(z.real()) && std::isfinite(z.imag()); }

// Aberth–Ehrlich (Gauss–Seidel form): z_j ← z_j − 1/(p'/p(z_j) − Σ_{k≠j} 1/(z_j − z_k)). Every root of the
// polynomial p must be represented by one entry of z. Returns false if it did not converge.
template <class LogDerivative>
bool aberth(LogDerivative&& logd, std::vector<cplx>& z, double scale, int max_sweeps = 100) {
  const std::size_t n = z.size();
  std::vector<char> done(n, 0);
  std::vector<double> last(n, INFINITY), re(n), im(n);
  for (std::size_t j = 0; j < n; ++j) re[j] = z[j].real(), im[j] = z[j].imag();
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    bool all = true;
    for (std::size_t j = 0; j < n; ++j) {
      if (done[j]) continue;
      const cplx ld = logd(z[j]);
      const cplx sum = detail::inverse_distance_sum(re.data(), im.data(), j, z[j]) +
                       detail::inverse_distance_sum(re.data() + j + 1, im.data() + j + 1, n - j - 1, z[j]);
      cplx w;
      if (std::isinf(ld.real())) w = 0.0;  // p(z_j) = 0 exactly: a root (p'/p has a pole there)
      else w = reciprocal(ld - sum);
      // not finite: exactly on a pole of one of the partial sums (s = ±ikΩ), where p'/p is finite but its parts
      // are not: nudge
      if (!finite(w)) w = cplx(1e-7 * scale, 1.3e-7 * scale);
      z[j] -= w;
      re[j] = z[j].real();
      im[j] = z[j].imag();
      const double size = std::abs(w), floor = 1e-14 * std::max(scale, std::abs(z[j]));
      // converged: below the rounding floor, or no longer decreasing once small
      if (size <= floor || (size <= 1e-10 * std::max(scale, std::abs(z[j])) && size >= 0.5 * last[j])) done[j] = 1;
      else all = false;
      last[j] = size;
    }
    if (all) return true;
  }
  for (std::size_t j = 0; j < n; ++j)
    if (!done[j] && !(last[j] <= 1e-8 * std::max(scale, std::abs(z[j])))) return false;
  return true;
}

// Seeds: distinct, off the poles of the logarithmic derivative (a deterministic small offset per entry).
void nudge(std::vector<cplx>& z, double omega) {
  for (std::size_t j = 0; j < z.size(); ++j)
    z[j] += 1e-3 * omega * std::polar(1.0, 0.7 + 2.39996 * static_cast<double>(j));
}

struct BankTerms {
  cplx d, dd;   // D = 1 + a0/s + Σ_kept G_k and D'
  cplx n, dn;   // Σ_rejected G_k and its derivative
  cplx lq_all;  // Σ_all 2s/(s² + k²Ω²)
  cplx lq_kept; // Σ_kept 2s/(s² + k²Ω²)
};
BankTerms bank_terms(const detail::SplitBank& b, cplx s) {
  BankTerms t{};
  const cplx inv_s = reciprocal(s);
  const detail::BankSums kept = detail::bank_sums(b.kept, s), rej = detail::bank_sums(b.rejected, s);
  t.d = 1.0 + b.a0 * inv_s + kept.g;  // G_k: eq. (18)
  t.dd = -b.a0 * inv_s * inv_s + kept.a_inv - 2.0 * s * kept.g_inv;
  t.n = rej.g;
  t.dn = rej.a_inv - 2.0 * s * rej.g_inv;
  t.lq_kept = 2.0 * s * kept.inv;
  t.lq_all = t.lq_kept + 2.0 * s * rej.inv;
  return t;
}

const OscillatorBank* plain_bank(const LoopSpec& loop, const SmithPredictor** smith) {
  *smith = std::get_if<SmithPredictor>(&loop.controller);
  const Bank* inner = nullptr;
  if (*smith) inner = &(*smith)->bank;
  if (inner) return std::get_if<OscillatorBank>(inner);
  return std::get_if<OscillatorBank>(&loop.controller);
}
}  // namespace

std::vector<std::complex<double>> bank_eigenvalues(const OscillatorBank& b) {
  const double omega = b.rotation_frequency();
  const bool integrator = b.a0() != 0.0;
  std::vector<cplx> exact, z;
  if (integrator) z.emplace_back(-b.a0(), 0.0);
  for (int k = 1; k <= b.harmonics(); ++k) {
    const cplx ikw(0.0, k * omega);
    if (b.is_rejected(k)) {  // the rejected oscillators do not feed e back: exact eigenvalues ±ikΩ
      exact.push_back(ikw);
      exact.push_back(-ikw);
      continue;
    }
    const cplx g(0.5 * b.a(k), 0.5 * b.b(k));  // eq. (34): root ≈ ikΩ − g_k to first order
    z.push_back(ikw - g);
    z.push_back(-ikw - std::conj(g));
  }
  nudge(z, omega);
  const detail::SplitBank split = detail::split_bank(b);
  // d / Π_rejected q_r = [s] Π_kept q_k · D:  log-derivative [1/s] + Σ_kept 2s/(s² + k²Ω²) + D'/D
  const auto logd = [&](cplx s) {
    const BankTerms t = bank_terms(split, s);
    if (t.d == 0.0) return cplx(INFINITY, 0.0);  // exactly at a root
    return (integrator ? reciprocal(s) : cplx(0.0)) + t.lq_kept + t.dd * reciprocal(t.d);
  };
  if (!aberth(logd, z, omega * (b.harmonics() + 1)))
    throw NumericalFailure(fmt::format("bank eigenvalues: the Aberth iteration did not converge (N = {})",
                                       b.harmonics()));
  z.insert(z.end(), exact.begin(), exact.end());
  return z;
}

std::vector<std::complex<double>> undelayed_poles_secular(const LoopSpec& loop) {
  const SmithPredictor* smith = nullptr;
  const OscillatorBank* b = plain_bank(loop, &smith);
  if (!b) throw InvalidParameter("controller", "controller: the delay-free poles need a finite bank (N = infinity has "
                                               "infinitely many)");
  const double omega = b->rotation_frequency();
  const double rho = loop.gain() / loop.plant_rate;  // Smith: K/γ as well (the model terms cancel at zero delays)
  const bool first_order = loop.plant_kind == PlantKind::FirstOrder;
  const bool integrator = b->a0() != 0.0;
  std::vector<cplx> z;
  if (integrator) z.emplace_back(-b->a0(), 0.0);
  if (first_order) z.emplace_back(-loop.plant_rate, 0.0);
  for (int k = 1; k <= b->harmonics(); ++k) {
    const cplx ikw(0.0, k * omega);
    cplx g(0.5 * b->a(k), 0.5 * b->b(k));
    if (b->is_rejected(k)) g *= rho;
    z.push_back(ikw - g);
    z.push_back(-ikw - std::conj(g));
  }
  nudge(z, omega);
  const detail::SplitBank split = detail::split_bank(*b);
  // Δ(τ = 0) ∝ [s] Π_all q_k · (M D + ρ N), M = 1 or 1 + s/γ
  const auto logd = [&](cplx s) {
    const BankTerms t = bank_terms(split, s);
    const cplx m = first_order ? 1.0 + s / loop.plant_rate : cplx(1.0);
    const double dm = first_order ? 1.0 / loop.plant_rate : 0.0;
    const cplx f = m * t.d + rho * t.n, df = dm * t.d + m * t.dd + rho * t.dn;
    if (f == 0.0) return cplx(INFINITY, 0.0);  // exactly at a root
    return (integrator ? reciprocal(s) : cplx(0.0)) + t.lq_all + df * reciprocal(f);
  };
  if (!aberth(logd, z, omega * (b->harmonics() + 1)))
    throw NumericalFailure(fmt::format("delay-free poles: the Aberth iteration did not converge (N = {})",
                                       b->harmonics()));
  if (smith && smith->model_kind == PlantKind::FirstOrder) z.emplace_back(-smith->model_rate, 0.0);  // M̂ factor
  return z;
}

}  // namespace afmkit::control
