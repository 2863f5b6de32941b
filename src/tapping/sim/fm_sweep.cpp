// FM orbits along the separation: warm start from the previous orbit (secant predictor), bisection of the step
// where Newton fails (include/afmkit/tapping/fm.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>

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

/// Linear extrapolation in l of the unknowns from two converged orbits (a, b: b the latest) to l.
FmState predict(const FmOrbit& a, const FmOrbit& b, double l) {
  const double dl = b.separation - a.separation;
  if (dl == 0.0) return b.state;
  const double s = (l - b.separation) / dl;
  FmState p;
  p.initial.position = b.state.initial.position + s * (b.state.initial.position - a.state.initial.position);
  p.initial.velocity = b.state.initial.velocity + s * (b.state.initial.velocity - a.state.initial.velocity);
  p.frequency = b.state.frequency + s * (b.state.frequency - a.state.frequency);
  p.drive = b.state.drive + s * (b.state.drive - a.state.drive);
  if (!(p.frequency > 0.0) || !(p.drive > 0.0)) return b.state;
  return p;
}

struct Tracker {
  const FmSetting& setting;
  const FmSweepOptions& options;
  long evaluations = 0;
  long failed_attempts = 0;
  std::optional<FmOrbit> last, before_last;

  std::optional<FmOrbit> attempt(double l, const FmState& guess) {
    auto o = try_solve_fm(setting, l, guess, options.fm);
    if (o) evaluations += o->evaluations;
    else ++failed_attempts;
    return o;
  }

  void accept(const FmOrbit& o) {
    before_last = last;
    last = o;
  }

  /// From the last converged orbit to l: direct (predicted, then plain warm start), else in 2^k sub-steps.
  std::optional<FmOrbit> reach(double l) {
    std::optional<FmOrbit> o;
    if (before_last) o = attempt(l, predict(*before_last, *last, l));
    if (!o) o = attempt(l, last->state);
    if (o) {
      before_last = last;
      return o;
    }
    const double from = last->separation;
    for (int depth = 1; depth <= options.max_bisections; ++depth) {
      const int n = 1 << depth;
      std::optional<FmOrbit> a = before_last, b = last;
      bool ok = true;
      for (int k = 1; k <= n; ++k) {
        const double lk = from + (l - from) * k / n;
        std::optional<FmOrbit> o = a ? attempt(lk, predict(*a, *b, lk)) : std::nullopt;
        if (!o) o = attempt(lk, b->state);
        if (!o) {
          ok = false;
          break;
        }
        a = b;
        b = o;
      }
      if (ok) {
        before_last = a;  // the sub-step before l: a closer secant for the next separation
        return b;
      }
      options.cancellation.check();
    }
    return std::nullopt;
  }
};

}  // namespace

FmSweepResult sweep_fm(const FmSetting& setting, const std::vector<double>& separations,
                       const FmSweepOptions& options) {
  options.validate();
  for (double l : separations) validate::finite("separation", l);
  const auto start = std::chrono::steady_clock::now();
  FmSweepResult result;
  Tracker tracker{setting, options};
  for (double l : separations) {
    options.cancellation.check();
    std::optional<FmOrbit> orbit;
    if (tracker.last) {
      orbit = tracker.reach(l);
      if (orbit) tracker.last = orbit;  // (reach set before_last)
    } else {
      orbit = tracker.attempt(l, free_fm_state(setting));
      if (!orbit) {
        // march in from above the law's switching gaps, where the free orbit is a good guess
        const auto& gaps = setting.law.switching_gaps();
        const double top = std::max(l, (gaps.empty() ? 0.0 : gaps.back()) + 3.0 * setting.amplitude);
        if (top > l) {
          if (auto far = tracker.attempt(top, free_fm_state(setting))) {
            tracker.accept(*far);
            orbit = tracker.reach(l);
            if (orbit) tracker.last = orbit;
            else tracker.last.reset(), tracker.before_last.reset();
          }
        }
      } else {
        tracker.accept(*orbit);
      }
    }
    FmPoint p;
    p.separation = l;
    if (orbit) {
      p.status = FmStatus::converged;
      p.orbit = orbit;
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
