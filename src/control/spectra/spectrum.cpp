// Rightmost roots with certification (spectrum.hpp).
#include "afmkit/control/spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/control/dde_collocation.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/computed.hpp"
#include "afmkit/core/validate.hpp"
#include "spectra_detail.hpp"

namespace afmkit::control {

using spectra_detail::cplx;

namespace {

void check_options(const SpectrumOptions& o) {
  if (!std::isnan(o.min_real)) validate::finite("min_real", o.min_real);
  if (!std::isnan(o.max_imag)) validate::positive("max_imag", o.max_imag);
  validate::positive("max_imag_cap_periods", o.max_imag_cap_periods);
  validate::in_range("count", static_cast<long>(o.count), 1L, 10000L);
  validate::in_range("collocation_nodes", static_cast<long>(o.collocation_nodes), 0L, 400L);
  validate::in_range("tolerance", o.tolerance, 1e-15, 1e-3);
}

bool in_box(const Box& b, cplx s) {
  return s.real() >= b.real_min && s.real() <= b.real_max && s.imag() >= b.imag_min && s.imag() <= b.imag_max;
}

// Newton-refined collocation eigenvalues (finite banks): upper half-plane and real axis, distinct.
std::vector<cplx> collocation_candidates(const LoopSpec& loop, const SpectrumOptions& o) {
  const auto v = spectra_detail::view(loop);
  const double omega = v.omega;
  if (v.bank->harmonics() > spectra_detail::kCollocationMaxHarmonics)
    return spectra_detail::delay_free_continuation(spectra_detail::Evaluator(loop), o.tolerance);
  const double scale = (v.bank->harmonics() + 3) * omega;
  const DelayDifferentialSystem sys = closed_loop_dde(loop);
  const auto ev = collocation_eigenvalues(sys, o.collocation_nodes, scale);
  std::vector<cplx> cand;
  const spectra_detail::Evaluator f(loop);
  for (cplx e : ev) {
    if (e.imag() < -1e-9 * omega || std::abs(e) > 4.0 * scale) continue;
    const auto r = spectra_detail::newton(f, e, o.tolerance, 60);
    if (!r.converged) continue;
    cplx s = r.root;
    if (std::abs(s.imag()) < 1e-10 * std::max(omega, std::abs(s))) s = s.real();
    if (s.imag() < 0) s = std::conj(s);
    spectra_detail::add_unique(cand, s, 1e-8 * std::max(omega, std::abs(s)));
  }
  return cand;
}

int weight(cplx s, double omega) { return std::abs(s.imag()) > 1e-10 * std::max(omega, std::abs(s)) ? 2 : 1; }
}  // namespace

int count_roots(const LoopSpec& loop, const Box& box) {
  validate::finite("real_min", box.real_min);
  validate::finite("real_max", box.real_max);
  validate::finite("imag_min", box.imag_min);
  validate::finite("imag_max", box.imag_max);
  validate::require(box.real_max > box.real_min, "real_max", box.real_max, "> real_min");
  validate::require(box.imag_max > box.imag_min, "imag_max", box.imag_max, "> imag_min");
  const auto w = spectra_detail::winding(spectra_detail::Evaluator(loop), box);
  if (!w.ok)
    throw NumericalFailure(fmt::format("argument principle: a root lies on the boundary of the box [{}, {}] x [{}, {}]",
                                       box.real_min, box.real_max, box.imag_min, box.imag_max));
  return w.count;
}

CharacteristicRoot refine_root(const LoopSpec& loop, std::complex<double> guess, double tolerance) {
  validate::finite("guess.real", guess.real());
  validate::finite("guess.imag", guess.imag());
  validate::in_range("tolerance", tolerance, 1e-15, 1e-3);
  const auto r = spectra_detail::newton(spectra_detail::Evaluator(loop), guess, tolerance, 100);
  if (!r.converged)
    throw NumericalFailure(fmt::format("Newton from {}{:+}i did not converge (last correction {:.3g})", guess.real(),
                                       guess.imag(), r.correction));
  return {r.root, 1, r.correction, false};
}

namespace {
// rightmost_roots on checked arguments (the public function checks them first)
Spectrum rightmost_roots_checked(const LoopSpec& loop, const SpectrumOptions& o) {
  const auto v = spectra_detail::view(loop);
  const double omega = v.omega;
  Spectrum out;
  out.neutral_bound = neutral_spectrum_bound(loop);
  if (v.infinite) out.structural = neutral_realisation_roots(loop);
  const double bound = out.neutral_bound.value_or(-INFINITY);
  // finite banks: every oscillator frequency kΩ ≤ NΩ carries roots, so the proven box height exceeds NΩ; the cap
  // is raised to 2(N + 1)Ω (the winding along the box is then O(N) evaluations of O(N) each)
  const double cap =
      (v.bank ? std::max(o.max_imag_cap_periods, 2.0 * (v.bank->harmonics() + 1)) : o.max_imag_cap_periods) * omega;
  const spectra_detail::Evaluator f(loop);

  // 1. candidates (finite banks: collocation + Newton)
  std::vector<cplx> cand;
  if (v.bank) cand = collocation_candidates(loop, o);
  std::sort(cand.begin(), cand.end(), [](cplx a, cplx b) { return a.real() > b.real(); });

  // 2. the box
  double sigma_min = o.min_real;
  if (std::isnan(sigma_min)) {
    if (v.bank) {
      int acc = 0;
      std::size_t i = 0;
      for (; i < cand.size() && acc < o.count; ++i) acc += weight(cand[i], omega);
      if (i == 0) sigma_min = -omega;
      else if (i < cand.size()) sigma_min = 0.5 * (cand[i - 1].real() + cand[i].real());
      else sigma_min = cand[i - 1].real() - 0.1 * omega;
    } else {
      // right of the neutral chain: a gap of 20 % of |bound| (at least 0.02 Ω)
      sigma_min = std::isfinite(bound) ? bound + std::max(0.2 * std::abs(bound), 0.02 * omega) : -omega;
    }
  }
  if (sigma_min <= bound) {
    out.notes.push_back(fmt::format("min_real raised from {:.6g} to the right of the neutral chain bound {:.6g}",
                                    sigma_min, bound));
    sigma_min = bound + std::max(0.05 * std::abs(bound), 0.01 * omega);
  }
  RootBounds rb = root_bounds(loop, sigma_min);
  if (std::isnan(o.min_real) && rb.proven && rb.imag_max > cap) {
    // raise σ_min until the proven box height fits under the cap
    double lo = sigma_min, hi = std::max(0.0, sigma_min) + omega;
    for (int i = 0; i < 40 && !(root_bounds(loop, hi).proven && root_bounds(loop, hi).imag_max <= cap); ++i) hi += omega;
    for (int i = 0; i < 30; ++i) {
      const double mid = 0.5 * (lo + hi);
      const RootBounds b = root_bounds(loop, mid);
      (b.proven && b.imag_max <= cap ? hi : lo) = mid;
    }
    out.notes.push_back(fmt::format("min_real raised from {:.6g} to {:.6g} so that the proven box height stays "
                                    "<= {:.6g}", sigma_min, hi, cap));
    sigma_min = hi;
    rb = root_bounds(loop, sigma_min);
  }
  double real_max, imag_max;
  if (rb.proven) {
    real_max = rb.real_max;
    imag_max = rb.imag_max;
    out.box_is_proven = true;
  } else {
    real_max = std::max(sigma_min, cand.empty() ? 0.0 : cand.front().real()) + omega;
    imag_max = cap;
    out.notes.push_back("no proven root-free bound: box chosen heuristically");
  }
  if (!std::isnan(o.max_imag)) {
    if (o.max_imag < imag_max) out.box_is_proven = false;
    imag_max = o.max_imag;
  } else if (imag_max > cap) {
    imag_max = cap;
    out.box_is_proven = false;
    out.notes.push_back(fmt::format("box height capped at {:.6g} (the proven bound is larger)", cap));
  }
  out.box = Box{sigma_min, real_max, -imag_max, imag_max};
  int n_box = 0;
  if (!spectra_detail::robust_count(f, out.box, n_box))
    throw NumericalFailure("argument principle: could not count the roots in the search box (root on the boundary)");
  out.box_count = n_box;

  // 3. roots in the box: candidates first, then subdivision search for any that are missing
  std::vector<std::pair<cplx, int>> found;
  int have = 0;
  for (cplx s : cand)
    if (in_box(out.box, s)) {
      found.emplace_back(s, 1);
      have += weight(s, omega);
    }
  if (have != n_box) {
    // search the upper half of the box (the real axis inside), conjugates implied
    const double h = 0.000618 * omega;
    Box upper{out.box.real_min, out.box.real_max, -h, out.box.imag_max};
    int n_upper = 0;
    if (!spectra_detail::robust_count(f, upper, n_upper))
      throw NumericalFailure("argument principle: could not count the roots in the upper half of the box");
    std::vector<std::pair<cplx, int>> sub;
    spectra_detail::subdivision_search(f, upper, n_upper, o.tolerance, sub);
    found.clear();
    have = 0;
    std::vector<cplx> uniq;
    for (auto [s, m] : sub) {
      if (std::abs(s.imag()) < 1e-10 * std::max(omega, std::abs(s))) s = s.real();
      if (s.imag() < 0) s = std::conj(s);
      if (!in_box(out.box, s)) continue;
      if (!spectra_detail::add_unique(uniq, s, 1e-8 * std::max(omega, std::abs(s)))) continue;
      found.emplace_back(s, m);
      have += m * weight(s, omega);
    }
  }
  out.complete = have == n_box;

  // 4. both members of conjugate pairs, multiplicities
  std::vector<cplx> all;
  for (const auto& [s, m] : found) {
    all.push_back(s);
    if (weight(s, omega) == 2) all.push_back(std::conj(s));
  }
  for (const auto& [s, m] : found) {
    CharacteristicRoot root;
    const auto nr = spectra_detail::newton(f, s, o.tolerance, 3, m);  // correction estimate at the root
    root.value = s;
    root.multiplicity = m;
    root.correction = nr.correction;
    if (o.multiplicities) {
      double dmin = 0.01 * omega;
      for (cplx t : all)
        if (t != s) dmin = std::min(dmin, 0.3 * std::abs(t - s));
      dmin = std::max(dmin, 1e-7 * std::max(omega, std::abs(s)));
      Box small{s.real() - dmin, s.real() + 1.03 * dmin, s.imag() - 0.97 * dmin, s.imag() + dmin};
      int c = 0;
      if (spectra_detail::robust_count(f, small, c)) {
        root.multiplicity = c;
        root.certified = c >= 1;
      }
    }
    out.roots.push_back(root);
    if (weight(s, omega) == 2) {
      CharacteristicRoot conj = root;
      conj.value = std::conj(s);
      out.roots.push_back(conj);
    }
  }
  std::sort(out.roots.begin(), out.roots.end(), [](const CharacteristicRoot& a, const CharacteristicRoot& b) {
    return a.value.real() != b.value.real() ? a.value.real() > b.value.real() : a.value.imag() > b.value.imag();
  });

  // 5. abscissa, unstable count
  double abscissa = -INFINITY;
  for (const auto& r : out.roots) abscissa = std::max(abscissa, r.value.real());
  if (out.roots.empty() && !cand.empty()) abscissa = cand.front().real();
  if (out.neutral_bound) {
    abscissa = std::max(abscissa, bound);
    if (std::isfinite(bound)) {
      // roots between the chain bound and the box: Newton from the chain asymptotics (B4/A4 < 0: half-integers)
      const double half = std::abs(v.infinite->alpha) > omega / std::numbers::pi ? 0.5 : 0.0;
      for (int m = 0; m <= 64; ++m) {
        const auto r = spectra_detail::newton(f, cplx(bound + 1e-3 * omega, (m + half) * omega), o.tolerance, 40);
        if (!r.converged || r.root.real() <= bound || r.root.real() >= out.box.real_min) continue;
        const cplx s = r.root.imag() < 0 ? std::conj(r.root) : r.root;
        if (spectra_detail::add_unique(out.near_chain, s, 1e-8 * std::max(omega, std::abs(s))))
          abscissa = std::max(abscissa, s.real());
      }
      std::sort(out.near_chain.begin(), out.near_chain.end(), [](cplx a, cplx b) { return a.real() > b.real(); });
    }
  }
  out.spectral_abscissa = abscissa;
  if (bound >= 0.0) {
    out.unstable_count = -1;
  } else if (out.box.real_min <= 0.0 && out.complete && out.box_is_proven) {
    int n = 0;
    for (const auto& r : out.roots)
      if (r.value.real() >= 0.0) n += r.multiplicity;
    out.unstable_count = n;
  } else {
    const UnstableCount u = unstable_roots(loop);
    out.unstable_count = u.count;
  }
  if (!out.complete)
    out.notes.push_back(fmt::format("incomplete: the argument principle counts {} roots in the box, {} were found",
                                    n_box, have));
  return out;
}
}  // namespace

Spectrum rightmost_roots(const LoopSpec& loop, const SpectrumOptions& o) {
  check_options(o);
  // the arguments are checked: what is refused from here on was computed (core/computed.hpp)
  return computed("rightmost roots", [&] { return rightmost_roots_checked(loop, o); });
}

double spectral_abscissa(const LoopSpec& loop) { return rightmost_roots(loop).spectral_abscissa; }

UnstableCount unstable_roots(const LoopSpec& loop) {
  const double omega = loop.rotation_frequency();
  UnstableCount u;
  const auto bound = neutral_spectrum_bound(loop);
  if (bound && *bound >= 0.0) {
    u.count = -1;
    u.marginal = *bound == 0.0;
    return u;
  }
  const RootBounds rb = root_bounds(loop, 0.0);
  if (!rb.proven) throw NumericalFailure("unstable_roots: no root-free bound for the right half-plane");
  // count in Re s ≥ 0; a root on the axis makes the count fail: then count in Re s ≥ ε and flag marginal
  const Box box{0.0, rb.real_max, -rb.imag_max, rb.imag_max};
  const spectra_detail::Evaluator f(loop);
  const auto w = spectra_detail::winding(f, box);
  if (w.ok) {
    u.count = w.count;
    return u;
  }
  u.marginal = true;
  Box shifted{1e-9 * omega, rb.real_max, -rb.imag_max * 1.0001, rb.imag_max * 1.0001};
  int n = 0;
  if (!spectra_detail::robust_count(f, shifted, n))
    throw NumericalFailure("unstable_roots: could not count the roots in the right half-plane");
  u.count = n;
  return u;
}

}  // namespace afmkit::control
