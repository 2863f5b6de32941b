#pragma once
// FM-AFM forward model: the self-excited cantilever at constant oscillation amplitude A with an ideal phase-locked
// loop (docs/theory-tapping.md#fm-afm). The drive is kept 90° ahead of the deflection (the phase of resonance) and
// its amplitude Γ is set so that the deflection's first harmonic has amplitude A. In the tapping model's
// normalised form (seed-1 eq. 8)
//   ẍ + 2ξω_n ẋ + ω_n² x = Γ cos(ωt) + H(x + l, ẋ)
// an FM orbit is a periodic orbit of period T = 2π/ω whose frequency ω and drive Γ are unknowns, fixed by
//   x(T) = x(0),  ẋ(T) = ẋ(0)                              (periodicity)
//   (2/T) ∫₀ᵀ x(t) cos(ωt) dt = 0                          (drive 90° ahead: x ≈ x̄ + A sin ωt + harmonics)
//   (2/T) ∫₀ᵀ x(t) sin(ωt) dt = A                          (first-harmonic amplitude A)
// four equations in the four unknowns (x(0), ẋ(0), ω, Γ), solved by Newton: the block ∂(periodicity)/∂(x, ẋ)
// is the exact monodromy matrix of the event-driven integrator, the other columns and rows are forward differences
// of the same map. Observables: frequency shift Δω = ω − ω_n, drive ratio Γ/Γ_free (Γ_free = 2ξω_n² A, the drive
// of the free cantilever at amplitude A), and the energy the tip–sample force takes per cycle
//   E_ts = −∫₀ᵀ H ẋ dt = W − ∫₀ᵀ 2ξω_n ẋ² dt,   W = ∫₀ᵀ Γ cos(ωt) ẋ dt = π Γ A   (on an FM orbit, by parts).
#include <complex>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/impact/force_law.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/shooting.hpp"

namespace afmkit::tapping {

/// The FM setting: cantilever, tip–sample force law and the amplitude setpoint A (model length units).
struct FmSetting {
  Cantilever cantilever;
  impact::ForceLaw law;
  double amplitude;  // A > 0

  FmSetting(Cantilever cantilever, impact::ForceLaw law, double amplitude);  // validated
  /// Drive of the free cantilever at amplitude A on resonance (ω = ω_n): Γ_free = 2ξω_n² A.
  double free_drive() const;
  /// The driven tapping model of an FM orbit (drive Γ cos ωt) at separation l.
  TappingModel model(double separation, double frequency, double drive) const;
};

/// The unknowns of an FM orbit: the state at t = 0 (drive at phase 0), the oscillation frequency and the drive.
struct FmState {
  TipState initial;
  double frequency = 1.0;  // ω > 0
  double drive = 0.0;      // Γ > 0
};

/// The free FM orbit: x = A sin(ω_n t), ω = ω_n, Γ = Γ_free (exact without interaction).
FmState free_fm_state(const FmSetting& setting);

struct FmOptions {
  ShootingOptions shooting;  // tolerance (on all four scaled residuals), max_iterations, time budget, integrator
  /// Forward-difference step of the columns not given by the monodromy, relative to the scale of each unknown
  /// (A, Aω, ω, Γ); 0: chosen from the integrator (1e-7 closed form, √(relative_tolerance) adaptive, ≥ 1e-7).
  double difference_step = 0.0;
  void validate() const;
};

/// A converged FM orbit at one separation.
struct FmOrbit {
  double separation = 0.0;  // l
  FmState state;
  double natural_frequency = 1.0;  // ω_n of the setting
  double free_drive = 0.0;         // Γ_free of the setting
  Eigen::Matrix2d monodromy = Eigen::Matrix2d::Identity();  // of the driven orbit with the drive frozen
  std::array<std::complex<double>, 2> floquet_multipliers{};
  double floquet_max = 0.0;
  bool stable = false;      // floquet_max < 1 (frozen drive: the loops held at their values)
  double residual = 0.0;    // largest scaled residual of the four equations
  int iterations = 0;       // Newton iterations
  long evaluations = 0;     // one-period simulations used
  OrbitMetrics metrics;     // of the orbit (harmonics, offset, gap, forces, energies; phase ≈ π/2)
  double frequency_shift() const;   // Δω = ω − ω_n (model units, rad per time unit)
  double drive_ratio() const;       // Γ/Γ_free
  double tip_dissipation() const;   // E_ts = −∫ H ẋ dt per cycle (= W − viscous; model energy units)
};

/// The Jacobian of the FM conditions (in the unknowns scaled by A, Aω_n, ω_n, Γ_free[, A]) kept from one solve for
/// the next: along an approach it changes little, so Newton starts from it and updates it by Broyden's rule,
/// recomputing it by differences only where it stops reducing the residual (sweep_fm keeps one).
struct FmJacobian {
  Eigen::MatrixXd matrix;  // empty: none yet
};

/// Newton on the FM conditions at separation l from `guess`; nullopt when it does not converge within the
/// iteration budget (throws NumericalFailure when the time budget is exhausted). `reuse`: a Jacobian to start from
/// and to update (nullptr: differences at the guess).
std::optional<FmOrbit> try_solve_fm(const FmSetting& setting, double separation, const FmState& guess,
                                    const FmOptions& options = {}, FmJacobian* reuse = nullptr);

/// As try_solve_fm with the separation an unknown too, fixed by the condition that the smallest gap over the cycle
/// (the tip–sample distance at the lower turning point) is `min_gap`; Newton starts from `separation_guess`.
std::optional<FmOrbit> try_solve_fm_at_gap(const FmSetting& setting, double min_gap, double separation_guess,
                                           const FmState& guess, const FmOptions& options = {},
                                           FmJacobian* reuse = nullptr);

enum class FmStatus { converged, no_orbit };
const char* fm_status_name(FmStatus status);

struct FmPoint {
  double separation = 0.0;  // the target: separation l (FmAxis::separation) or min gap (FmAxis::min_gap)
  FmStatus status = FmStatus::no_orbit;
  bool jumped = false;           // reached past a fold of the branch in l: the orbit lies on another branch
  std::optional<FmOrbit> orbit;  // when converged
};

/// What the targets of sweep_fm are: separations l (as an instrument steps its piezo), or gaps at the lower
/// turning point (the tip–sample distance of closest approach; l is solved for).
enum class FmAxis { separation, min_gap };

struct FmSweepOptions {
  FmOptions fm;
  FmAxis axis = FmAxis::separation;
  /// Where Newton fails from the previous point, the step is halved up to this many times (2^depth sub-steps).
  int max_bisections = 6;
  /// Separation axis: where the branch ends in a fold before the next separation, follow it in the turning-point
  /// gap (through the fold) to the branch that reaches that separation, as the loops of an instrument would jump.
  bool jumps = true;
  std::function<void(long)> progress;  // called with 1 after each target
  Cancellation cancellation;
  void validate() const;
};

struct FmSweepResult {
  std::vector<FmPoint> points;  // in the order of the targets given
  long evaluations = 0;         // one-period simulations of the converged Newton solves
  long failed_attempts = 0;     // Newton solves that did not converge (then retried in smaller steps)
  double seconds = 0.0;
  long converged() const;
};

/// FM orbits at the targets in the order given (an approach: decreasing), each warm started from the previous
/// converged orbits (secant predictor), the step bisected where Newton fails; the first from the free FM orbit
/// (marched in from 3A above the law's switching gaps when needed). On the separation axis, a branch that ends in
/// a fold is followed through it in the turning-point gap to the branch that reaches the next separation (point
/// marked jumped). A target where no orbit is found is a point with status no_orbit; the sweep continues from the
/// last converged orbit.
FmSweepResult sweep_fm(const FmSetting& setting, const std::vector<double>& targets,
                       const FmSweepOptions& options = {});

}  // namespace afmkit::tapping
