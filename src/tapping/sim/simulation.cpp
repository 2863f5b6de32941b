#include "afmkit/tapping/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "engine.hpp"

namespace afmkit::tapping {

const char* integrator_name(Integrator integrator) {
  switch (integrator) {
    case Integrator::automatic: return "automatic";
    case Integrator::closed_form: return "closed_form";
    case Integrator::adaptive: return "adaptive";
  }
  return "?";
}

void SimulationOptions::validate() const {
  // cheap when valid (called for every simulation): messages are built only on failure
  check_fields(*this);  // the ranges describe() declares
  if (!(max_step_fraction > 0 && max_step_fraction <= 0.25))
    validate::require(false, "max_step_fraction", max_step_fraction, "in (0, 0.25]");
  if (!(initial_step >= 0 && std::isfinite(initial_step)))
    validate::require(false, "initial_step", initial_step, ">= 0 and finite");
  if (max_events < 1) validate::require(false, "max_events", static_cast<double>(max_events), ">= 1");
  if (max_steps < 1) validate::require(false, "max_steps", static_cast<double>(max_steps), ">= 1");
}

Integrator resolve_integrator(const TappingModel& model, Integrator requested) {
  const bool linear = model.law.piecewise_linear() != nullptr;
  if (requested == Integrator::automatic) return linear ? Integrator::closed_form : Integrator::adaptive;
  if (requested == Integrator::closed_form && !linear)
    throw InvalidParameter("integrator", fmt::format("integrator = closed_form needs a piecewise-linear force law "
                                                     "(seed-1 eqs. 10, 11, 26); law '{}' is not",
                                                     model.law.name()));
  return requested;
}

namespace {
void check_run(double t_begin, const TipState& start, double t_end) {
  if (!std::isfinite(t_begin)) validate::finite("t_begin", t_begin);
  if (!std::isfinite(t_end)) validate::finite("t_end", t_end);
  if (!(t_end >= t_begin)) validate::require(false, "t_end", t_end, fmt::format(">= t_begin = {}", t_begin));
  if (!std::isfinite(start.position)) validate::finite("position", start.position);
  if (!std::isfinite(start.velocity)) validate::finite("velocity", start.velocity);
}

SimulationResult run_system(const TappingSystem& sys, Integrator integrator, double t_begin, TipState start,
                            double t_end, const SimulationOptions& options, TrajectoryObserver* observer) {
  detail::RunState rs;
  rs.t = t_begin;
  rs.y = start;
  rs.mode = sys.initial_mode(t_begin, rs.y);
  if (rs.mode.branch == ContactBranch::sticking) {
    ++rs.stats.sticking_count;
    // a velocity perturbation is absorbed by the sticking (saltation diag(1, 0, 1)); one mode only (no
    // variational equations for several)
    if (!sys.modal()) rs.jacobian(1, 1) = 0.0;
  }
  if (integrator == Integrator::closed_form)
    detail::run_closed_form(sys, rs, t_end, options, observer);
  else
    detail::run_adaptive(sys, rs, t_end, options, observer);
  if (!std::isfinite(rs.y.position) || !std::isfinite(rs.y.velocity))
    throw NumericalFailure(
        sys.modal() ? fmt::format("tapping simulation (modes): the motion diverges (state x = {}, dx/dt = {} at "
                                  "t = {:.9g})",
                                  rs.y.position, rs.y.velocity, rs.t)
                    : fmt::format("tapping simulation: the motion diverges (state x = {}, dx/dt = {} at t = {:.9g}); "
                                  "a law that creates energy (allow_energy_gain) can drive it without bound",
                                  rs.y.position, rs.y.velocity, rs.t));
  SimulationResult out;
  out.time = rs.t;
  out.state = rs.y;
  out.state.contact = rs.mode.contact;  // the memory of a contact-aware law travels with the state
  out.mode = rs.mode;
  out.stats = rs.stats;
  out.sensitivity = rs.jacobian;
  return out;
}
}  // namespace

SimulationResult simulate(const TappingModel& model, double t_begin, TipState start, double t_end,
                          const SimulationOptions& options, TrajectoryObserver* observer) {
  options.validate();
  check_run(t_begin, start, t_end);
  const Integrator integrator = resolve_integrator(model, options.integrator);
  const TappingSystem sys(model);
  return run_system(sys, integrator, t_begin, start, t_end, options, observer);
}

SimulationResult simulate(const TappingSystem& system, double t_begin, TipState start, double t_end,
                          const SimulationOptions& options, TrajectoryObserver* observer) {
  if (system.modal())
    throw InvalidParameter("system", "simulate(TappingSystem): a single-mode system only (multi-mode models: "
                                     "simulate(MultiModeModel))");
  options.validate();
  check_run(t_begin, start, t_end);
  const Integrator integrator = resolve_integrator(system.model(), options.integrator);
  return run_system(system, integrator, t_begin, start, t_end, options, observer);
}

SimulationResult simulate(const MultiModeModel& model, double t_begin, TipState start, double t_end,
                          const SimulationOptions& options, TrajectoryObserver* observer) {
  if (model.single_mode()) return simulate(model.first_mode(), t_begin, start, t_end, options, observer);
  options.validate();
  if (options.sensitivity)
    throw InvalidParameter("sensitivity", "sensitivity (variational equations) is available for one eigenmode only");
  if (options.integrator == Integrator::closed_form)
    throw InvalidParameter("integrator", "integrator = closed_form is available for one eigenmode only (the modes "
                                         "are integrated by the adaptive integrator)");
  check_run(t_begin, start, t_end);
  for (double c : start.modal)
    if (!std::isfinite(c)) validate::finite("modal coordinate", c);
  return run_system(TappingSystem(model), Integrator::adaptive, t_begin, start, t_end, options, observer);
}

namespace detail {

double scan_step(const TappingSystem& sys, double mode_period, const SimulationOptions& options) {
  const double drive_period = sys.model().period();
  // a multi-mode system: also the other drives' and modes' periods (infinity for a TappingModel)
  return options.max_step_fraction * std::min({drive_period, mode_period, sys.shortest_extra_period()});
}

void handle_event(const TappingSystem& sys, RunState& rs, const Guard& guard, double te, TipState pre_state,
                  const SimulationOptions& options, TrajectoryObserver* observer) {
  const Mode before = rs.mode;
  TipState post = pre_state;
  const Mode after = sys.after_event(before, guard, te, post);
  if (options.sensitivity) {
    // Saltation matrix S = I + (f⁺ − f⁻) ∇gᵀ / (∇g·f⁻ + ∂g/∂t), states (x, ẋ, l) with l̇ = 0.
    const Eigen::Vector3d f_minus(pre_state.velocity, sys.acceleration(before, te, pre_state), 0.0);
    const Eigen::Vector3d f_plus(post.velocity, sys.acceleration(after, te, post), 0.0);
    double grad[3], dt_partial = 0.0;
    sys.witness_gradient(guard, before, te, pre_state, grad, dt_partial);
    const Eigen::Vector3d g(grad[0], grad[1], grad[2]);
    const double denom = g.dot(f_minus) + dt_partial;
    if (denom != 0.0 && std::isfinite(denom)) {
      const Eigen::Matrix3d s = Eigen::Matrix3d::Identity() + (f_plus - f_minus) * g.transpose() / denom;
      rs.jacobian = s * rs.jacobian;
    }
  }
  ++rs.stats.events;
  if (guard.kind == GuardKind::gap && guard.direction == CrossingDirection::falling && after.region == 0)
    ++rs.stats.impacts;
  if (after.branch == ContactBranch::sticking && before.branch != ContactBranch::sticking) ++rs.stats.sticking_count;
  rs.t = te;
  rs.y = post;
  rs.mode = after;
  if (observer) observer->on_event(sys, Event{te, guard, before, after, post});
  if (rs.stats.events > options.max_events)
    throw NumericalFailure(fmt::format(
        "tapping simulation: event budget of {} events exhausted at t = {:.9g} (x = {:.9g}, dx/dt = {:.3g}, "
        "{} branch); the motion chatters between modes — raise max_events or check the force law",
        options.max_events, te, post.position, post.velocity, contact_branch_name(after.branch)));
}

namespace {
class StaticSegment final : public Segment {
 public:
  StaticSegment(double a, double b, Mode m, double x) : Segment(a, b, m), x_(x) {}
  TipState state(double) const override { return {x_, 0.0}; }

 private:
  double x_;
};
}  // namespace

void run_sticking(const TappingSystem& sys, RunState& rs, double t_end, const SimulationOptions& options,
                  TrajectoryObserver* observer) {
  std::array<Guard, 3> guards;
  const int n = sys.guards(rs.mode, guards);
  const TipState rest{rs.y.position, 0.0};
  auto state = [&](double) { return rest; };
  const double h = scan_step(sys, std::numeric_limits<double>::infinity(), options);
  const double t0 = rs.t;
  double ta = t0;
  GuardSamples a, b;
  sample_guards(sys, rs.mode, guards, n, ta, rest, a);
  while (ta < t_end) {
    const double tb = std::min(ta + h, t_end);
    sample_guards(sys, rs.mode, guards, n, tb, rest, b);
    ++rs.stats.steps;
    if (auto c = first_crossing(sys, rs.mode, guards, n, ta, tb, a, b, state)) {
      rs.stats.sticking_duration += c->time - t0;
      if (observer) observer->on_segment(sys, StaticSegment(t0, c->time, rs.mode, rest.position));
      handle_event(sys, rs, guards[c->guard], c->time, rest, options, observer);
      return;
    }
    ta = tb;
    a = b;
  }
  rs.stats.sticking_duration += t_end - t0;
  if (observer) observer->on_segment(sys, StaticSegment(t0, t_end, rs.mode, rest.position));
  rs.t = t_end;
  rs.y = rest;
}

}  // namespace detail
}  // namespace afmkit::tapping
