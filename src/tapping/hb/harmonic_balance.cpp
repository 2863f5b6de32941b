// All harmonic-balance solutions at a separation and the folds of the branches (seed-1 ext. E1–E7,
// docs/theory-tapping.md#two-branch-solution, #folds).
#include "afmkit/tapping/harmonic_balance.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include <boost/math/tools/toms748_solve.hpp>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "general_harmonic_balance.hpp"

namespace afmkit::tapping {

namespace {

using std::numbers::pi;  // (a using-declaration: repeatable in a unity build)
// Scan grid. Contact angle a = arccos q: node at a = 0 (grazing), log grid on [1e-8, 0.3] (1 − q ≈ a²/2 down
// to 5e-17, i.e. q = 1 to double precision), uniform grid on [0.3, π]. Permanent contact: q = −10^(k/40),
// k = 0 … 280 (down to q = −1e7; l is then within ~1e-7 (relative) of its limit E8; further out dl/dq ~ 1/q² is
// below the rounding of its own terms and would show spurious folds).
constexpr double log_angle_min = 1e-8;
constexpr double log_angle_max = 0.3;
constexpr int log_angle_per_decade = 60;
constexpr double uniform_angle_step = 0.005;
constexpr int permanent_per_decade = 40;
constexpr int permanent_decades = 7;
constexpr std::uintmax_t max_refine_iterations = 200;

std::vector<double> contact_grid() {
  std::vector<double> g{0.0};
  const double decades = std::log10(log_angle_max / log_angle_min);
  const int n_log = static_cast<int>(std::ceil(decades * log_angle_per_decade));
  for (int k = 0; k < n_log; ++k) g.push_back(log_angle_min * std::pow(10.0, decades * k / n_log));
  const int n_lin = static_cast<int>(std::ceil((pi - log_angle_max) / uniform_angle_step));
  for (int k = 0; k <= n_lin; ++k) g.push_back(log_angle_max + (pi - log_angle_max) * k / n_lin);
  g.back() = pi;
  return g;
}

std::vector<double> permanent_grid() {
  std::vector<double> g;
  const int n = permanent_per_decade * permanent_decades;
  for (int k = 0; k <= n; ++k) g.push_back(-std::pow(10.0, static_cast<double>(k) / permanent_per_decade));
  g.front() = -1.0;
  return g;
}

HbBranch branch_of(int sign) { return sign > 0 ? HbBranch::Plus : HbBranch::Minus; }

HbPoint to_point(const HbBranchEvaluation& e, HbBranch branch) {
  return {e.q, e.separation, e.amplitude, e.offset, e.phase, branch};
}

HbPoint free_point(const HbCoefficients& c, double q) {
  const double b = c.free_amplitude();
  return {q, q * b, b, 0.0, c.free_phase(), HbBranch::Free};
}

// Root of f on [lo, hi] (f(lo)·f(hi) ≤ 0) to a few ulp.
template <class F>
double refine(F f, double lo, double hi, double f_lo, double f_hi) {
  if (f_lo == 0.0) return lo;
  if (f_hi == 0.0) return hi;
  std::uintmax_t iterations = max_refine_iterations;
  const auto bracket = boost::math::tools::toms748_solve(f, lo, hi, f_lo, f_hi,
                                                         boost::math::tools::eps_tolerance<double>(52), iterations);
  if (iterations >= max_refine_iterations)
    throw NumericalFailure(fmt::format("harmonic balance: root refinement did not converge on [{}, {}]", lo, hi));
  return 0.5 * (bracket.first + bracket.second);
}

std::optional<HbPoint> point_at_q(const HbCoefficients& c, double q, HbBranch branch) {
  if (!std::isfinite(q)) validate::finite("q", q);
  if (q >= 1.0) {
    if (branch == HbBranch::Minus) return std::nullopt;
    return free_point(c, q);
  }
  if (branch == HbBranch::Free) return std::nullopt;
  const HbBranchEvaluation e = evaluate_branch_at_gap(c, 1.0 - q, static_cast<int>(branch));
  if (!e.exists) return std::nullopt;
  return to_point(e, branch);
}

}  // namespace

const char* branch_name(HbBranch branch) {
  switch (branch) {
    case HbBranch::Free: return "free";
    case HbBranch::Plus: return "plus";
    case HbBranch::Minus: return "minus";
  }
  return "unknown";
}

HbBranchEvaluation HarmonicBalance::evaluate(const Node& like, double parameter, int sign) const {
  return like.permanent ? evaluate_branch_permanent(*coefficients_, parameter, sign)
                        : evaluate_branch_at_angle(*coefficients_, parameter, sign);
}

HarmonicBalance::HarmonicBalance(const TappingModel& model, const Cancellation& cancellation)
    : free_amplitude_(model.free_amplitude()) {
  if (model.law.piecewise_linear() == nullptr) {
    general_ = std::make_shared<const detail::GeneralHarmonicBalance>(model, cancellation);
    folds_ = general_->folds();
    free_amplitude_ = general_->free_amplitude();
    return;
  }
  coefficients_.emplace(model);
  free_amplitude_ = coefficients_->free_amplitude();
  scan_branch(+1);
  scan_branch(-1);
  std::sort(folds_.begin(), folds_.end(), [](const HbFold& a, const HbFold& b) { return a.point.q < b.point.q; });
}

const HbCoefficients& HarmonicBalance::coefficients() const& {
  if (!coefficients_) require_piecewise_linear_model();
  return *coefficients_;
}

HbCoefficients HarmonicBalance::coefficients() const&& {
  if (!coefficients_) require_piecewise_linear_model();
  return *coefficients_;
}

void HarmonicBalance::require_piecewise_linear_model() const {
  throw InvalidParameter("law", "harmonic balance: the closed-form coefficients exist only for the piecewise-linear "
                                "laws of seed-1 eqs. (10), (11), (26)");
}

std::vector<HbPoint> HarmonicBalance::points_at_q(double q) const {
  if (general_) return general_->points_at_q(q);
  std::vector<HbPoint> out;
  for (const HbBranch b : {HbBranch::Minus, HbBranch::Plus})
    if (const auto p = point_at_q(*coefficients_, q, b)) out.push_back(*p);
  std::sort(out.begin(), out.end(), [](const HbPoint& a, const HbPoint& b) { return a.amplitude < b.amplitude; });
  return out;
}

void HarmonicBalance::scan_branch(int sign) {
  std::vector<Run>& runs = runs_[sign > 0 ? 0 : 1];
  for (const bool permanent : {false, true}) {
    const std::vector<double> grid = permanent ? permanent_grid() : contact_grid();
    const Node kind{permanent, 0.0, 0.0, 0.0};
    Run run;
    auto node_of = [&](double p, const HbBranchEvaluation& e) {
      return Node{permanent, p, e.separation, e.parameter_derivative};
    };
    auto close_run = [&] {
      if (run.size() >= 2) runs.push_back(std::move(run));
      run.clear();
    };
    double previous_p = grid.front();
    bool previous_exists = false;
    for (std::size_t k = 0; k < grid.size(); ++k) {
      const double p = grid[k];
      const HbBranchEvaluation e = evaluate(kind, p, sign);
      if (k > 0 && e.exists != previous_exists) {
        // Locate the existence boundary between the two grid points by bisection (to adjacent doubles).
        double p_in = e.exists ? p : previous_p;
        double p_out = e.exists ? previous_p : p;
        HbBranchEvaluation at_in = e.exists ? e : evaluate(kind, p_in, sign);
        for (int it = 0; it < 200; ++it) {
          const double mid = 0.5 * (p_in + p_out);
          if (mid == p_in || mid == p_out) break;
          const HbBranchEvaluation m = evaluate(kind, mid, sign);
          if (m.exists) {
            p_in = mid;
            at_in = m;
          } else {
            p_out = mid;
          }
        }
        // At the boundary node itself the two roots meet (or B → 0): its slope is rounding-dominated, so it is
        // marked unusable, and a helper node slightly inside carries the slope sign of the end of the run.
        const double inside = p_in + 1e-6 * ((e.exists ? p : previous_p) - p_in);
        Node boundary = node_of(p_in, at_in);
        boundary.derivative = std::numeric_limits<double>::quiet_NaN();
        const HbBranchEvaluation near = evaluate(kind, inside, sign);
        if (e.exists) {
          close_run();
          if (p_in != p) run.push_back(boundary);
          if (near.exists && inside != p_in && inside != p) run.push_back(node_of(inside, near));
        } else {
          if (near.exists && inside != p_in && inside != previous_p) run.push_back(node_of(inside, near));
          if (p_in != previous_p) run.push_back(boundary);
          close_run();
        }
      }
      if (e.exists) run.push_back(node_of(p, e));
      previous_p = p;
      previous_exists = e.exists;
    }
    close_run();
  }
  // Folds: sign changes of dl/dθ between nodes of a run; refine and insert them as nodes, so that l is
  // monotone between consecutive nodes.
  for (Run& run : runs) {
    Run refined;
    refined.reserve(run.size() + 4);
    const Node* last_signed = nullptr;  // last node with a finite non-zero derivative
    for (std::size_t k = 0; k < run.size(); ++k) {
      const Node& n = run[k];
      const bool usable = std::isfinite(n.derivative) && n.derivative != 0.0;
      if (usable && last_signed != nullptr && (last_signed->derivative > 0.0) != (n.derivative > 0.0)) {
        const Node& a = *last_signed;
        auto slope = [&](double p) { return evaluate(n, p, sign).parameter_derivative; };
        const double lo = std::min(a.parameter, n.parameter);
        const double hi = std::max(a.parameter, n.parameter);
        const double f_lo = lo == a.parameter ? a.derivative : n.derivative;
        const double f_hi = hi == a.parameter ? a.derivative : n.derivative;
        const double p_fold = refine(slope, lo, hi, f_lo, f_hi);
        const HbBranchEvaluation e = evaluate(n, p_fold, sign);
        if (e.exists) {
          folds_.push_back({to_point(e, branch_of(sign)), a.derivative > 0.0});
          if (p_fold != refined.back().parameter && p_fold != n.parameter)
            refined.push_back({n.permanent, p_fold, e.separation, 0.0});
        }
      }
      refined.push_back(n);
      if (usable) last_signed = &run[k];
    }
    run = std::move(refined);
  }
}

std::vector<HbPoint> HarmonicBalance::solutions(double separation) const {
  if (general_) return general_->solutions(separation);
  validate::finite("separation", separation);
  std::vector<HbPoint> out;
  const double b_free = coefficients_->free_amplitude();
  if (separation >= b_free) out.push_back(free_point(*coefficients_, separation / b_free));
  for (const int sign : {+1, -1}) {
    for (const Run& run : runs_[sign > 0 ? 0 : 1]) {
      auto add = [&](const Node& like, double p) {
        const HbBranchEvaluation e = evaluate(like, p, sign);
        if (e.exists && e.gap > 0.0) out.push_back(to_point(e, branch_of(sign)));
      };
      for (std::size_t k = 0; k + 1 < run.size(); ++k) {
        const Node& a = run[k];
        const Node& b = run[k + 1];
        const double fa = a.separation - separation;
        const double fb = b.separation - separation;
        if (fa == 0.0) add(a, a.parameter);
        if (fa * fb >= 0.0) continue;
        auto f = [&](double p) {
          const HbBranchEvaluation e = evaluate(a, p, sign);
          return e.exists ? e.separation - separation : fa;  // (cannot happen inside a run)
        };
        const double lo = std::min(a.parameter, b.parameter);
        const double hi = std::max(a.parameter, b.parameter);
        add(a, refine(f, lo, hi, lo == a.parameter ? fa : fb, lo == a.parameter ? fb : fa));
      }
      if (run.back().separation == separation) add(run.back(), run.back().parameter);
    }
  }
  std::sort(out.begin(), out.end(), [](const HbPoint& a, const HbPoint& b) { return a.amplitude < b.amplitude; });
  // Remove duplicates (a root on a shared node, the junction q = −1, or the meeting point of B₊ and B₋).
  std::vector<HbPoint> unique;
  for (const HbPoint& p : out) {
    const bool duplicate = std::any_of(unique.begin(), unique.end(), [&](const HbPoint& u) {
      return std::abs(u.q - p.q) <= 1e-12 * std::max(1.0, std::abs(p.q)) &&
             std::abs(u.amplitude - p.amplitude) <= 1e-10 * p.amplitude;
    });
    if (!duplicate) unique.push_back(p);
  }
  return unique;
}

std::optional<HbPoint> HarmonicBalance::at_q(double q, HbBranch branch) const {
  if (!general_) return point_at_q(*coefficients_, q, branch);
  std::optional<HbPoint> best;
  for (const HbPoint& p : general_->points_at_q(q)) {  // by increasing amplitude: the last match is the largest
    const bool match = branch == HbBranch::Minus  ? p.branch == HbBranch::Minus
                       : branch == HbBranch::Free ? p.branch == HbBranch::Free
                                                  : p.branch != HbBranch::Minus;
    if (match) best = p;
  }
  return best;
}

std::vector<HbPoint> harmonic_balance_solutions(const TappingModel& model) {
  return HarmonicBalance(model).solutions(model.separation);
}

std::optional<HbPoint> harmonic_balance_at_q(const TappingModel& model, double q, HbBranch branch) {
  if (model.law.piecewise_linear() == nullptr) {
    validate::finite("q", q);
    return HarmonicBalance(model).at_q(q, branch);
  }
  return point_at_q(HbCoefficients(model), q, branch);
}

std::vector<HbFold> harmonic_balance_folds(const TappingModel& model) { return HarmonicBalance(model).folds(); }

}  // namespace afmkit::tapping
