#include "afmkit/tapping/shooting.hpp"

#include <chrono>
#include <cmath>

#include <Eigen/LU>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::tapping {

void ShootingOptions::validate() const {
  check_fields(*this);     // the ranges describe() declares (the simulation's included)
  simulation.validate();  // and the simulation's internal limits
}

StroboscopicMap stroboscopic_map(const TappingModel& model, TipState start, int period_multiple,
                                 const SimulationOptions& options) {
  validate::require(period_multiple >= 1, "period_multiple", period_multiple, ">= 1");
  SimulationOptions o = options;
  o.sensitivity = true;
  const SimulationResult r = simulate(model, 0.0, start, period_multiple * model.period(), o);
  return {r.state, r.sensitivity, r.stats};
}

void set_floquet(PeriodicOrbit& orbit) {
  const Eigen::Matrix2d& m = orbit.monodromy;
  const double half_trace = 0.5 * m.trace(), det = m.determinant();
  const std::complex<double> root = std::sqrt(std::complex<double>(half_trace * half_trace - det, 0.0));
  orbit.floquet_multipliers = {half_trace + root, half_trace - root};
  orbit.floquet_max = std::max(std::abs(orbit.floquet_multipliers[0]), std::abs(orbit.floquet_multipliers[1]));
  orbit.stable = orbit.floquet_max < 1.0;
}

TipState free_response_state(const TappingModel& model) {
  // x_p(t) = Re[Γ L(iω) e^{iωt}] (seed-1 eq. 9)
  const std::complex<double> z = model.drive.amplitude * model.cantilever.transfer({0.0, model.drive.frequency});
  return {z.real(), -model.drive.frequency * z.imag()};
}

namespace {

double scaled_norm(const Eigen::Vector2d& r, const Eigen::Vector2d& y, double omega) {
  const double scale = std::max({1.0, std::abs(y.x()), std::abs(y.y()) / omega});
  return std::max(std::abs(r.x()), std::abs(r.y()) / omega) / scale;
}

/// The Newton tolerance: the adaptive integrator's map is only as smooth as its tolerance: do not ask Newton for more.
double newton_tolerance(const TappingModel& model, const ShootingOptions& options) {
  return resolve_integrator(model, options.simulation.integrator) == Integrator::adaptive
             ? std::max(options.tolerance, 10.0 * options.simulation.relative_tolerance)
             : options.tolerance;
}

/// The orbit accepted at y: the map from y (end state within `tolerance`, residual r of size `norm`) has the
/// sensitivities `sensitivity` and `stats`. The last Newton step, from the map already evaluated, takes the state from
/// a residual of size `norm` to one of size O(norm²): without it the fixed point is off by (M − I)⁻¹ r, large when a
/// multiplier is near 1 (high Q).
PeriodicOrbit accepted_orbit(const TappingModel& model, Eigen::Vector2d y, bool memory, int period_multiple,
                             const Eigen::Vector2d& r, double norm, const Eigen::Matrix3d& sensitivity,
                             const SimulationStats& stats, int iterations, double tolerance) {
  const double omega = model.drive.frequency;
  const Eigen::Matrix2d monodromy = sensitivity.topLeftCorner<2, 2>();
  const Eigen::FullPivLU<Eigen::Matrix2d> last(monodromy - Eigen::Matrix2d::Identity());
  if (last.isInvertible()) {
    const Eigen::Vector2d step = -last.solve(r);
    if (step.allFinite() && scaled_norm(step, y, omega) <= 1e3 * tolerance) y += step;
  }
  PeriodicOrbit orbit;
  orbit.separation = model.separation;
  orbit.period_multiple = period_multiple;
  orbit.initial = {y.x(), y.y(), memory};
  orbit.monodromy = monodromy;
  orbit.separation_sensitivity = sensitivity.topRightCorner<2, 1>();
  orbit.residual = norm;
  orbit.iterations = iterations;
  orbit.stats = stats;
  set_floquet(orbit);
  return orbit;
}

}  // namespace

std::optional<PeriodicOrbit> try_shoot(const TappingModel& model, TipState guess, int period_multiple,
                                       const ShootingOptions& options) {
  options.validate();
  validate::require(period_multiple >= 1, "period_multiple", period_multiple, ">= 1");
  validate::finite("position", guess.position);
  validate::finite("velocity", guess.velocity);
  const auto start_time = std::chrono::steady_clock::now();
  const double tolerance = newton_tolerance(model, options);
  const double omega = model.drive.frequency;
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  };
  Eigen::Vector2d y(guess.position, guess.velocity);
  // The memory of a contact-aware law is part of the orbit's state (docs/force-laws.md#hysteresis): a periodic
  // orbit starts with the memory it ends with. Newton runs with the guess's memory; when it has converged on a
  // state whose period ends with the other memory (an orbit that touches, or rises above the release gap, fixes
  // its end memory whatever it started with), it continues from there with that memory (at most twice). The
  // memory never changes at an unconverged iterate: a wild Newton step that touches the sample cannot turn a
  // free orbit between the contact and the release gaps into an attached one.
  bool memory = guess.contact;
  int memory_switches = 0;
  auto evaluate = [&](const Eigen::Vector2d& at) {
    return stroboscopic_map(model, {at.x(), at.y(), memory}, period_multiple, options.simulation);
  };
  StroboscopicMap map = evaluate(y);
  Eigen::Vector2d r = Eigen::Vector2d(map.end.position, map.end.velocity) - y;
  double norm = scaled_norm(r, y, omega);
  for (int it = 0; it <= options.max_iterations; ++it) {
    if (norm <= tolerance && map.end.contact != memory) {
      if (memory_switches == 2) return std::nullopt;  // the memory does not repeat: no period-n orbit here
      ++memory_switches;
      memory = map.end.contact;
      map = evaluate(y);
      r = Eigen::Vector2d(map.end.position, map.end.velocity) - y;
      norm = scaled_norm(r, y, omega);
    }
    if (norm <= tolerance && map.end.contact == memory) {
      PeriodicOrbit orbit =
          accepted_orbit(model, y, memory, period_multiple, r, norm, map.sensitivity, map.stats, it, tolerance);
      y = {orbit.initial.position, orbit.initial.velocity};
      // a period-n solution that repeats after a divisor m of n is reported with its minimal period
      for (int m = 1; m < period_multiple; ++m) {
        if (period_multiple % m != 0) continue;
        const auto sub = simulate(model, 0.0, orbit.initial, m * model.period(), options.simulation);
        const Eigen::Vector2d rs = Eigen::Vector2d(sub.state.position, sub.state.velocity) - y;
        if (scaled_norm(rs, y, omega) <= 100.0 * tolerance) {
          ShootingOptions again = options;
          again.tolerance = std::max(tolerance, scaled_norm(rs, y, omega));
          if (auto reduced = try_shoot(model, orbit.initial, m, again)) return reduced;
        }
      }
      return orbit;
    }
    if (it == options.max_iterations) break;
    if (elapsed() > options.time_budget_seconds)
      throw NumericalFailure(fmt::format("shooting: time budget of {} s exhausted after {} Newton iterations "
                                         "(residual {:.3g}) at separation {}",
                                         options.time_budget_seconds, it, norm, model.separation));
    const Eigen::Matrix2d jac = map.sensitivity.topLeftCorner<2, 2>() - Eigen::Matrix2d::Identity();
    const Eigen::FullPivLU<Eigen::Matrix2d> lu(jac);
    if (!lu.isInvertible()) return std::nullopt;  // multiplier exactly 1: Newton cannot proceed
    const Eigen::Vector2d step = -lu.solve(r);
    if (!step.allFinite()) return std::nullopt;
    // damped Newton: halve the step until the residual decreases (the map is only piecewise smooth)
    double lambda = 1.0;
    bool accepted = false;
    for (int k = 0; k < 8; ++k, lambda *= 0.5) {
      const Eigen::Vector2d trial = y + lambda * step;
      StroboscopicMap m = evaluate(trial);
      const Eigen::Vector2d rt = Eigen::Vector2d(m.end.position, m.end.velocity) - trial;
      const double nt = scaled_norm(rt, trial, omega);
      if (nt < norm || k == 7) {
        y = trial;
        map = m;
        r = rt;
        accepted = nt < norm;
        norm = nt;
        break;
      }
    }
    if (!accepted && norm > 1e3 * tolerance) return std::nullopt;
  }
  return std::nullopt;
}

namespace {
/// A residual within this many tolerances: the next Newton step is taken to land within the tolerance.
constexpr double kUntestedResidual = 100.0;
}  // namespace

std::optional<PeriodicOrbit> try_shoot_near(const TappingModel& model, TipState guess, const PeriodicOrbit& near,
                                            const ShootingOptions& options, bool evaluate_guess) {
  options.validate();
  validate::finite("position", guess.position);
  validate::finite("velocity", guess.velocity);
  const int n = near.period_multiple;
  const double tolerance = newton_tolerance(model, options), omega = model.drive.frequency;
  SimulationOptions cheap = options.simulation;
  cheap.sensitivity = false;
  const bool memory = guess.contact;
  Eigen::Vector2d y(guess.position, guess.velocity);
  auto residual = [&](const Eigen::Vector2d& at, bool& same_memory) {
    const SimulationResult m = simulate(model, 0.0, {at.x(), at.y(), memory}, n * model.period(), cheap);
    same_memory = m.state.contact == memory;
    return Eigen::Vector2d(m.state.position - at.x(), m.state.velocity - at.y());
  };
  bool same_memory = true;
  Eigen::Vector2d r = Eigen::Vector2d::Zero();
  double norm = 0.0;
  if (evaluate_guess) {
    r = residual(y, same_memory);
    norm = scaled_norm(r, y, omega);
  }
  // Newton–Broyden on the map without sensitivities, from the Jacobian of the nearby orbit (Broyden's "good"
  // update J += (Δr − JΔy)Δyᵀ/|Δy|²); any step that does not reduce the residual hands over to try_shoot.
  // Once the residual is within kUntestedResidual tolerances, the next step is not evaluated on the cheap map: it
  // goes straight to the run with sensitivities, which judges it as try_shoot judges its first evaluation (from
  // the Jacobian of a nearby orbit a step shrinks the residual 300-fold and more on a coarse grid: 1e-6 to 3e-9,
  // measured; one that does not hands over to try_shoot from the step that run gives). Broyden's check that each
  // step reduces the residual stays for the steps before. (Like any change of the orbits' last digits, this moves
  // where a chaotic transient beyond the period-doubling cascade of LocatedJumps settles; the test compares the
  // jumps up to that landing.)
  Eigen::Matrix2d jac = near.monodromy - Eigen::Matrix2d::Identity();
  int iterations = 0;
  bool untested = !evaluate_guess;  // y is not evaluated on the cheap map
  Eigen::Vector2d tested = y;  // the last iterate evaluated (where try_shoot starts when the untested step fails)
  while (!untested && same_memory && iterations < options.max_iterations) {
    const Eigen::FullPivLU<Eigen::Matrix2d> lu(jac);
    if (!lu.isInvertible()) break;
    const Eigen::Vector2d step = -lu.solve(r);
    if (!step.allFinite()) break;
    const Eigen::Vector2d trial = y + step;
    if (norm <= kUntestedResidual * tolerance) {
      y = trial;
      untested = true;
      if (norm > tolerance) ++iterations;  // (`iterations` 0 says the guess was within the tolerance, as try_shoot's)
      break;
    }
    bool trial_memory = true;
    const Eigen::Vector2d rt = residual(trial, trial_memory);
    const double nt = scaled_norm(rt, trial, omega);
    if (!trial_memory || !(nt < norm)) break;
    jac += ((rt - r) - jac * step) * step.transpose() / step.squaredNorm();
    y = trial;
    tested = y;
    r = rt;
    norm = nt;
    ++iterations;
  }
  if (untested && n == 1) {
    // try_shoot's first evaluation and acceptance (a period-n orbit, n > 1, is left to try_shoot: it checks the
    // divisors of n)
    SimulationOptions o = options.simulation;
    o.sensitivity = true;
    const SimulationResult m = simulate(model, 0.0, {y.x(), y.y(), memory}, n * model.period(), o);
    const Eigen::Vector2d rs(m.state.position - y.x(), m.state.velocity - y.y());
    const double ns = scaled_norm(rs, y, omega);
    if (m.state.contact == memory && ns <= tolerance)  // accepted as try_shoot accepts (its last Newton step)
      return accepted_orbit(model, y, memory, n, rs, ns, m.sensitivity, m.stats, iterations, tolerance);
    // not within the tolerance: Newton goes on from the step this run gives (try_shoot's next iterate), else
    // try_shoot starts at the last iterate tested on the cheap map
    ++iterations;
    if (m.state.contact == memory && rs.allFinite()) {
      const Eigen::FullPivLU<Eigen::Matrix2d> lu(m.sensitivity.topLeftCorner<2, 2>() - Eigen::Matrix2d::Identity());
      const Eigen::Vector2d step = lu.isInvertible() ? Eigen::Vector2d(-lu.solve(rs)) : Eigen::Vector2d::Constant(NAN);
      if (step.allFinite() && scaled_norm(step, y, omega) < 1.0) {
        if (auto orbit = try_shoot(model, {y.x() + step.x(), y.y() + step.y(), memory}, n, options)) {
          orbit->iterations += iterations;
          return orbit;
        }
      }
    }
    y = tested;  // (the guess itself when it was not evaluated: try_shoot from there, with its damping)
  }
  auto orbit = try_shoot(model, {y.x(), y.y(), memory}, n, options);
  if (orbit) orbit->iterations += iterations;
  return orbit;
}

PeriodicOrbit shoot(const TappingModel& model, TipState guess, int period_multiple, const ShootingOptions& options) {
  if (auto orbit = try_shoot(model, guess, period_multiple, options)) return *orbit;
  throw NumericalFailure(fmt::format("shooting: Newton did not converge to a period-{} orbit within {} iterations "
                                     "from x(0) = {:.9g}, dx/dt(0) = {:.9g} at separation {}",
                                     period_multiple, options.max_iterations, guess.position, guess.velocity,
                                     model.separation));
}

}  // namespace afmkit::tapping
