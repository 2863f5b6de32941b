// The parametric separation–amplitude curve (l(q), B(q), A(q), φ(q)) sampled over q (seed-1 eq. 19).
#include <algorithm>
#include <cmath>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "general_harmonic_balance.hpp"

namespace afmkit::tapping {

namespace {

void validate_options(const HbCurveOptions& o) {
  validate::finite("q_min", o.q_min);
  validate::finite("q_max", o.q_max);
  validate::require(o.q_max > o.q_min, "q_max", o.q_max, "> q_min");
  validate::require(o.points >= 2, "points", static_cast<double>(o.points), ">= 2");
  validate::require(o.min_gap > 0.0 && o.min_gap < 1.0, "min_gap", o.min_gap, "in (0, 1)");
}

// Calls visit(q, gap) for every sample by increasing q (gap = 1 − q, exact for the log samples).
template <class Visit>
void for_each_sample(const HbCurveOptions& o, Visit visit) {
  const std::size_t n = o.points;
  // Log samples of the gap s = 1 − q on [max(min_gap, 1 − q_max), 1 − q_min], only where q < 1.
  const double gap_hi = 1.0 - o.q_min;
  const double gap_lo = std::max(o.min_gap, 1.0 - o.q_max);
  const bool refined = o.spacing == HbCurveSpacing::RefinedGrazing && o.q_min < 1.0 && gap_lo < gap_hi;
  const std::size_t n_log = refined && n >= 4 ? n / 2 : 0;  // both parts need ≥ 2 samples
  const std::size_t n_uniform = n - n_log;
  const double log_ratio = refined ? std::log(gap_lo / gap_hi) : 0.0;
  // The log samples exclude gap_hi (q_min is a uniform sample) and, when gap_lo = 1 − q_max, also gap_lo.
  const bool include_lo = o.min_gap > 1.0 - o.q_max;
  const double log_steps = static_cast<double>(include_lo ? n_log : n_log + 1);
  auto uniform_q = [&](std::size_t k) {
    if (k + 1 == n_uniform) return o.q_max;
    return o.q_min + (o.q_max - o.q_min) * static_cast<double>(k) / static_cast<double>(n_uniform - 1);
  };
  auto log_gap = [&](std::size_t k) {
    if (include_lo && k + 1 == n_log) return gap_lo;
    return gap_hi * std::exp(log_ratio * static_cast<double>(k + 1) / log_steps);
  };
  // Merge both sequences by increasing q (uniform: increasing q; log: decreasing gap).
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < n_uniform || j < n_log) {
    if (j >= n_log || (i < n_uniform && uniform_q(i) <= 1.0 - log_gap(j))) {
      const double q = uniform_q(i++);
      visit(q, 1.0 - q);
    } else {
      const double gap = log_gap(j++);
      visit(1.0 - gap, gap);
    }
  }
}

HbPoint curve_point(const HbBranchEvaluation& e, HbBranch branch) {
  return {e.q, e.separation, e.amplitude, e.offset, e.phase, branch};
}

// Any other law: every point at each sample from the traced curve (general_harmonic_balance.hpp).
void general_curve(const TappingModel& model, const HbCurveOptions& options, std::vector<HbPoint>& out) {
  std::vector<double> qs;
  qs.reserve(options.points);
  for_each_sample(options, [&](double q, double) { qs.push_back(q); });
  const detail::GeneralHarmonicBalance hb(model, options.cancellation);
  std::vector<HbPoint> lower;
  out.clear();
  hb.sample(qs, options.include_minus, out, lower, options.cancellation);
  out.insert(out.end(), lower.begin(), lower.end());
}

void curve_of_checked(const TappingModel& model, const HbCurveOptions& options, std::vector<HbPoint>& out) {
  if (model.law.piecewise_linear() == nullptr) {
    general_curve(model, options, out);
    return;
  }
  const HbCoefficients c(model);
  const std::size_t n = options.points;
  // One pass: Plus/Free points fill out[0, …), Minus points out[n, …); then the Minus block is moved down.
  // No allocation when out.capacity() ≥ 2n.
  out.resize(2 * n);
  std::size_t n_plus = 0;
  std::size_t n_minus = 0;
  const double b_free = c.free_amplitude();
  const double phase_free = c.free_phase();
  std::size_t visited = 0;
  for_each_sample(options, [&](double q, double gap) {
    if ((++visited & 4095) == 0) options.cancellation.check();
    if (gap <= 0.0) {
      out[n_plus++] = {q, q * b_free, b_free, 0.0, phase_free, HbBranch::Free};
      return;
    }
    const HbRoots roots = evaluate_branches_at_gap(c, gap, false);
    if (roots.plus.exists) out[n_plus++] = curve_point(roots.plus, HbBranch::Plus);
    if (options.include_minus && roots.minus.exists) out[n + n_minus++] = curve_point(roots.minus, HbBranch::Minus);
  });
  std::copy(out.begin() + static_cast<std::ptrdiff_t>(n), out.begin() + static_cast<std::ptrdiff_t>(n + n_minus),
            out.begin() + static_cast<std::ptrdiff_t>(n_plus));
  out.resize(n_plus + n_minus);
}

}  // namespace

void harmonic_balance_curve(const TappingModel& model, const HbCurveOptions& options, std::vector<HbPoint>& out) {
  validate_options(options);
  // the options are checked: what is refused from here on was computed (core/computed.hpp)
  computed("harmonic-balance curve", [&] { curve_of_checked(model, options, out); });
}

std::vector<HbPoint> harmonic_balance_curve(const TappingModel& model, const HbCurveOptions& options) {
  std::vector<HbPoint> out;
  out.reserve(2 * options.points);
  harmonic_balance_curve(model, options, out);
  return out;
}

}  // namespace afmkit::tapping
