#pragma once
// Time-domain simulation of the tapping cantilever (seed-1 eq. 8):
//   ẍ + 2ξω_n ẋ + ω_n² x = Γ cos(ωt) − h(x, ẋ),   h = −H(x + l, ẋ)
// The three concerns are separate (as in Boost.Odeint):
//   * what the system is      — TappingSystem (system.hpp): modes, branch accelerations, guards;
//   * how it is integrated    — Integrator::closed_form (exact flow of the piecewise-linear laws, eqs. 10/11/26)
//                               or Integrator::adaptive (Dormand–Prince 5(4) with dense output, any law);
//   * what is recorded        — a TrajectoryObserver (observer.hpp) receiving every smooth segment and event.
// Mode switches are events located on the guard (witness) functions of events.hpp: the gap x + l crossing a
// switching gap of the law (with its direction) and the sign change of ẋ (approach ↔ departure branch).
// Sticking (ẋ = 0 with both branches pushing back onto ẋ = 0) is a mode of its own: the tip rests until the
// drive can move it; it is counted, never looped on.
#include <Eigen/Core>

#include "afmkit/core/describe.hpp"

#include "afmkit/tapping/events.hpp"
#include "afmkit/tapping/model.hpp"
#include "afmkit/tapping/modes.hpp"

namespace afmkit::tapping {

class TrajectoryObserver;
class TappingSystem;

/// How the flow between events is computed.
enum class Integrator {
  automatic,    // closed_form for piecewise-linear laws, adaptive otherwise
  closed_form,  // exact (to rounding) flow of the linear modes; piecewise-linear laws only
  adaptive,     // DOP853 (order 8, 7th-order dense output) + event isolation on the dense output
};
const char* integrator_name(Integrator integrator);

struct SimulationOptions {
  Integrator integrator = Integrator::automatic;
  double relative_tolerance = 1e-10;  // adaptive integrator only
  double absolute_tolerance = 1e-12;  // adaptive integrator only (in model length units)
  /// Largest step of the adaptive integrator and of the closed-form guard scan, as a fraction of the shortest
  /// period present (drive period, damped mode period): a crossing can never be stepped over.
  double max_step_fraction = 1.0 / 24.0;
  /// First trial step of the adaptive integrator (model time; 0: 1e-3 of the drive period). A caller that runs
  /// the motion in pieces passes the step the last piece ended with (SimulationStats::next_step) instead of
  /// growing again from 1e-3 of a period; the error control accepts or shrinks it as any other step.
  double initial_step = 0.0;
  long max_events = 1'000'000;  // exceeded -> NumericalFailure
  long max_steps = 50'000'000;  // adaptive steps budget -> NumericalFailure
  /// Propagate ∂(x, ẋ, l)(t_end)/∂(x, ẋ, l)(t_begin) (variational equations + saltation matrices at events).
  bool sensitivity = false;

  /// The fields a user sets, declared once: key, help, unit, range (core/describe.hpp); the defaults are the
  /// initializers above. The command line's `--integrator`, `--relative-tolerance`, `--absolute-tolerance`.
  template <class Archive, class Self>
  static void describe(Archive& a, Self& o) {
    a.choice("integrator", o.integrator,
             "time integration: closed_form (exact, piecewise-linear laws), adaptive (DOP853, order 8, events located "
             "on its dense output; any law) or automatic",
             {{"automatic", Integrator::automatic},
              {"closed_form", Integrator::closed_form},
              {"adaptive", Integrator::adaptive}});
    a.real("relative_tolerance", o.relative_tolerance, "adaptive integrator relative tolerance", "dimensionless",
           Range::open(0.0, 1.0));
    a.real("absolute_tolerance", o.absolute_tolerance, "adaptive integrator absolute tolerance of the model state",
           "L (= nm in physical runs)", Range::positive());
  }
  void validate() const;  // InvalidParameter naming the key on bad values (the ranges of describe() and the rest)
};

/// Counters of one simulation.
struct SimulationStats {
  long events = 0;            // all mode switches
  long impacts = 0;           // entries into contact (gap falling through the lowest switching gap)
  long sticking_count = 0;    // entries into the sticking mode
  double sticking_duration = 0.0;  // total time spent sticking
  long steps = 0;             // closed-form guard-scan intervals or adaptive steps
  double next_step = 0.0;     // adaptive: the step the error control proposes at the end (for initial_step)
};

struct SimulationResult {
  double time = 0.0;
  TipState state;
  Mode mode;
  SimulationStats stats;
  /// ∂(x, ẋ, l)(time)/∂(x, ẋ, l)(t_begin) when SimulationOptions::sensitivity (identity otherwise).
  Eigen::Matrix3d sensitivity = Eigen::Matrix3d::Identity();
};

/// Integrate from (t_begin, start) to t_end ≥ t_begin. The initial mode follows from the state (see
/// TappingSystem::initial_mode). Throws NumericalFailure when an event or step budget is exhausted and
/// InvalidParameter for a non-finite state, t_end < t_begin, or closed_form with a non piecewise-linear law.
SimulationResult simulate(const TappingModel& model, double t_begin, TipState start, double t_end,
                          const SimulationOptions& options = {}, TrajectoryObserver* observer = nullptr);

/// The same on a system already built (a single-mode TappingSystem, e.g. one whose separation an imaging engine
/// moves with TappingSystem::set_separation): no model copy, no allocation by the engine itself.
SimulationResult simulate(const TappingSystem& system, double t_begin, TipState start, double t_end,
                          const SimulationOptions& options = {}, TrajectoryObserver* observer = nullptr);

/// The same for a multi-mode cantilever (modes.hpp): `start` holds the tip's x, ẋ and the higher modal
/// coordinates (TipState::modal). A MultiModeModel::single_mode() model is simulated as its TappingModel (the
/// same bits); otherwise by the adaptive integrator, with the same guards and events seen at the tip (sticking holds
/// the tip while the modes move on). Not available for more than one mode: sensitivity and closed_form
/// (InvalidParameter).
SimulationResult simulate(const MultiModeModel& model, double t_begin, TipState start, double t_end,
                          const SimulationOptions& options = {}, TrajectoryObserver* observer = nullptr);

/// Integrator actually used for `model` under `requested` (resolves automatic; validates closed_form).
Integrator resolve_integrator(const TappingModel& model, Integrator requested);

}  // namespace afmkit::tapping
