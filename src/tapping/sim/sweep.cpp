#include <algorithm>
#include "afmkit/tapping/sweep.hpp"

#include <cmath>
#include <exception>
#include <limits>
#include <optional>

#include <Eigen/LU>

#include <fmt/format.h>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/parallel.hpp"
#include "afmkit/core/validate.hpp"
#include "sweep_points.hpp"
#include "phase_space.hpp"

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
  validate::require(state_resolution > 0 && state_resolution <= 1, "state_resolution", state_resolution, "in (0, 1]");
  validate::require(transient_step > 0 && transient_step <= 1, "transient_step", transient_step, "in (0, 1]");
  validate::require(jump_tolerance >= 1e-12 && jump_tolerance <= 1e-2, "jump_tolerance", jump_tolerance,
                    "in [1e-12, 1e-2]");
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

/// The length scale of the sweep's tolerances: the free amplitude.
double base_amplitude(const TappingModel& model) { return std::max(model.free_amplitude(), 1e-300); }

void check_range(const SweepParameter& parameter, double l_min, double l_max, int points) {
  const std::string lo = parameter.name() + "_min", hi = parameter.name() + "_max";
  validate::finite(lo, l_min);
  validate::finite(hi, l_max);
  validate::require(l_min < l_max, lo, l_min, fmt::format("< {} = {}", hi, l_max));
  validate::require(points >= 2, "points", points, ">= 2");
}

/// Settle a transient from `state` at the parameter value `value`; the point is marked jumped.
SweepPoint from_transient(const detail::ParameterPath& path, double value, TipState state, SweepDirection direction,
                          const SweepOptions& options) {
  const TappingModel model = path.at(value);
  SweepPoint p;
  p.separation = model.separation;
  p.parameter = value;
  p.direction = direction;
  p.jumped = true;
  TransientOptions transient = options.transient;
  transient.cancellation = options.cancellation;  // a long transient stops within a chunk on request
  const TransientOutcome t = settle(model, state, transient, options.shooting);
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
/// The same along any parameter p: −(M − I)⁻¹ ∂P/∂p (`sensitivity` = ∂P/∂p at the orbit, ParameterPath).
std::optional<Eigen::Vector2d> branch_slope(const PeriodicOrbit& orbit, const Eigen::Vector2d& sensitivity,
                                            double omega) {
  const Eigen::Matrix2d j = orbit.monodromy - Eigen::Matrix2d::Identity();
  const Eigen::FullPivLU<Eigen::Matrix2d> lu(j);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Vector2d dydl = -lu.solve(sensitivity);  // d(x, ẋ)/dl
  if (!dydl.allFinite()) return std::nullopt;
  return Eigen::Vector2d(dydl.x(), dydl.y() / omega);
}

/// Whether one Newton step for the fixed point of the stroboscopic map, taken from the scaled state `from`,
/// lands ten times closer to the scaled state `target` than `from` is (or within Newton-level agreement).
/// `target_monodromy`: the Jacobian of the map at the target orbit, used for the step instead of the one at
/// `from` when given (the map is then evaluated without sensitivities: a Newton step with the Jacobian at the
/// root is as good to second order in the distance, and a guess in another basin still steps away from it).
bool newton_heads_for(const TappingModel& model, const Eigen::Vector2d& from, const Eigen::Vector2d& target, int n,
                      double omega, const SimulationOptions& simulation, bool memory,
                      const Eigen::Matrix2d* target_monodromy = nullptr) {
  const double before = (from - target).norm();
  try {
    SimulationOptions o = simulation;
    o.sensitivity = target_monodromy == nullptr;
    const SimulationResult m = simulate(model, 0.0, {from.x(), from.y() * omega, memory}, n * model.period(), o);
    const Eigen::Matrix2d jac =
        (target_monodromy ? *target_monodromy : Eigen::Matrix2d(m.sensitivity.topLeftCorner<2, 2>())) -
        Eigen::Matrix2d::Identity();
    const Eigen::FullPivLU<Eigen::Matrix2d> lu(jac);
    if (!lu.isInvertible()) return false;
    const Eigen::Vector2d residual(m.state.position - from.x(), m.state.velocity - from.y() * omega);
    const Eigen::Vector2d step = -lu.solve(residual);
    const Eigen::Vector2d after = from + Eigen::Vector2d(step.x(), step.y() / omega);
    const double scale = std::max(1.0, target.norm());
    return after.allFinite() && (after - target).norm() <= std::max(0.1 * before, 1e-8 * scale);
  } catch (const NumericalFailure&) {
    return false;
  }
}

}  // namespace

namespace {

/// Stability margins of a period-n orbit of the 2-D stroboscopic map (Jury): det(I − M) = (1 − λ₁)(1 − λ₂) and
/// det(I + M) = (1 + λ₁)(1 + λ₂). With |det M| < 1 the orbit is stable iff both are positive; a real multiplier
/// crosses +1 where the first vanishes (fold, branch point) and −1 where the second does (period doubling).
Eigen::Vector2d stability_margins(const Eigen::Matrix2d& m) {
  const double tr = m.trace(), det = m.determinant();
  return {1.0 - tr + det, 1.0 + tr + det};
}

/// Whether the margins of `next` show the stability resolved over the sub-step from `current`: neither margin
/// shrank by more than half (above the rounding level of the monodromy). A branch losing stability is approached
/// in sub-steps that shorten as the margin vanishes, so the bisection beyond it starts next to the change.
bool margins_resolved(const PeriodicOrbit& current, const PeriodicOrbit& next) {
  const Eigen::Vector2d a = stability_margins(current.monodromy), b = stability_margins(next.monodromy);
  constexpr double noise = 1e-9;
  return b.x() >= 0.5 * a.x() - noise && b.y() >= 0.5 * a.y() - noise;
}

/// How far the Floquet multipliers moved between two orbits (the larger move of the closer pairing). A pair that
/// turns around the unit circle (the effective stiffness of the orbit changing fast, e.g. in an attractive well)
/// passes −1 and +1 on the way; a sub-step that moves a multiplier by more than kMaxMultiplierMove could have
/// crossed the unit circle and back unseen.
double multiplier_move(const PeriodicOrbit& a, const PeriodicOrbit& b) {
  const auto& x = a.floquet_multipliers;
  const auto& y = b.floquet_multipliers;
  return std::min(std::max(std::abs(x[0] - y[0]), std::abs(x[1] - y[1])),
                  std::max(std::abs(x[0] - y[1]), std::abs(x[1] - y[0])));
}
constexpr double kMaxMultiplierMove = 0.25;

}  // namespace

namespace {
/// An orbit of the followed branch before the one followed from (scaled state z = (x, ẋ/ω) at the parameter value
/// `at`): with the orbits behind, Newton starts from the Hermite polynomial through them and the one followed from.
struct BranchBehind {
  Eigen::Vector2d z;
  double at = 0.0;
  Eigen::Matrix2d monodromy = Eigen::Matrix2d::Identity();  // its M (the Jacobian of Newton's start, extrapolated)
  std::optional<Eigen::Vector2d> slope;  // dz/dp of its branch where known (free for the separation)
};
/// The orbits behind, the nearest first (at most kMaxBehind, each further behind than the one before).
using BranchHistory = std::vector<BranchBehind>;
constexpr std::size_t kMaxBehind = 2;

/// follow_stable_branch along any parameter: `from` is an orbit at p = l_from, l_to the value to reach.
BranchFollow follow_along(const detail::ParameterPath& path, const PeriodicOrbit& from, double l_from, double l_to,
                          const SweepOptions& options, BranchHistory behind = {});
}  // namespace

BranchFollow follow_stable_branch(const TappingModel& base, const PeriodicOrbit& from, double l_to,
                                  const SweepOptions& options) {
  validate::finite("separation", l_to);
  options.validate();
  const SweepParameter separation = SweepParameter::separation();
  return follow_along(detail::make_path(base, separation, from.separation, l_to), from, from.separation, l_to,
                      options);
}

namespace {

/// Newton's starting guess at l_next: the tangent prediction `predicted` from z (at `at`, slope `slope`) raised in
/// order by the orbits behind: the Hermite polynomial through z with its slope and each orbit behind with its slope
/// where known (Newton's form on the confluent nodes at, at, p₁, p₁, p₂, …), term by term while each term is at most
/// half the one before (a smooth branch: with the two grid points behind and their slopes O(Δl⁶) off instead of
/// the quadratic's O(Δl³); at a corner or a fold between the higher terms say nothing and are left out).
/// `monodromy` (M of the orbit at z on entry): with a guess above the tangent, the Jacobian Newton starts from at
/// l_next, extrapolated in l through the orbits' M by the same rule (at high Q, M − I is nearly singular and
/// magnifies the Jacobian's error, so Broyden's iterations from M(l) alone were most of the cost of a coarse grid).
Eigen::Vector2d starting_guess(const Eigen::Vector2d& predicted, const Eigen::Vector2d& z, const Eigen::Vector2d& slope,
                               double at, double l_next, const BranchHistory& behind, Eigen::Matrix2d& monodromy) {
  const double ahead = l_next - at;
  // the nodes: each orbit behind must lie further behind than the one before
  std::vector<double> t{at, at};
  std::vector<Eigen::Vector2d> f{z, z};  // divided differences, computed in place (Newton's form)
  std::vector<Eigen::Matrix2d> m{monodromy};  // M's divided differences on the distinct nodes
  std::vector<double> tm{at};
  double last = at;
  for (const BranchBehind& b : behind) {
    const double back = b.at - at;
    if (!(back != 0.0) || (back > 0) == (ahead > 0) || std::abs(b.at - at) <= std::abs(last - at)) break;
    last = b.at;
    t.push_back(b.at);
    f.push_back(b.z);
    tm.push_back(b.at);
    m.push_back(b.monodromy);
    if (!b.slope) break;  // (a value without its slope ends the nodes: the next would need it)
    t.push_back(b.at);
    f.push_back(b.z);
  }
  if (t.size() == 2) return predicted;
  // confluent divided differences: f[t_i, t_i] = slope at t_i
  const std::size_t count = t.size();
  std::vector<Eigen::Vector2d> slopes(count, Eigen::Vector2d::Zero());
  slopes[0] = slope;
  for (std::size_t i = 2, k = 0; i < count; ++i)
    if (t[i] == t[i - 1]) slopes[i - 1] = *behind[k++].slope;
  std::vector<Eigen::Vector2d> coefficient{f[0]};
  for (std::size_t order = 1; order < count; ++order) {
    for (std::size_t i = count - 1; i >= order; --i) {
      f[i] = t[i] == t[i - order] ? slopes[i - 1] : Eigen::Vector2d((f[i] - f[i - 1]) / (t[i] - t[i - order]));
    }
    coefficient.push_back(f[order]);
  }
  // the terms beyond the tangent, while they shrink
  Eigen::Vector2d guess = predicted;
  double product = ahead * ahead;  // Π (l_next − t_j), j < order, for order 2
  double previous = std::abs(ahead) * slope.norm();
  std::size_t used = 1;
  for (std::size_t order = 2; order < count; ++order) {
    const Eigen::Vector2d term = product * coefficient[order];
    if (!term.allFinite() || term.norm() > 0.5 * previous) break;
    guess += term;
    previous = term.norm();
    used = order;
    product *= l_next - t[order];
  }
  if (used < 2) return predicted;
  // M through the distinct nodes (as many as the guess used: the quadratic guess extrapolates M linearly)
  const std::size_t nodes = std::min(tm.size(), used == 2 ? std::size_t{2} : std::size_t{3});
  for (std::size_t order = 1; order < nodes; ++order)
    for (std::size_t i = nodes - 1; i >= order; --i) m[i] = (m[i] - m[i - 1]) / (tm[i] - tm[i - order]);
  Eigen::Matrix2d extrapolated = m[0];
  double factor = 1.0;
  double before = std::numeric_limits<double>::infinity();
  for (std::size_t order = 1; order < nodes; ++order) {
    factor *= l_next - tm[order - 1];
    const Eigen::Matrix2d term = factor * m[order];
    if (!term.allFinite() || (order > 1 && term.norm() > 0.5 * before)) break;
    extrapolated += term;
    before = term.norm();
  }
  if (extrapolated.allFinite()) monodromy = extrapolated;
  return guess;
}

BranchFollow follow_along(const detail::ParameterPath& path, const PeriodicOrbit& from, double l_from, double l_to,
                          const SweepOptions& options, BranchHistory behind) {
  const TappingModel& base = path.base;
  const ShootingOptions& shooting = options.shooting;
  const double omega = base.drive.frequency;
  const int n = from.period_multiple;
  BranchFollow out;
  out.last = from;
  out.last_parameter = l_from;
  out.failed_at = l_from;
  const double span = l_to - l_from;
  if (!from.stable) return out;  // nothing stable to follow
  if (span == 0.0) {
    out.reached = from;
    return out;
  }
  const double scale = std::max(1.0, scaled(from.initial, omega).norm());
  const double amplitude = base_amplitude(base);
  // below this sub-step the branch is taken to end (fold, loss of stability, or a corner into another branch)
  // (parameter units: the free amplitude over the scale of the parameter, ParameterPath)
  const double h_min = options.jump_tolerance * amplitude / path.scale;
  // largest move of the scaled state per sub-step (relative to the larger of A_free and the state, e.g. a deep
  // static deflection in contact)
  const double max_move = options.state_resolution * amplitude;
  // from the tangent prediction Newton converges in a few iterations; a slow start means the step is too long
  ShootingOptions quick = shooting;
  quick.max_iterations = std::min(quick.max_iterations, 8);
  const double closeness = 1e-8 * scale;  // Newton-level agreement
  PeriodicOrbit current = from;
  double at = l_from;  // the parameter value of `current`
  const SimulationOptions& simulation = shooting.simulation;
  std::optional<Eigen::Vector2d> slope;
  try {
    slope = branch_slope(current, path.orbit_derivative(current, at, simulation), omega);
  } catch (const NumericalFailure&) {
    slope.reset();  // no derivative of the map: no branch to follow from here
  }
  double h = span;  // try the whole step first
  // Whether Newton's starting guess is expected within the tolerance (as the last one was): then the map is
  // evaluated with its sensitivities at once (one run where it is), else Broyden's iterations on the cheap map
  // come first (try_shoot_near). Either way the sensitivities of the orbit are those at it.
  // (`iterations` 0: the first evaluation at the guess was within the tolerance, on either path)
  bool guess_converges = from.iterations == 0;
  for (int k = 0; k < options.max_substeps; ++k) {
    const double remaining = l_to - at;
    if (remaining == 0.0) break;
    if (std::abs(h) > std::abs(remaining)) h = remaining;
    if (!slope) {
      out.failed_at = at + h;
      return out;  // M − I singular: a fold (reached exactly)
    }
    const double l_next = std::abs(remaining - h) <= 1e-14 * std::max(1.0, std::abs(l_to)) ? l_to : at + h;
    const Eigen::Vector2d z = scaled(current.initial, omega);
    const Eigen::Vector2d predicted = z + (l_next - at) * *slope;
    ++out.substeps;
    const TappingModel at_next = path.at(l_next);
    // Newton at l_next: lazy (try_shoot_near: the sensitivities once, at the converged orbit) from the quadratic
    // guess, then from the tangent prediction; eager (try_shoot: at every iteration) from the tangent prediction
    auto solve = [&](bool lazy) {
      std::optional<PeriodicOrbit> o;
      try {
        if (lazy) {
          PeriodicOrbit near = current;  // its Jacobian, extrapolated to l_next with the quadratic guess
          const Eigen::Vector2d start = starting_guess(predicted, z, *slope, at, l_next, behind, near.monodromy);
          o = try_shoot_near(at_next, {start.x(), start.y() * omega, current.initial.contact}, near, quick,
                             !guess_converges);
          if (!o && start != predicted)
            o = try_shoot_near(at_next, {predicted.x(), predicted.y() * omega, current.initial.contact}, current, quick);
        } else {
          o = try_shoot(at_next, {predicted.x(), predicted.y() * omega, current.initial.contact}, n, quick);
        }
      } catch (const NumericalFailure&) {
        o.reset();
      }
      return o;
    };
    std::optional<PeriodicOrbit> next;
    std::optional<Eigen::Vector2d> slope_next;  // of the new orbit's branch
    bool accepted = false;
    bool resolved = true;  // false: the sub-step was too long to see the stability (not a failure of the branch)
    auto judge = [&](bool lazy) {
      slope_next.reset();
      accepted = false;
      resolved = true;
      if (!(next && next->stable && next->period_multiple == n)) return;
      // continuity, both ways: (1) the corrector moves the prediction by at most |Δl| times the larger of the two
      // branch slopes (O(Δl²) on a smooth branch, O(Δl) at a corner where the slope changes, e.g. grazing; another
      // branch stays a finite distance away however small Δl is); (2) the step taken back from the new orbit
      // returns to the current one (after a jump, Newton from the new orbit's tangent prediction lands on the
      // other branch's continuation instead — this catches a jump hidden inside a long step)
      const double dl = l_next - at;
      try {
        slope_next = branch_slope(*next, path.orbit_derivative(*next, l_next, simulation), omega);
      } catch (const NumericalFailure&) {
        slope_next.reset();
      }
      const double bound = std::abs(dl) * std::max(slope->norm(), slope_next ? slope_next->norm() : 0.0) + closeness;
      accepted = slope_next && (scaled(next->initial, omega) - predicted).norm() <= bound;
      // (3) the Floquet multipliers along the step: the margins to instability and the move of the orbit are
      // resolved (a step over a fold pair or an interval of instability is shortened until it is seen)
      if (accepted && std::abs(dl) > 2.0 * h_min &&
          (!margins_resolved(current, *next) || multiplier_move(current, *next) > kMaxMultiplierMove ||
           (scaled(next->initial, omega) - z).norm() > max_move * std::max(1.0, z.norm() / amplitude))) {
        accepted = false;
        resolved = false;
      }
      if (accepted) {
        const Eigen::Vector2d back_guess = scaled(next->initial, omega) - dl * *slope_next;
        const TappingModel at_current = path.at(at);
        // usually one Newton step from the backward prediction shows where it goes: it closes 90 % of the
        // distance to the current orbit (quadratic convergence towards it). Otherwise Newton decides in full.
        accepted = newton_heads_for(at_current, back_guess, z, n, omega, quick.simulation, current.initial.contact,
                                    lazy ? &current.monodromy : nullptr);
        if (!accepted) {
          std::optional<PeriodicOrbit> back;
          try {
            const TipState guess{back_guess.x(), back_guess.y() * omega, current.initial.contact};
            back = lazy ? try_shoot_near(at_current, guess, current, quick) : try_shoot(at_current, guess, n, quick);
          } catch (const NumericalFailure&) {
            back.reset();
          }
          accepted = back && (scaled(back->initial, omega) - z).norm() <= 1e-6 * scale;
        }
      }
    };
    next = solve(options.lazy_sensitivities);
    judge(options.lazy_sensitivities);
    if (options.lazy_sensitivities && resolved && !accepted) {
      // Broyden's iterates may reach another orbit nearby than Newton's (in a period-doubling cascade orbits lie
      // close) or none: the sub-step is refused only as the eager path refuses it
      next = solve(false);
      judge(false);
    }
    if (accepted) {
      behind.insert(behind.begin(), BranchBehind{z, at, current.monodromy, slope});
      if (behind.size() > kMaxBehind) behind.pop_back();
      current = *next;
      at = l_next;
      slope = slope_next;
      out.last = current;
      out.last_parameter = at;
      guess_converges = next->iterations == 0;
      h *= 2.0;  // grow again after a successful sub-step
      continue;
    }
    if (resolved) out.failed_at = l_next;  // no stable continuation at l_next: the bracket's far end
    h *= 0.5;
    if (std::abs(h) < h_min) return out;
  }
  if (at == l_to) {
    out.reached = current;
  } else {
    out.failed_at = std::numeric_limits<double>::quiet_NaN();  // budget spent before l_to
  }
  return out;
}

}  // namespace

std::optional<PeriodicOrbit> follow_branch(const TappingModel& base, const PeriodicOrbit& from, double l_to,
                                           const ShootingOptions& shooting, int max_substeps) {
  SweepOptions options;
  options.shooting = shooting;
  options.max_substeps = max_substeps;
  return follow_stable_branch(base, from, l_to, options).reached;
}

namespace {

/// At most this many jumps, or transient sub-steps through a non-periodic response, between two grid points
/// (then the tip is left to settle at the grid point).
constexpr int kMaxPassesPerStep = 64;

/// Whether the orbit reached from `p` (at p_at, followed back to `previous` at its value previous_at) is the same
/// branch.
bool connects_back(const detail::ParameterPath& path, const PeriodicOrbit& p, double p_at,
                   const PeriodicOrbit& previous, double previous_at, const SweepOptions& options) {
  const double omega = path.base.drive.frequency;
  const auto back = follow_along(path, p, p_at, previous_at, options).reached;
  const double scale = std::max(1.0, detail::phase_magnitude(previous.initial, omega));
  return back && back->period_multiple == previous.period_multiple &&
         detail::phase_distance(back->initial, previous.initial, omega) <= 1e-6 * scale;
}

SweepJump make_jump(const detail::ParameterPath& path, double separation, double tolerance, SweepDirection direction,
                    bool located, const PeriodicOrbit& from, double from_at, const SweepPoint& landed) {
  SweepJump j;
  j.parameter = separation;
  j.separation = path.parameter.is_separation() ? separation : path.at(separation).separation;
  j.from_parameter = from_at;
  j.to_parameter = landed.parameter;
  j.tolerance = tolerance;
  j.direction = direction;
  j.located = located;
  j.from = from;
  j.to = landed.orbit;
  j.landed_periodic = landed.periodic;
  return j;
}

/// One instrument step: continue `previous` (at the previous separation) to the model's separation, through every
/// jump on the way (appended to `jumps`). A stable orbit is followed along its branch; where the branch ceases to
/// be stable the tip lands (transient) just beyond; a response that does not settle is stepped by transients in
/// sub-steps of transient_step·A_free until it settles on a periodic orbit.
SweepPoint continue_point(const detail::ParameterPath& path, double l_to, const SweepPoint& previous,
                          SweepDirection direction, const SweepOptions& options, std::vector<SweepJump>& jumps,
                          const SweepPoint* before = nullptr, const SweepPoint* before2 = nullptr) {
  if (previous.periodic && !previous.orbit.stable) {
    // a neutrally stable periodic response (e.g. a tip resting on the sample) has no stable branch to follow: it
    // settles (or not) at the new value; a jump is known to the grid's resolution only
    SweepPoint p = from_transient(path, l_to, previous.orbit.initial, direction, options);
    if (p.periodic && connects_back(path, p.orbit, l_to, previous.orbit, previous.parameter, options)) p.jumped = false;
    if (p.jumped)
      jumps.push_back(make_jump(path, l_to, std::abs(l_to - previous.parameter), direction, false, previous.orbit,
                                previous.parameter, p));
    return p;
  }
  const double step_np = options.transient_step * base_amplitude(path.base) / path.scale;
  bool following = previous.periodic;  // else: a non-periodic response, stepped by transients
  PeriodicOrbit orbit = previous.orbit;  // the followed orbit, or (non-periodic) the last state in orbit.initial
  double l_at = previous.parameter;
  bool jumped = false;
  for (int pass = 0; pass < kMaxPassesPerStep; ++pass) {
    const bool last_pass = pass + 1 == kMaxPassesPerStep;
    if (!following) {
      const double l_next = std::abs(l_to - l_at) <= step_np || last_pass ? l_to : l_at + std::copysign(step_np, l_to - l_at);
      SweepPoint p = from_transient(path, l_next, orbit.initial, direction, options);
      if (p.periodic) {  // it settled: the tip leaves the non-periodic response (known to the sub-step)
        jumps.push_back(make_jump(path, 0.5 * (l_at + l_next), 0.5 * std::abs(l_next - l_at), direction, false, orbit,
                                  l_at, p));
        jumped = true;
      }
      if (l_next == l_to || (p.periodic && !p.orbit.stable)) {
        if (l_next != l_to) p = from_transient(path, l_to, p.orbit.initial, direction, options);
        p.jumped = jumped;
        return p;
      }
      following = p.periodic;
      orbit = p.orbit;
      l_at = l_next;
      continue;
    }
    // the points before the previous one, on the same stable branch (no jump, the same period and memory), with
    // the slopes of their branch where they are free (the separation: the map's column ∂P/∂l at the orbit)
    BranchHistory behind;
    if (pass == 0 && !previous.jumped) {
      const double omega = path.base.drive.frequency;
      for (const SweepPoint* b : {before, before ? before2 : nullptr}) {
        if (!(b && b->periodic && b->orbit.stable && b->orbit.period_multiple == orbit.period_multiple &&
              b->orbit.initial.contact == orbit.initial.contact))
          break;
        std::optional<Eigen::Vector2d> slope;
        if (path.parameter.is_separation()) slope = branch_slope(b->orbit, b->orbit.separation_sensitivity, omega);
        behind.push_back(BranchBehind{scaled(b->orbit.initial, omega), b->parameter, b->orbit.monodromy, slope});
        if (b->jumped) break;  // the one before it is on another branch
      }
    }
    const BranchFollow f = follow_along(path, orbit, l_at, l_to, options, behind);
    if (f.reached) {
      SweepPoint p;
      p.separation = f.reached->separation;
      p.parameter = l_to;
      p.direction = direction;
      p.orbit = *f.reached;
      p.jumped = jumped;
      return p;
    }
    // The followed branch ceases to be stable in (last, failed_at] (budget spent: somewhere before l_to). Do what
    // the instrument does: the tip keeps moving from where it was and settles on whatever attracts it, just beyond.
    const double l_last = f.last_parameter;
    const bool located = std::isfinite(f.failed_at) && !last_pass;
    const double l_land = located ? f.failed_at : l_to;
    SweepPoint landed = from_transient(path, l_land, f.last.initial, direction, options);
    // Not a jump if the branch of the new orbit, followed back to the last stable orbit through stable orbits
    // without a fold, arrives at it (the forward follow can fail where the backward one does not, e.g. through a
    // grazing corner entered from the other side).
    if (!(landed.periodic && connects_back(path, landed.orbit, l_land, f.last, l_last, options))) {
      jumps.push_back(make_jump(path, located ? 0.5 * (l_last + l_land) : l_land,
                                std::abs(l_land - l_last) * (located ? 0.5 : 1.0), direction, located, f.last, l_last,
                                landed));
      jumped = true;
    }
    if (l_land == l_to || (landed.periodic && !landed.orbit.stable)) {
      if (l_land != l_to) landed = from_transient(path, l_to, landed.orbit.initial, direction, options);
      landed.jumped = jumped;
      return landed;
    }
    following = landed.periodic;
    orbit = landed.orbit;
    l_at = l_land;
  }
  return {};  // not reached: the last pass ends at l_to
}

std::vector<SweepPoint> run_direction(const detail::ParameterPath& path, const std::vector<double>& ls,
                                      SweepPoint first, SweepDirection direction, const SweepOptions& options,
                                      std::vector<SweepJump>& jumps) {
  std::vector<SweepPoint> out;
  out.reserve(ls.size());
  first.direction = direction;
  out.push_back(first);
  if (options.progress) options.progress(1);
  for (std::size_t k = 1; k < ls.size(); ++k) {
    options.cancellation.check();
    out.push_back(continue_point(path, ls[k], out[k - 1], direction, options, jumps, k >= 2 ? &out[k - 2] : nullptr,
                                 k >= 3 ? &out[k - 3] : nullptr));
    if (options.progress) options.progress(1);
  }
  return out;
}

}  // namespace

namespace detail {

void finish_points(const TappingModel& base, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   bool harmonic_balance, bool parallel, const Cancellation& cancellation) {
  std::optional<HarmonicBalance> hb;  // branch scan once, cheap queries
  if (harmonic_balance) hb.emplace(base, cancellation);  // any law (closed form for piecewise-linear ones)
  finish_points(base, points, simulation, hb ? &*hb : nullptr, parallel, cancellation);
}

void finish_points(const TappingModel& base, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   const HarmonicBalance* hb, bool parallel, const Cancellation& cancellation) {
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

void finish_points(const ParameterPath& path, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   bool harmonic_balance, bool parallel, const Cancellation& cancellation) {
  ExceptionCollector errors;
#pragma omp parallel for schedule(dynamic) if (parallel)
  for (std::size_t i = 0; i < points.size(); ++i) {
    errors.run([&] {
      cancellation.check();
      SweepPoint& p = points[i];
      const TappingModel model = path.at(p.parameter);
      p.metrics = analyse_orbit(model, p.orbit, simulation);
      // every point has its own model: one HB evaluation each, done where it is a closed form (piecewise-linear
      // laws, microseconds); for another law it traces a describing-function curve per point (7 ms for DMT to
      // 0.3 s for a table, measured): not evaluated (hb_* NaN, hb_solutions 0)
      if (harmonic_balance && model.law.piecewise_linear())
        attach_from(HarmonicBalance(model, cancellation).solutions(model.separation), p);
    });
  }
  errors.rethrow();
}

void finish_jumps(const ParameterPath& path, std::vector<SweepJump>& jumps, const SimulationOptions& simulation,
                  bool parallel) {
  ExceptionCollector errors;
#pragma omp parallel for schedule(dynamic) if (parallel)
  for (std::size_t i = 0; i < jumps.size(); ++i) {
    errors.run([&] {
      SweepJump& j = jumps[i];
      j.from_metrics = analyse_orbit(path.at(j.from_parameter), j.from, simulation);
      j.to_metrics = analyse_orbit(path.at(j.to_parameter), j.to, simulation);
    });
  }
  errors.rethrow();
}

}  // namespace detail

namespace {
// the computations of sweep_instrument and sweep_grid on checked input (below)
SweepResult sweep_checked(const TappingModel& base, const SweepParameter& parameter, const std::vector<double>& values,
                          const SweepOptions& options);
std::vector<OrbitSearchResult> grid_checked(const TappingModel& base, const std::vector<double>& separations,
                                            const OrbitSearchOptions& options,
                                            const std::function<void(long)>& progress);
}  // namespace

SweepResult sweep_instrument(const TappingModel& base, double l_min, double l_max, int points,
                             const SweepOptions& options) {
  return sweep_instrument(base, SweepParameter::separation(), l_min, l_max, points, options);
}

SweepResult sweep_instrument(const TappingModel& base, std::vector<double> separations, const SweepOptions& options) {
  return sweep_instrument(base, SweepParameter::separation(), std::move(separations), options);
}

SweepResult sweep_instrument(const TappingModel& base, const SweepParameter& parameter, double p_min, double p_max,
                             int points, const SweepOptions& options) {
  check_range(parameter, p_min, p_max, points);
  std::vector<double> up(points);
  for (int k = 0; k < points; ++k) up[k] = p_min + (p_max - p_min) * k / (points - 1);
  up.front() = p_min;
  up.back() = p_max;
  return sweep_instrument(base, parameter, up, options);
}

SweepResult sweep_instrument(const TappingModel& base, const SweepParameter& parameter, std::vector<double> values,
                             const SweepOptions& options) {
  const std::string key = parameter.is_separation() ? "separations" : parameter.name();
  for (double l : values) validate::finite(key, l);
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  validate::require(values.size() >= 2, key, static_cast<double>(values.size()),
                    parameter.is_separation() ? "at least 2 distinct separations" : "at least 2 distinct values");
  options.validate();
  // the input is checked: a value or model refused from here on was computed (core/computed.hpp), never the
  // user's error
  return computed("instrument sweep", [&] { return sweep_checked(base, parameter, values, options); });
}

std::vector<OrbitSearchResult> sweep_grid(const TappingModel& base, const std::vector<double>& separations,
                                          const OrbitSearchOptions& options,
                                          const std::function<void(long)>& progress) {
  for (double l : separations) validate::finite("separation", l);
  options.validate();
  return computed("grid of orbit searches", [&] { return grid_checked(base, separations, options, progress); });
}

namespace {

SweepResult sweep_checked(const TappingModel& base, const SweepParameter& parameter, const std::vector<double>& values,
                          const SweepOptions& options) {
  const std::vector<double> up = values;
  const std::vector<double> down(values.rbegin(), values.rend());
  const double l_max = up.back();
  const detail::ParameterPath path = detail::make_path(base, parameter, up.front(), l_max);
  // start far from the sample (or at the largest value of the parameter): the free response, settled if it touches
  const TappingModel start_model = path.at(l_max);
  SweepPoint start;
  start.separation = start_model.separation;
  start.parameter = l_max;
  std::optional<PeriodicOrbit> orbit;
  try {
    orbit = try_shoot(start_model, free_response_state(start_model), 1, options.shooting);
  } catch (const NumericalFailure&) {
    orbit.reset();
  }
  if (orbit && orbit->stable)
    start.orbit = *orbit;
  else
    start = from_transient(path, l_max, free_response_state(start_model), SweepDirection::approach, options);
  start.jumped = false;

  SweepResult result;
  result.approach = run_direction(path, down, start, SweepDirection::approach, options, result.jumps);
  if (options.retract) {
    SweepPoint turn = result.approach.back();
    turn.jumped = false;
    result.retract = run_direction(path, up, turn, SweepDirection::retract, options, result.jumps);
  }
  for (const SweepJump& j : result.jumps)
    (j.direction == SweepDirection::approach ? result.approach_jumps : result.retract_jumps).push_back(j.parameter);
  if (parameter.is_separation()) {
    // one harmonic balance of the model for both directions (for a law without closed forms its constructor
    // traces the whole curve: 5–20 ms)
    std::optional<HarmonicBalance> hb;
    if (options.harmonic_balance) hb.emplace(base, options.cancellation);
    const HarmonicBalance* beside = hb ? &*hb : nullptr;
    detail::finish_points(base, result.approach, options.shooting.simulation, beside, options.parallel,
                          options.cancellation);
    detail::finish_points(base, result.retract, options.shooting.simulation, beside, options.parallel,
                          options.cancellation);
  } else {
    detail::finish_points(path, result.approach, options.shooting.simulation, options.harmonic_balance,
                          options.parallel, options.cancellation);
    detail::finish_points(path, result.retract, options.shooting.simulation, options.harmonic_balance,
                          options.parallel, options.cancellation);
  }
  detail::finish_jumps(path, result.jumps, options.shooting.simulation, options.parallel);
  return result;
}

std::vector<OrbitSearchResult> grid_checked(const TappingModel& base, const std::vector<double>& separations,
                                            const OrbitSearchOptions& options,
                                            const std::function<void(long)>& progress) {
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

}  // namespace

}  // namespace afmkit::tapping
