#pragma once
// What a multi-mode run measures (docs/theory-tapping.md#more-than-one-eigenmode): the amplitude and phase of
// every mode and of the tip at every drive frequency by a lock-in over whole periods, the energy balance of every
// mode, the closest approach and the peak force; and the separation sweep of bimodal AM-AFM.
// Phase convention as everywhere: q_i(t) ≈ A cos(ω_d t − φ) (φ = π/2 for a free mode driven at its resonance).
#include <array>
#include <complex>
#include <functional>
#include <vector>

#include "afmkit/tapping/modes.hpp"
#include "afmkit/tapping/observer.hpp"
#include "afmkit/tapping/simulation.hpp"

namespace afmkit::tapping {

struct ModalHarmonic {
  double amplitude = 0.0;  // A ≥ 0
  double phase = 0.0;      // φ (rad, in (−π, π])
  static ModalHarmonic of(std::complex<double> c) { return {std::abs(c), -std::arg(c)}; }  // c = A e^{−iφ}
};

/// Energy terms of one mode over a window, per unit mass of mode 1 (vacuum), so that the modes add up:
///   E_i = (½q̇_i² + ½ω_i'²q_i²)/(ρβ_i),  drive_work = ∫F_i q̇_i dt/(ρβ_i),  damping_loss = ∫2ξ_i'ω_i' q̇_i² dt/(ρβ_i),
///   tip_work = −∫h q̇_i dt (the work of the tip–sample force on the mode);
///   drive_work − damping_loss + tip_work = E_i(end) − E_i(begin)  (0 over a period of a periodic orbit).
struct ModeEnergy {
  double drive_work = 0.0;
  double damping_loss = 0.0;
  double tip_work = 0.0;
  double energy_change = 0.0;  // E_i(end) − E_i(begin), from the states
  double residual() const { return drive_work - damping_loss + tip_work - energy_change; }
};

/// Lock-in and energies of a multi-mode trajectory. The window of drive d is the last whole periods of ω_d that fit
/// in [t_end − periods·T_1, t_end] (T_1: the period of drive 1); the energies are taken over the window of drive 1.
class ModalLockIn : public TrajectoryObserver {
 public:
  ModalLockIn(const MultiModeModel& model, double t_end, int periods);
  void on_segment(const TappingSystem& system, const Segment& segment) override;

  /// Mode i (0-based) at drive d.
  ModalHarmonic mode(int i, int d) const { return ModalHarmonic::of(mode_[i][d] * (2.0 / window(d))); }
  /// The tip x (base motion included) at drive d.
  ModalHarmonic tip(int d) const { return ModalHarmonic::of(tip_[d] * (2.0 / window(d))); }
  double window(int d) const { return t_end_ - begin_[d]; }
  double window_begin(int d) const { return begin_[d]; }
  double mean() const { return mean_ / window(0); }  // mean tip position over the window of drive 1
  const ModeEnergy& energy(int i) const { return energy_[i]; }
  double min_gap() const { return min_gap_; }
  double peak_force() const { return peak_force_; }  // largest H = −h (per unit mode-1 mass; positive: repulsive)

 private:
  MultiModeModel model_;
  double t_end_;
  std::array<double, 2> begin_{};
  std::array<std::array<std::complex<double>, 2>, kMaxEigenmodes> mode_{};
  std::array<std::complex<double>, 2> tip_{};
  std::array<ModeEnergy, kMaxEigenmodes> energy_{};
  std::array<bool, 2> have_start_{};
  double mean_ = 0.0;
  double min_gap_ = 1e300, peak_force_ = -1e300;
  void modal_state(double t, const TipState& s, double* q, double* v, double* f) const;
  void integrate(const TappingSystem& system, const Segment& segment, double a, double b, double shortest);
  double stored_energy(int i, double q, double v) const;
};

/// The free (no tip force) steady state at time t: the tip, its velocity and the higher modal coordinates.
TipState free_steady_state(const MultiModeModel& model, double t);

/// The common period of the drives: T_1, or T = n_1 T_1 = n_2 T_2 when ω_2/ω_1 = n_2/n_1 with n_1, n_2 ≤
/// `max_multiple` (to 1e-12 relative); InvalidParameter("drives") when the drive frequencies are incommensurate.
double common_period(const MultiModeModel& model, int max_multiple = 64);

struct ModalShootingOptions {
  int max_iterations = 30;
  double tolerance = 1e-10;  // |Φ_T(z) − z| ≤ tolerance · max(1, |z|) (z: x, ẋ and the higher modal coordinates)
  int max_multiple = 64;     // of common_period
  SimulationOptions simulation;
};

/// A periodic orbit of a multi-mode cantilever with commensurate drives, by shooting: Newton on
/// Φ_T(z) − z = 0 over the common period T (z = x, ẋ, q_2, q̇_2, q_3, q̇_3 at time t0), the Jacobian by difference
/// quotients of whole simulations (the saltation at the events is in them).
struct ModalOrbit {
  TipState state;  // at t0
  double t0 = 0.0;
  double period = 0.0;
  double residual = 0.0;  // |Φ_T(z) − z| at the answer
  int iterations = 0;
  bool converged = false;
};
ModalOrbit modal_periodic_orbit(const MultiModeModel& model, double t0, TipState guess,
                                const ModalShootingOptions& options = {});

struct ModalResponseOptions {
  /// Drive-1 periods simulated before the lock-in (0: automatic, 2 max_i Q_i'ω_1'/ω_i' rounded up, at least 10:
  /// every mode's transient decays by e^{−2π}).
  long settle_periods = 0;
  long lockin_periods = 20;  // drive-1 periods of the lock-in window
  SimulationOptions simulation;
  /// After the settling, solve the periodic orbit by shooting from its end (commensurate drives; the lock-in
  /// window then spans whole common periods) and measure on it; where Newton fails, on the settled transient.
  bool periodic = false;
  ModalShootingOptions shooting;
  void validate() const;
  long settle_periods_for(const MultiModeModel& model) const;
};

/// The steady response at one separation, from `start` at time t_begin.
struct ModalResponse {
  double separation = 0.0;
  std::array<std::array<ModalHarmonic, 2>, kMaxEigenmodes> mode{};  // [mode][drive]
  std::array<ModalHarmonic, 2> tip{};
  std::array<ModeEnergy, kMaxEigenmodes> energy{};
  double mean = 0.0, min_gap = 0.0, peak_force = 0.0;
  double time = 0.0;  // end of the run
  TipState state;     // at the end of the run
  SimulationStats stats;
  bool periodic = false;        // measured on a periodic orbit found by shooting (ModalResponseOptions::periodic)
  double orbit_residual = 0.0;  // |Φ_T(z) − z| of that orbit (NaN when not asked)
};

ModalResponse modal_response(const MultiModeModel& model, double t_begin, TipState start,
                             const ModalResponseOptions& options = {});

/// Bimodal AM-AFM along an approach: the separations in the order given, each run from the end state of the
/// previous one (the first from the free steady state), as an instrument's piezo steps. `progress(n)` is called
/// after every point.
std::vector<ModalResponse> modal_sweep(const MultiModeModel& model, const std::vector<double>& separations,
                                       const ModalResponseOptions& options = {},
                                       const std::function<void(long)>& progress = {});

}  // namespace afmkit::tapping
