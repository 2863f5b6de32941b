#include "afmkit/tapping/sweep.hpp"

#include <cmath>
#include <exception>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
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
  validate::require(jump_check_distance > 0, "jump_check_distance", jump_check_distance, "> 0");
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
  if (!base.law.piecewise_linear()) return;
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

/// One instrument step: continue `previous` (at the previous separation) to the model's separation.
SweepPoint continue_point(const TappingModel& model, const SweepPoint& previous, const SweepPoint* before_previous,
                          SweepDirection direction, const SweepOptions& options) {
  const double omega = model.drive.frequency;
  TipState guess = previous.orbit.initial;
  if (previous.periodic && before_previous && before_previous->periodic && !previous.jumped &&
      before_previous->orbit.period_multiple == previous.orbit.period_multiple) {
    // secant predictor along the branch
    const double r = (model.separation - previous.separation) / (previous.separation - before_previous->separation);
    guess.position += r * (previous.orbit.initial.position - before_previous->orbit.initial.position);
    guess.velocity += r * (previous.orbit.initial.velocity - before_previous->orbit.initial.velocity);
  }
  if (previous.periodic) {
    std::optional<PeriodicOrbit> orbit;
    try {
      orbit = try_shoot(model, guess, previous.orbit.period_multiple, options.shooting);
    } catch (const NumericalFailure&) {
      orbit.reset();
    }
    const double scale = std::max(1e-9, magnitude(previous.orbit.initial, omega));
    if (orbit && orbit->stable && distance(orbit->initial, guess, omega) <= options.jump_check_distance * scale) {
      SweepPoint p;
      p.separation = model.separation;
      p.direction = direction;
      p.orbit = *orbit;
      return p;
    }
  }
  // Newton failed, found an unstable orbit or moved far: do what the instrument does — the tip keeps moving
  // from where it was and settles on whatever attracts it.
  SweepPoint p = from_transient(model, previous.orbit.initial, direction, options);
  if (p.periodic && previous.periodic) {
    // Not a jump if the new orbit continues the previous branch: Newton from it at the previous separation
    // returns to the previous orbit (a long step on a steep branch, not the end of the branch).
    std::optional<PeriodicOrbit> back;
    try {
      back = try_shoot(model.with_separation(previous.separation), p.orbit.initial, p.orbit.period_multiple,
                       options.shooting);
    } catch (const NumericalFailure&) {
      back.reset();
    }
    const double scale = std::max(1e-9, magnitude(previous.orbit.initial, omega));
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
    const SweepPoint* before = k >= 2 ? &out[k - 2] : nullptr;
    out.push_back(continue_point(base.with_separation(ls[k]), out[k - 1], before, direction, options));
    if (out.back().jumped) jumps.push_back(ls[k]);
    if (options.progress) options.progress(1);
  }
  return out;
}

}  // namespace

namespace detail {

void finish_points(const TappingModel& base, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   bool harmonic_balance, bool parallel) {
  std::optional<HarmonicBalance> hb;  // branch scan once, cheap queries
  if (harmonic_balance && base.law.piecewise_linear()) hb.emplace(base);
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic) if (parallel)
  for (std::size_t i = 0; i < points.size(); ++i) {
    try {
      SweepPoint& p = points[i];
      p.metrics = analyse_orbit(base.with_separation(p.separation), p.orbit, simulation);
      if (hb) attach_from(hb->solutions(p.separation), p);
    } catch (...) {
#pragma omp critical(afmkit_sweep_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace detail

SweepResult sweep_instrument(const TappingModel& base, double l_min, double l_max, int points,
                             const SweepOptions& options) {
  check_range(l_min, l_max, points);
  options.validate();
  std::vector<double> down(points), up(points);
  for (int k = 0; k < points; ++k) {
    up[k] = l_min + (l_max - l_min) * k / (points - 1);
    down[points - 1 - k] = up[k];
  }
  up.front() = down.back() = l_min;
  up.back() = down.front() = l_max;
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
  detail::finish_points(base, result.approach, options.shooting.simulation, options.harmonic_balance, options.parallel);
  detail::finish_points(base, result.retract, options.shooting.simulation, options.harmonic_balance, options.parallel);
  return result;
}

std::vector<OrbitSearchResult> sweep_grid(const TappingModel& base, const std::vector<double>& separations,
                                          const OrbitSearchOptions& options,
                                          const std::function<void(long)>& progress) {
  for (double l : separations) validate::finite("separation", l);
  std::vector<OrbitSearchResult> out(separations.size());
  OrbitSearchOptions inner = options;
  inner.parallel = false;  // parallel over separations instead
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic) if (options.parallel)
  for (std::size_t i = 0; i < separations.size(); ++i) {
    try {
      out[i] = find_orbits(base.with_separation(separations[i]), inner);
      if (progress) {
#pragma omp critical(afmkit_grid_progress)
        progress(1);
      }
    } catch (...) {
#pragma omp critical(afmkit_grid_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
  return out;
}

}  // namespace afmkit::tapping
