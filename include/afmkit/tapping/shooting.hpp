#pragma once
// Periodic steady states by shooting: Newton's method on the stroboscopic map P^n (n drive periods, drive at
// phase 0 at t = 0), with the exact monodromy matrix M = ∂P^n/∂(x, ẋ) from the variational equations and the
// saltation matrices of every event. Floquet multipliers = eigenvalues of M; the orbit is (asymptotically)
// stable when max |μ| < 1.
#include <array>
#include <complex>
#include <optional>

#include <Eigen/Core>

#include "afmkit/tapping/simulation.hpp"

namespace afmkit::tapping {

struct ShootingOptions {
  double tolerance = 1e-11;         // converged when |P^n(y) − y| ≤ tolerance · max(1, |y|) (per component scale)
  int max_iterations = 30;          // Newton iterations -> NumericalFailure when exceeded (shoot) / nullopt (try_shoot)
  double time_budget_seconds = 30;  // wall-clock budget of one shooting solve -> NumericalFailure when exceeded
  SimulationOptions simulation;     // integrator used for the map (sensitivity is switched on internally)

  /// The fields a user sets, declared once (core/describe.hpp): the simulation's, then the shooting's.
  template <class Archive, class Self>
  static void describe(Archive& a, Self& o) {
    SimulationOptions::describe(a, o.simulation);
    describe_tolerance(a, o.tolerance, "Newton convergence of periodic orbits |P(y) - y| / |y|",
                       Range::open(0.0, 1.0));
    a.integer("max_newton_iterations", o.max_iterations, "Newton iterations per shooting solve", 1, 1000);
    a.real("time_budget", o.time_budget_seconds, "wall-clock budget of one shooting solve", "s", Range::positive());
  }
  void validate() const;  // InvalidParameter naming the key (the ranges of describe())

  /// `shooting_tolerance` (the `tolerance` above), declared once for every options struct whose orbits are shot
  /// (spectroscopy::FitOptions too), each with its help and range: a fit's orbits need less than a sweep's.
  template <class Archive, class Tolerance>
  static void describe_tolerance(Archive& a, Tolerance& tolerance, const char* help, Range range) {
    a.real("shooting_tolerance", tolerance, help, "dimensionless", range);
  }
};

/// A periodic orbit of period n·T (T = 2π/ω), given by its state at t = 0 (drive Γ cos ωt at phase 0).
struct PeriodicOrbit {
  double separation = 0.0;   // l
  int period_multiple = 1;   // n
  TipState initial;          // state at t = 0 (= state at t = nT)
  Eigen::Matrix2d monodromy = Eigen::Matrix2d::Identity();          // ∂P^n/∂(x, ẋ)
  Eigen::Vector2d separation_sensitivity = Eigen::Vector2d::Zero();  // ∂P^n/∂l (used by continuation)
  std::array<std::complex<double>, 2> floquet_multipliers{};
  double floquet_max = 0.0;  // max |μ|
  bool stable = false;       // floquet_max < 1
  double residual = 0.0;     // final |P^n(y) − y| (scaled)
  int iterations = 0;
  SimulationStats stats;     // of the last period evaluation (events, impacts, sticking)
};

/// One evaluation of the map: state after n periods and its sensitivities (columns x, ẋ, l).
struct StroboscopicMap {
  TipState end;
  Eigen::Matrix3d sensitivity;
  SimulationStats stats;
};
StroboscopicMap stroboscopic_map(const TappingModel& model, TipState start, int period_multiple,
                                 const SimulationOptions& options);

/// Newton shooting from `guess`. Returns nullopt when Newton does not converge within the iteration budget
/// (so callers can try another guess); throws NumericalFailure when the time budget is exhausted.
std::optional<PeriodicOrbit> try_shoot(const TappingModel& model, TipState guess, int period_multiple,
                                       const ShootingOptions& options = {});
/// try_shoot from a guess near a known orbit `near` of a neighbouring model (the previous point of a branch): the
/// first Newton iterations evaluate the map without its sensitivities, with Broyden updates of near's Jacobian
/// M − I, until the residual is within 100 tolerances (or they stop reducing it); the next step then goes to the
/// run with sensitivities directly, untested on the cheap map, so the variational equations are integrated at the
/// converged state (usually there only: the two maps differ by the integrator's tolerance) and the monodromy and
/// multipliers are those of the converged orbit, as try_shoot's. That run judges the step as try_shoot judges its
/// first evaluation; Newton goes on from there (try_shoot) when it is not yet the orbit. `iterations` counts both
/// kinds (0: the guess was within the tolerance). `evaluate_guess` false: the guess is taken to be within the
/// tolerance (as a caller's last one was) and goes to that run at once.
std::optional<PeriodicOrbit> try_shoot_near(const TappingModel& model, TipState guess, const PeriodicOrbit& near,
                                            const ShootingOptions& options = {}, bool evaluate_guess = true);
/// As try_shoot, but non-convergence -> NumericalFailure with the residual in the message.
PeriodicOrbit shoot(const TappingModel& model, TipState guess, int period_multiple, const ShootingOptions& options = {});

/// Fill monodromy-derived fields (multipliers, floquet_max, stable) of `orbit` from `orbit.monodromy`.
void set_floquet(PeriodicOrbit& orbit);

/// The exact periodic response of the cantilever without contact (linear oscillator), state at t = 0.
TipState free_response_state(const TappingModel& model);

}  // namespace afmkit::tapping
