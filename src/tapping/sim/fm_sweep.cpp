// FM orbits along an approach: warm start from the previous orbits (secant predictor), bisection of the step where
// Newton fails, and the jump past a fold of the branch in l (include/afmkit/tapping/fm.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/fm.hpp"

namespace afmkit::tapping {

void FmSweepOptions::validate() const {
  fm.validate();
  validate::require(max_bisections >= 0 && max_bisections <= 20, "max_bisections", max_bisections, "in [0, 20]");
}

long FmSweepResult::converged() const {
  return std::count_if(points.begin(), points.end(), [](const FmPoint& p) { return p.status == FmStatus::converged; });
}

namespace {

/// A starting point of Newton: the FM unknowns and the separation.
struct Guess {
  FmState state;
  double separation;
};

Guess guess_of(const FmOrbit& o) { return {o.state, o.separation}; }

class Tracker {
 public:
  Tracker(const FmSetting& setting, const FmSweepOptions& options, FmAxis axis)
      : setting_(setting), options_(options), axis_(axis) {}

  long evaluations = 0;
  long failed_attempts = 0;
  bool folded = false;  // the last jump() passed a fold (l turned back): the orbit is on another branch
  std::optional<FmOrbit> last, before_last;

  double parameter(const FmOrbit& o, FmAxis axis) const {
    return axis == FmAxis::min_gap ? o.metrics.min_gap : o.separation;
  }

  std::optional<FmOrbit> attempt(double target, const Guess& g, FmAxis axis) {
    FmJacobian& jac = axis == FmAxis::min_gap ? gap_jacobian_ : separation_jacobian_;
    auto o = axis == FmAxis::min_gap
                 ? try_solve_fm_at_gap(setting_, target, g.separation, g.state, options_.fm, &jac)
                 : try_solve_fm(setting_, target, g.state, options_.fm, &jac);
    if (o) evaluations += o->evaluations;
    else {
      ++failed_attempts;
      jac.matrix.resize(0, 0);  // a failed solve's Jacobian is not trusted for the next
    }
    return o;
  }

  /// Linear extrapolation of the unknowns and the separation from two orbits (b the latest) to `target`.
  Guess predict(const FmOrbit& a, const FmOrbit& b, double target, FmAxis axis) const {
    const double pa = parameter(a, axis), pb = parameter(b, axis);
    if (pa == pb) return guess_of(b);
    const double s = (target - pb) / (pb - pa);
    auto lin = [s](double va, double vb) { return vb + s * (vb - va); };
    Guess g{{{lin(a.state.initial.position, b.state.initial.position),
              lin(a.state.initial.velocity, b.state.initial.velocity)},
             lin(a.state.frequency, b.state.frequency),
             lin(a.state.drive, b.state.drive)},
            lin(a.separation, b.separation)};
    if (!(g.state.frequency > 0.0) || !(g.state.drive > 0.0)) return guess_of(b);
    return g;
  }

  /// From `b` (and `a` before it, for the secant) to target: predicted, then plain warm start.
  std::optional<FmOrbit> step(const FmOrbit* a, const FmOrbit& b, double target, FmAxis axis) {
    std::optional<FmOrbit> o;
    if (a) o = attempt(target, predict(*a, b, target, axis), axis);
    if (!o) o = attempt(target, guess_of(b), axis);
    return o;
  }

  /// From the last converged orbit to target: directly, else in 2^k sub-steps. Updates last / before_last.
  std::optional<FmOrbit> reach(double target) {
    if (auto o = step(before_last ? &*before_last : nullptr, *last, target, axis_)) return advance(*o);
    return bisect(target);
  }

  std::optional<FmOrbit> bisect(double target) {
    const double from = parameter(*last, axis_);
    for (int depth = 1; depth <= options_.max_bisections; ++depth) {
      options_.cancellation.check();
      const int n = 1 << depth;
      std::vector<FmOrbit> chain;  // the orbits of the sub-steps, after the last two converged
      if (before_last) chain.push_back(*before_last);
      chain.push_back(*last);
      bool ok = true;
      for (int k = 1; k <= n && ok; ++k) {
        const FmOrbit* a = chain.size() >= 2 ? &chain[chain.size() - 2] : nullptr;
        auto o = step(a, chain.back(), from + (target - from) * k / n, axis_);
        if (o) chain.push_back(std::move(*o));
        else ok = false;
      }
      if (ok) {
        before_last = chain[chain.size() - 2];
        last = chain.back();
        return last;
      }
    }
    return std::nullopt;
  }

  /// Separation axis, past a fold: follow the branch from the last orbit in the turning-point gap (through the
  /// fold, where l turns back) until l passes `target`, then solve at target from that bracket. Updates last.
  std::optional<FmOrbit> jump(double target) {
    const double a = setting_.amplitude, l0 = last->separation;
    const double sense = target < l0 ? -1.0 : 1.0;  // approach: l must come below target
    double dz = 0.01 * a;
    folded = false;
    std::vector<FmOrbit> chain{*last};  // the orbits of the walk in the turning-point gap
    for (int k = 0; k < 400 && dz > 1e-6 * a; ++k) {
      options_.cancellation.check();
      const FmOrbit& prev = chain.back();
      const FmOrbit* pp = chain.size() >= 2 ? &chain[chain.size() - 2] : nullptr;
      auto o = step(pp, prev, prev.metrics.min_gap + sense * dz, FmAxis::min_gap);
      if (!o) {
        dz *= 0.5;
        continue;
      }
      if (sense * (o->separation - prev.separation) < 0.0) folded = true;  // l turns back: past a fold
      if (sense * (o->separation - target) >= 0.0) {
        // bracket [prev, o] in l: Newton at the separation from o, else from the interpolation
        auto r = step(nullptr, *o, target, FmAxis::separation);
        if (!r) r = attempt(target, predict(prev, *o, target, FmAxis::separation), FmAxis::separation);
        if (!r) return std::nullopt;
        before_last.reset();  // no secant across branches
        last = r;
        return r;
      }
      chain.push_back(std::move(*o));
      dz = std::min(1.5 * dz, 0.05 * a);
    }
    return std::nullopt;
  }

  /// The first orbit: from the free FM orbit; else marched in from 3A above the law's switching gaps.
  std::optional<FmOrbit> first(double target) {
    const double a = setting_.amplitude;
    const auto& gaps = setting_.law.switching_gaps();
    const double top_gap = (gaps.empty() ? 0.0 : gaps.back()) + 2.0 * a;  // turning point far above the law's gaps
    FmState free = free_fm_state(setting_);
    const double l_free = axis_ == FmAxis::min_gap ? target + a : target;
    if (auto o = attempt(target, {free, l_free}, axis_)) return advance(*o);
    const double far = axis_ == FmAxis::min_gap ? top_gap : top_gap + a;
    if (!(far > target)) return std::nullopt;
    auto o = attempt(far, {free, axis_ == FmAxis::min_gap ? far + a : far}, axis_);
    if (!o) return std::nullopt;
    last = o;
    before_last.reset();
    auto r = reach(target);
    if (!r) last.reset(), before_last.reset();
    return r;
  }

 private:
  const FmSetting& setting_;
  const FmSweepOptions& options_;
  FmAxis axis_;
  FmJacobian separation_jacobian_, gap_jacobian_;  // kept from solve to solve (Broyden-updated)

  std::optional<FmOrbit> advance(const FmOrbit& o) {
    before_last = last;
    last = o;
    return o;
  }
};

}  // namespace

FmSweepResult sweep_fm(const FmSetting& setting, const std::vector<double>& targets, const FmSweepOptions& options) {
  options.validate();
  for (double t : targets) validate::finite(options.axis == FmAxis::min_gap ? "min_gap" : "separation", t);
  const auto start = std::chrono::steady_clock::now();
  FmSweepResult result;
  Tracker tracker(setting, options, options.axis);
  for (double target : targets) {
    options.cancellation.check();
    FmPoint p;
    p.separation = target;
    std::optional<FmOrbit> orbit;
    if (!tracker.last) {
      orbit = tracker.first(target);
    } else if (options.axis == FmAxis::separation && options.jumps) {
      // directly; else along the branch in the turning-point gap (through a fold, or a steep stretch where the
      // gap barely moves), else in bisected steps of l
      const FmOrbit* before = tracker.before_last ? &*tracker.before_last : nullptr;
      if (auto o = tracker.step(before, *tracker.last, target, FmAxis::separation)) {
        tracker.before_last = tracker.last;
        tracker.last = o;
        orbit = o;
      } else if ((orbit = tracker.jump(target))) {
        p.jumped = tracker.folded;
      } else {
        orbit = tracker.bisect(target);
      }
    } else {
      orbit = tracker.reach(target);
    }
    if (orbit) {
      p.status = FmStatus::converged;
      p.orbit = std::move(orbit);
    }
    result.points.push_back(std::move(p));
    if (options.progress) options.progress(1);
  }
  result.evaluations = tracker.evaluations;
  result.failed_attempts = tracker.failed_attempts;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace afmkit::tapping
