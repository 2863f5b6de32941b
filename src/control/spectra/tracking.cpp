#include "tracking.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "afmkit/control/dde_collocation.hpp"
#include "afmkit/control/spectrum.hpp"
#include "spectra_detail.hpp"

namespace afmkit::control::spectra_detail {

double TrackedSpectrum::abscissa() const {
  double a = neutral_bound.value_or(-INFINITY);
  for (const auto& r : roots) a = std::max(a, r.real());
  return a;
}

int TrackedSpectrum::unstable() const {
  if (neutral_bound && *neutral_bound >= 0.0) return -1;
  int n = 0;
  for (const auto& r : roots)
    if (r.real() > 0.0) n += r.imag() > 0.0 ? 2 : 1;
  return n;
}

bool RootTracker::refine(const FastCharacteristic& f, cplx& s) const {
  const double omega = f.rotation_frequency();
  const double tol2 = tolerance_ * tolerance_;
  for (int it = 0; it < 40; ++it) {
    cplx step = f.newton_step(s);
    if (!(std::isfinite(step.real()) && std::isfinite(step.imag()))) return false;
    const double s2 = std::norm(s), st2 = std::norm(step);
    const double limit = 0.5 * (omega + std::sqrt(s2));
    if (st2 > limit * limit) step *= limit / std::sqrt(st2);
    s -= step;
    if (st2 <= tol2 * std::max(omega * omega, s2)) return s2 < 1e8 * omega * omega;
  }
  return false;
}

void RootTracker::finish(std::vector<cplx>& roots, double omega) const {
  std::sort(roots.begin(), roots.end(), [](cplx a, cplx b) { return a.real() > b.real(); });
  std::vector<cplx> out;
  out.reserve(roots.size());
  for (cplx s : roots) {
    if (out.size() >= static_cast<std::size_t>(keep_)) break;
    add_unique(out, s, 1e-7 * std::max(omega, std::abs(s)));
  }
  roots.swap(out);
}

void RootTracker::add_seeds(const LoopSpec& loop, std::vector<cplx>& starts) const {
  const LoopView v = view(loop);
  const double omega = v.omega;
  if (v.infinite) {
    const double alpha = v.infinite->alpha, beta = v.infinite->beta;
    starts.emplace_back(-alpha, 0.0);
    for (int k = 1; k <= 12; ++k) starts.emplace_back(-alpha, k * omega + beta / k);  // eq. (45)
    const auto bound = neutral_spectrum_bound(loop);
    if (bound && std::isfinite(*bound)) {
      const double half = std::abs(alpha) > omega / std::numbers::pi ? 0.5 : 0.0;  // B4/A4 < 0
      for (int m = 0; m <= 12; ++m) starts.emplace_back(*bound + 0.01 * omega, (m + half) * omega);
    }
  } else {
    const double shift = 0.02 * omega;
    if (v.bank->a0() != 0.0) starts.emplace_back(-shift, 0.0);
    // both ends of the bank: the low harmonics meet the plant and the delay, the top ones are the least damped
    // at large N (the edge of the coupling sum; e.g. N = 1000: Re s ≈ −0.03Ω at k = N, ≈ −α in the middle)
    const int n = v.bank->harmonics();
    for (int k = 1; k <= std::min(n, 16); ++k) starts.emplace_back(-shift, k * omega);
    for (int k = std::max(17, n - 15); k <= n; ++k) starts.emplace_back(-shift, k * omega);
  }
}

TrackedSpectrum RootTracker::update(const LoopSpec& loop, const TrackedSpectrum& previous, bool with_seeds) const {
  const FastCharacteristic f(loop);
  const double omega = f.rotation_frequency();
  std::vector<cplx> starts = previous.roots;
  if (with_seeds) add_seeds(loop, starts);
  TrackedSpectrum out;
  out.neutral_bound = neutral_spectrum_bound(loop);
  out.omega = omega;
  out.roots.reserve(starts.size());
  for (cplx s : starts) {
    // start real roots slightly off the axis so that a colliding pair can leave the real axis
    if (std::abs(s.imag()) < 1e-9 * std::max(omega, std::abs(s))) s += cplx(0.0, 1e-3 * omega);
    if (!refine(f, s)) continue;
    if (std::abs(s.imag()) < 1e-9 * std::max(omega, std::abs(s))) s = s.real();
    if (s.imag() < 0.0) s = std::conj(s);
    out.roots.push_back(s);
  }
  finish(out.roots, omega);
  return out;
}

TrackedSpectrum RootTracker::merge(const TrackedSpectrum& a, const TrackedSpectrum& b) const {
  TrackedSpectrum out;
  out.neutral_bound = a.neutral_bound ? a.neutral_bound : b.neutral_bound;
  out.roots = a.roots;
  out.roots.insert(out.roots.end(), b.roots.begin(), b.roots.end());
  out.omega = a.omega;
  finish(out.roots, out.omega);
  return out;
}

TrackedSpectrum RootTracker::initial(const LoopSpec& loop) const {
  const LoopView v = view(loop);
  TrackedSpectrum start;
  if (v.bank && v.bank->harmonics() > kCollocationMaxHarmonics) {
    start.roots = delay_free_continuation(Evaluator(loop), tolerance_, static_cast<std::size_t>(4 * keep_));
    std::sort(start.roots.begin(), start.roots.end(), [](cplx a, cplx b) { return a.real() > b.real(); });
    if (start.roots.size() > static_cast<std::size_t>(3 * keep_)) start.roots.resize(3 * keep_);
  } else if (v.bank) {
    const double scale = (v.bank->harmonics() + 3) * v.omega;
    const auto ev = collocation_eigenvalues(closed_loop_dde(loop), 0, scale);
    for (cplx e : ev)
      if (e.imag() >= -1e-9 * v.omega && std::abs(e) < 4.0 * scale) start.roots.push_back(e);
    std::sort(start.roots.begin(), start.roots.end(), [](cplx a, cplx b) { return a.real() > b.real(); });
    if (start.roots.size() > static_cast<std::size_t>(3 * keep_)) start.roots.resize(3 * keep_);
  } else {
    SpectrumOptions o;
    o.multiplicities = false;
    const Spectrum sp = rightmost_roots(loop, o);
    for (const auto& r : sp.roots)
      if (r.value.imag() >= 0.0) start.roots.push_back(r.value);
  }
  return update(loop, start, true);
}

}  // namespace afmkit::control::spectra_detail
