#pragma once
// Time-domain simulation of the seed-2 closed loop (docs/theory-control.md#simulation):
//   plant   first order ẏ = −γ (y − f(Ωt)) + u (eq. 1) or static y = f(Ωt) + u/γ (eq. 3), plant.hpp
//   measure m(t) = y(t − τ(t))   (τ may vary slowly: Plant::delay_at; off-grid values by cubic interpolation)
//   control u = −w, w = controller output: finite oscillator bank (eq. 15, 6) or the N = ∞ neutral
//           realisation (eqs. 32–33, with the Heaviside rule: both delay lines read 0 during the first period).
//
// Fixed step h = T/M (M = steps_per_period, T = 2π/Ω of the plant). The controller is stepped either by
//   * AdamsBashforth3 — as in the paper (AB1, AB2 for the first two steps), with its dense output (the
//     integrated interpolation polynomial of the derivatives) giving u as a cubic in t over each step; or
//   * ZeroOrderHold  — the exact discretisation for a held sample m_n (Φ = e^{Ah}, Γ; computed in the modal
//     coordinates of A from bank_eigenvalues(), O(N) per step, no N×N matrix), output u_n = −K c_rᵀ z_n held over
//     the step (a DAC); finite banks only;
//   * BlockZeroOrderHold — each oscillator exact for the held error e_n (discretisation.hpp: SampledForm), u held;
//     finite banks only. The two ZOH forms are what RealtimeFilter runs (computed there independently).
// The first-order plant is integrated exactly over each step for the polynomial u and the trigonometric f
// (φ-functions), so only the controller discretisation contributes error. Initial state (theory-control.md#simulation):
// controller 0; y(t ≤ 0) = the uncontrolled steady-state output (the plant ran before the controller started).
//
// Report: harmonics of y over the last period (exact projection of the M samples), compared with the analytic
// steady state (harmonic k ≥ 2: f_k for plant (3), γ f_k/(γ + ikΩ) for plant (1); 0 for rejected k);
// per-period envelope of |y_1| and the fitted growth rate; decimated time series.
#include <complex>
#include <functional>
#include <string>
#include <vector>

#include "afmkit/control/plant.hpp"
#include "afmkit/control/smith_predictor.hpp"  // control::Bank = variant<OscillatorBank, InfiniteBank>

namespace afmkit::control {

enum class ControllerStepping { AdamsBashforth3, ZeroOrderHold, BlockZeroOrderHold };

struct SimulationOptions {
  int periods = 60;              // number of rotation periods simulated (≥ 1)
  int steps_per_period = 2000;   // M: h = T/M (≥ 8, Nyquist M > 2N, AB3 region)
  ControllerStepping stepping = ControllerStepping::AdamsBashforth3;
  int record_every = 1;          // keep every n-th step in the time series (0: no time series)
  /// Highest harmonic order k in the report (0: the bank's N, or for N = ∞ the highest order of f). Orders above
  /// N show what the controller does to harmonics it does not model (< M/2).
  int report_max_order = 0;
};

/// One harmonic of y over the last period against its analytic steady-state target.
struct HarmonicComparison {
  int order;                     // k
  std::complex<double> value;    // y_k
  std::complex<double> target;   // 0 (rejected) or the uncontrolled steady state
  double error;                  // |y_k − target|
};

struct SimulationReport {
  double step = 0;                                 // h
  int steps_per_period = 0;
  int periods_completed = 0;                       // < requested if the run diverged
  bool diverged = false;                           // |y| exceeded 1e100 or became non-finite: run stopped
  bool delay_exceeds_period = false;               // τ ≥ T somewhere (allowed; the paper assumes τ < T)
  std::complex<double> first_harmonic;             // y_1 over the last period
  double residual_first_harmonic = 0;              // |y_1|
  std::vector<HarmonicComparison> harmonics;       // k = 0 … report_max_order except a rejected k = 1 (rejected
                                                   // k target 0); default up to N (N = ∞: the max order of f)
  int bank_max_order = 0;                          // N (N = ∞: max order of f): orders the controller models
  double max_harmonic_error = 0;                   // max over `harmonics` with k ≤ bank_max_order
  double max_harmonic_error_above = 0;             // max over `harmonics` with k > bank_max_order (NaN: none)
  std::complex<double> control_first_harmonic;     // u_1 (expected −γ f_1 when only k = 1 is rejected)
  std::vector<double> envelope;                    // |y_1| of each complete period
  double growth_rate = 0;                          // fitted slope of ln envelope [1/s] (NaN if undetermined)
  int fit_first_period = 0, fit_last_period = -1;  // fit window
};

struct TimeSeries {
  std::vector<double> t, y, u, m;  // time, plant output, control, measurement y(t − τ)
  std::vector<double> target;      // target output (uncontrolled steady state without the rejected harmonics)
  std::vector<double> f_minus_first;  // f − f^(1) (disturbance without its first harmonic)
};

struct SimulationResult {
  SimulationReport report;
  TimeSeries series;
};

/// progress(done_periods, total_periods), called once per period.
using SimulationProgress = std::function<void(long, long)>;

/// One recorded step of the time series (the columns of TimeSeries).
struct TimeSample {
  double t, y, u, m, target, f_minus_first;
};
/// Receives every recorded step in time order (streaming: the series is then not kept in memory).
using SampleSink = std::function<void(const TimeSample&)>;

class ClosedLoopSimulation {
 public:
  /// Validates (InvalidParameter naming the parameter and the allowed range): periods ≥ 1;
  /// 0 ≤ report_max_order < steps_per_period/2;
  /// steps_per_period ≥ 8 and > 2·(highest harmonic of the controller and of f) (Nyquist); record_every ≥ 0;
  /// AB3: h·λ inside the AB3 stability region for every eigenvalue λ of the controller's state matrix (growing
  /// modes are mirrored, −λ̄); N = ∞: AB3 only, α > 0 (|B4/A4| < 1), controller Ω = plant Ω.
  ClosedLoopSimulation(Plant plant, Bank controller, SimulationOptions options = {});

  /// Runs the loop. With a `sink`, every recorded step (record_every) is passed to it as it is computed and
  /// `series` stays empty (memory independent of the run length); without one, `series` holds them.
  /// Cost: O(N) per step for every stepping (ZOH in modal coordinates), O(N²) set-up (controller modes).
  SimulationResult run(const SimulationProgress& progress = {}, const SampleSink& sink = {}) const;

  const Plant& plant() const& { return plant_; }
  const Plant& plant() const&& = delete;
  const Bank& controller() const& { return controller_; }
  const Bank& controller() const&& = delete;
  const SimulationOptions& options() const& { return options_; }
  const SimulationOptions& options() const&& = delete;
  double step() const;  // h = T/M
  /// Harmonics rejected by the controller ({1} for N = ∞).
  std::vector<int> rejected() const;

 private:
  Plant plant_;
  Bank controller_;
  SimulationOptions options_;
};

/// Convenience: ClosedLoopSimulation(plant, controller, options).run().
SimulationResult simulate_closed_loop(const Plant& plant, const Bank& controller, const SimulationOptions& options = {});

std::string to_string(ControllerStepping stepping);  // "ab3" | "zoh" | "block_zoh"

}  // namespace afmkit::control
