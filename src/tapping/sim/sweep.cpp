#include <algorithm>
#include "afmkit/tapping/sweep.hpp"

#include <cmath>
#include <exception>
#include <limits>
#include <optional>

#include <Eigen/LU>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/parallel.hpp"
#include "afmkit/core/validate.hpp"
#include "sweep_points.hpp"

namespace afmkit::tapping {

const char* direction_name(SweepDirection direction) {
  switch (direction) {
    case SweepDirection::approach: return "approach";
    case SweepDirection::retract: return "retract";
    case SweepDirection::continuation: return "continuation";
  }
  return "?";
}

void SweepOptions::validate() const {
  shooting.validate();
  transient.validate();
  validate::require(max_substeps >= 1, "max_substeps", max_substeps, ">= 1");
}

namespace {
void attach_from(const std::vector<HbPoint>& solutions, SweepPoint& point) {
  point.hb_solutions = static_cast<int>(solutions.size());
  double best = std::numeric_limits<double>::infinity();
  for (const HbPoint& p : solutions) {
    const double d = std::abs(p.amplitude - point.metrics.amplitude);
    if (d < best) {
      best = d;
      point.hb_amplitude = p.amplitude;
      point.hb_offset = p.offset;
      point.hb_phase = p.phase;
    }
  }
}
}  // namespace

void attach_harmonic_balance(const TappingModel& base, SweepPoint& point) {
  attach_from(harmonic_balance_solutions(base.with_separation(point.separation)), point);
}

namespace {

double distance(TipState a, TipState b, double omega) {
  return std::hypot(a.position - b.position, (a.velocity - b.velocity) / omega);
}
double magnitude(TipState a, double omega) { return std::hypot(a.position, a.velocity / omega); }

void check_range(double l_min, double l_max, int points) {
  validate::finite("separation_min", l_min);
  validate::finite("separation_max", l_max);
  validate::require(l_min < l_max, "separation_min", l_min, fmt::format("< separation_max = {}", l_max));
  validate::require(points >= 2, "points", points, ">= 2");
}

/// Settle a transient from `state` at the model's separation; the point is marked jumped.
SweepPoint from_transient(const TappingModel& model, TipState state, SweepDirection direction,
                          const SweepOptions& options) {
  SweepPoint p;
  p.separation = model.separation;
  p.direction = direction;
  p.jumped = true;
  const TransientOutcome t = settle(model, state, options.transient, options.shooting);
  if (t.orbit) {
    p.orbit = *t.orbit;
  } else {
    // not settled: describe one period from the last state (flagged non-periodic, never stable)
    p.periodic = false;
    p.orbit.separation = model.separation;
    p.orbit.initial = t.final_state;
    p.orbit.stable = false;
    p.orbit.floquet_max = std::numeric_limits<double>::quiet_NaN();
  }
  return p;
}

/// Scaled state z = (x, ẋ/ω) of an orbit and the slope dz/dl of its branch, −(M − I)⁻¹ ∂P/∂l (implicit
/// function theorem on P_l(z) = z); nullopt at a fold (M − I singular).
Eigen::Vector2d scaled(TipState s, double omega) { return {s.position, s.velocity / omega}; }
std::optional<Eigen::Vector2d> branch_slope(const PeriodicOrbit& orbit, double omega) {
  const Eigen::Matrix2d j = orbit.monodromy - Eigen::Matrix2d::Identity();
  const Eigen::FullPivLU<Eigen::Matrix2d> lu(j);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Vector2d dydl = -lu.solve(orbit.separation_sensitivity);  // d(x, ẋ)/dl
  if (!dydl.allFinite()) return std::nullopt;
  return Eigen::Vector2d(dydl.x(), dydl.y() / omega);
}

/// Whether one Newton step for the fixed point of the stroboscopic map, taken from the scaled state `from`,
/// lands ten times closer to the scaled state `target` than `from` is (or within Newton-level agreement).
bool newton_heads_for(const TappingModel& model, const Eigen::Vector2d& from, const Eigen::Vector2d& target, int n,
                      double omega, const SimulationOptions& simulation) {
  const double before = (from - target).norm();
  try {
    const StroboscopicMap m = stroboscopic_map(model, {from.x(), from.y() * omega}, n, simulation);
    const Eigen::Matrix2d jac = m.sensitivity.topLeftCorner<2, 2>() - Eigen::Matrix2d::Identity();
    const Eigen::FullPivLU<Eigen::Matrix2d> lu(jac);
    if (!lu.isInvertible()) return false;
    const Eigen::Vector2d residual(m.end.position - from.x(), m.end.velocity - from.y() * omega);
    const Eigen::Vector2d step = -lu.solve(residual);
    const Eigen::Vector2d after = from + Eigen::Vector2d(step.x(), step.y() / omega);
    const double scale = std::max(1.0, target.norm());
    return after.allFinite() && (after - target).norm() <= std::max(0.1 * before, 1e-8 * scale);
  } catch (const NumericalFailure&) {
    return false;
  }
}

}  // namespace

std::optional<PeriodicOrbit> follow_branch(const TappingModel& base, const PeriodicOrbit& from, double l_to,
                                           const ShootingOptions& shooting, int max_substeps) {
  validate::finite("separation", l_to);
  validate::require(max_substeps >= 1, "max_substeps", max_substeps, ">= 1");
  const double omega = base.drive.frequency;
  const int n = from.period_multiple;
  const double span = l_to - from.separation;
  if (span == 0.0) return from.stable ? std::optional<PeriodicOrbit>(from) : std::nullopt;
  const double scale = std::max(1.0, scaled(from.initial, omega).norm());
  // below this sub-step the branch is taken to end (fold, or a corner into another branch)
  const double h_min = 1e-5 * std::max(1.0, std::abs(span));
  // from the tangent prediction Newton converges in a few iterations; a slow start means the step is too long
  ShootingOptions quick = shooting;
  quick.max_iterations = std::min(quick.max_iterations, 8);
  const double closeness = 1e-8 * scale;  // Newton-level agreement
  PeriodicOrbit current = from;
  if (!current.stable) return std::nullopt;
  double h = span;  // try the whole step first
  for (int k = 0; k < max_substeps; ++k) {
    const double remaining = l_to - current.separation;
    if (remaining == 0.0) return current;
    if (std::abs(h) > std::abs(remaining)) h = remaining;
    const auto slope = branch_slope(current, omega);
    if (!slope) return std::nullopt;
    const double l_next = std::abs(remaining - h) <= 1e-14 * std::max(1.0, std::abs(l_to)) ? l_to : current.separation + h;
    const Eigen::Vector2d z = scaled(current.initial, omega);
    const Eigen::Vector2d predicted = z + (l_next - current.separation) * *slope;
    std::optional<PeriodicOrbit> next;
    try {
      next = try_shoot(base.with_separation(l_next), {predicted.x(), predicted.y() * omega}, n, quick);
    } catch (const NumericalFailure&) {
      next.reset();
    }
    bool accepted = false;
    if (next && next->stable && next->period_multiple == n) {
      // continuity, both ways: (1) the corrector moves the prediction by at most |Δl| times the larger of the two
      // branch slopes (O(Δl²) on a smooth branch, O(Δl) at a corner where the slope changes, e.g. grazing; another
      // branch stays a finite distance away however small Δl is); (2) the step taken back from the new orbit
      // returns to the current one (after a jump, Newton from the new orbit's tangent prediction lands on the
      // other branch's continuation instead — this catches a jump hidden inside a long step)
      const double dl = l_next - current.separation;
      const auto slope_next = branch_slope(*next, omega);
      const double bound = std::abs(dl) * std::max(slope->norm(), slope_next ? slope_next->norm() : 0.0) + closeness;
      accepted = slope_next && (scaled(next->initial, omega) - predicted).norm() <= bound;
      if (accepted) {
        const Eigen::Vector2d back_guess = scaled(next->initial, omega) - dl * *slope_next;
        const TappingModel at_current = base.with_separation(current.separation);
        // usually one Newton step from the backward prediction shows where it goes: it closes 90 % of the
        // distance to the current orbit (quadratic convergence towards it). Otherwise Newton decides in full.
        accepted = newton_heads_for(at_current, back_guess, z, n, omega, quick.simulation);
        if (!accepted) {
          std::optional<PeriodicOrbit> back;
          try {
            back = try_shoot(at_current, {back_guess.x(), back_guess.y() * omega}, n, quick);
          } catch (const NumericalFailure&) {
            back.reset();
          }
          accepted = back && (scaled(back->initial, omega) - z).norm() <= 1e-6 * scale;
        }
      }
    }
    if (accepted) {
      current = *next;
      current.separation = l_next;
      h *= 2.0;  // grow again after a successful sub-step
      continue;
    }
    h *= 0.5;
    if (std::abs(h) < h_min) return std::nullopt;
  }
  return std::nullopt;
}

namespace {

/// One instrument step: continue `previous` (at the previous separation) to the model's separation.
SweepPoint continue_point(const TappingModel& model, const SweepPoint& previous, SweepDirection direction,
                          const SweepOptions& options) {
  const double omega = model.drive.frequency;
  if (previous.periodic) {
    // follow the branch of the previous orbit to the new separation (sub-stepping when needed)
    if (auto orbit = follow_branch(model, previous.orbit, model.separation, options.shooting, options.max_substeps)) {
      SweepPoint p;
      p.separation = model.separation;
      p.direction = direction;
      p.orbit = *orbit;
      return p;
    }
  }
  // The branch ends (fold, stability loss, or a corner into another branch) before the new separation: do what
  // the instrument does — the tip keeps moving from where it was and settles on whatever attracts it.
  SweepPoint p = from_transient(model, previous.orbit.initial, direction, options);
  if (p.periodic && previous.periodic) {
    // Not a jump if the branch of the new orbit, followed back to the previous separation through stable orbits
    // without a fold, arrives at the previous orbit (the forward follow can fail where the backward one does
    // not, e.g. through a grazing corner entered from the other side).
    const auto back = follow_branch(model, p.orbit, previous.separation, options.shooting, options.max_substeps);
    const double scale = std::max(1.0, magnitude(previous.orbit.initial, omega));
    if (back && back->period_multiple == previous.orbit.period_multiple &&
        distance(back->initial, previous.orbit.initial, omega) <= 1e-6 * scale)
      p.jumped = false;
  }
  return p;
}

std::vector<SweepPoint> run_direction(const TappingModel& base, const std::vector<double>& ls, SweepPoint first,
                                      SweepDirection direction, const SweepOptions& options,
                                      std::vector<double>& jumps) {
  std::vector<SweepPoint> out;
  out.reserve(ls.size());
  first.direction = direction;
  out.push_back(first);
  if (options.progress) options.progress(1);
  for (std::size_t k = 1; k < ls.size(); ++k) {
    options.cancellation.check();
    out.push_back(continue_point(base.with_separation(ls[k]), out[k - 1], direction, options));
    if (out.back().jumped) jumps.push_back(ls[k]);
    if (options.progress) options.progress(1);
  }
  return out;
}

}  // namespace

namespace detail {

void finish_points(const TappingModel& base, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   bool harmonic_balance, bool parallel, const Cancellation& cancellation) {
  std::optional<HarmonicBalance> hb;  // branch scan once, cheap queries
  if (harmonic_balance) hb.emplace(base);  // any law (closed form for piecewise-linear ones)
  ExceptionCollector errors;
#pragma omp parallel for schedule(dynamic) if (parallel)
  for (std::size_t i = 0; i < points.size(); ++i) {
    errors.run([&] {
      cancellation.check();
      SweepPoint& p = points[i];
      p.metrics = analyse_orbit(base.with_separation(p.separation), p.orbit, simulation);
      if (hb) attach_from(hb->solutions(p.separation), p);
    });
  }
  errors.rethrow();
}

}  // namespace detail

SweepResult sweep_instrument(const TappingModel& base, double l_min, double l_max, int points,
                             const SweepOptions& options) {
  check_range(l_min, l_max, points);
  std::vector<double> up(points);
  for (int k = 0; k < points; ++k) up[k] = l_min + (l_max - l_min) * k / (points - 1);
  up.front() = l_min;
  up.back() = l_max;
  return sweep_instrument(base, up, options);
}

SweepResult sweep_instrument(const TappingModel& base, std::vector<double> separations, const SweepOptions& options) {
  for (double l : separations) validate::finite("separations", l);
  std::sort(separations.begin(), separations.end());
  separations.erase(std::unique(separations.begin(), separations.end()), separations.end());
  validate::require(separations.size() >= 2, "separations", static_cast<double>(separations.size()),
                    "at least 2 distinct separations");
  options.validate();
  const std::vector<double> up = separations;
  const std::vector<double> down(separations.rbegin(), separations.rend());
  const double l_max = up.back();
  // start far from the sample: the free response, settled if it touches at l_max
  const TappingModel start_model = base.with_separation(l_max);
  SweepPoint start;
  start.separation = l_max;
  std::optional<PeriodicOrbit> orbit;
  try {
    orbit = try_shoot(start_model, free_response_state(start_model), 1, options.shooting);
  } catch (const NumericalFailure&) {
    orbit.reset();
  }
  if (orbit && orbit->stable)
    start.orbit = *orbit;
  else
    start = from_transient(start_model, free_response_state(start_model), SweepDirection::approach, options);
  start.jumped = false;

  SweepResult result;
  result.approach = run_direction(base, down, start, SweepDirection::approach, options, result.approach_jumps);
  SweepPoint turn = result.approach.back();
  turn.jumped = false;
  result.retract = run_direction(base, up, turn, SweepDirection::retract, options, result.retract_jumps);
  detail::finish_points(base, result.approach, options.shooting.simulation, options.harmonic_balance, options.parallel,
                        options.cancellation);
  detail::finish_points(base, result.retract, options.shooting.simulation, options.harmonic_balance, options.parallel,
                        options.cancellation);
  return result;
}

std::vector<OrbitSearchResult> sweep_grid(const TappingModel& base, const std::vector<double>& separations,
                                          const OrbitSearchOptions& options,
                                          const std::function<void(long)>& progress) {
  for (double l : separations) validate::finite("separation", l);
  std::vector<OrbitSearchResult> out(separations.size());
  OrbitSearchOptions inner = options;
  inner.parallel = false;  // parallel over separations instead
  ExceptionCollector errors;
#pragma omp parallel for schedule(dynamic) if (options.parallel)
  for (std::size_t i = 0; i < separations.size(); ++i) {
    errors.run([&] {
      options.cancellation.check();
      out[i] = find_orbits(base.with_separation(separations[i]), inner);
      if (progress) {
#pragma omp critical(afmkit_grid_progress)
        progress(1);
      }
    });
  }
  errors.rethrow();
  return out;
}

}  // namespace afmkit::tapping
