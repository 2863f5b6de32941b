#pragma once
// The exact time-domain tip engine (docs/theory-tapping.md#time-domain-imaging): the cantilever ODE of seed-1 eq. 8
// stepped drive cycle by drive cycle by the one event engine (simulation.hpp: closed-form flow for
// piecewise-linear laws, DOP853/Dopri5 with located events otherwise), the force law seeing the sample height under
// the moving tip: over each cycle the separation is l = Z − h(x_tip, y), h interpolated along the line at the
// tip's lateral position at the middle of the cycle (held over the cycle: a lateral error of at most half a
// cycle's travel, v T/2). The cycles start where the engaged orbit is at its top (ωt − φ = 0), so the separation
// moves while the tip is farthest from the sample. The lock-in demodulates every cycle exactly
// (2/T ∫ x e^{−iωt} dt by Gauss–Legendre quadrature on the trajectory's smooth segments), averages the last N
// cycles and passes them through its first-order output filter (CycleLockIn, lockin.hpp). Z is held over a
// controller period; the controller reads the lock-in after the whole cycles that end within it (the clock carries
// the remainder, so updates that are not whole cycles alternate between ⌊n⌋ and ⌈n⌉ cycles).
//
// Engagement: at the separation where the orbit map's approach reaches the set-point (the same engagement as the
// quasi-static engine), the periodic orbit there by shooting, the lock-in settled on it.
//
// The per-cycle loop allocates nothing (the system's separation moves in place; the lock-in window is allocated
// once). One thread: the loop carries Z, the integral and the orbit from line to line.
#include "afmkit/tapping/image/imaging.hpp"
#include "afmkit/tapping/image/lockin.hpp"
#include "afmkit/tapping/image/orbit_map.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/system.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::tapping::image {

struct TimeDomainOptions {
  long lockin_cycles = 1;          // N: drive cycles the lock-in averages (boxcar), >= 1
  double lockin_bandwidth = 5e3;   // −3 dB bandwidth of the lock-in's output filter [Hz] (0: none)
  ShootingOptions shooting;        // the engaged orbit; shooting.simulation: the integrator of every cycle
  /// Relative tolerance of the cycles' adaptive integrator (absolute: 1e-2 of it, model length units); the
  /// engagement's shooting keeps shooting.simulation's. 1e-8: the image then differs from the converged one (1e-12)
  /// by less than its GSF files' float32 rounding (DMT + vdW, 16 nm amplitude: height 3e-15 m, amplitude 4e-15 m,
  /// phase 7e-5 deg, peak force 4e-6 relative; docs/theory-tapping.md#time-domain-imaging).
  double cycle_tolerance = 1e-8;
  void validate() const;           // InvalidParameter naming lockin_cycles, lockin_bandwidth, cycle_tolerance
};

class TimeDomainEngine final : public TipEngine {
 public:
  /// The adaptive integrator's largest step in the cycles, as a fraction of the shortest period (SimulationOptions::
  /// max_step_fraction; the closed-form flow keeps its own scan step).
  static constexpr double kCycleMaxStepFraction = 1.0 / 12.0;

  /// `model`: cantilever, drive and law (model units; its separation is moved); `map`: the approach that engages
  /// (kept by reference); `scales` to SI (PhysicalCantilever::scales()).
  TimeDomainEngine(const TappingModel& model, const OrbitMap& map, const UnitScales& scales,
                   const TimeDomainOptions& options);

  double free_amplitude() const override { return map_.free_amplitude() * metres_; }
  double drive_frequency() const override { return 1.0 / period_; }
  double engage(double amplitude) override;
  TipReading advance(const scan::Surface& surface, double z, double x0, double x1, double y, double dt) override;

  long cycles() const { return cycles_; }     // drive cycles simulated since the engagement
  long events() const { return events_; }     // events located over them (contact entries, branch switches)
  long steps() const { return steps_; }      // integrator steps over them
  bool engaged_by_shooting() const { return shot_; }  // false: settled by simulation instead

 private:
  struct Cycle;  // one cycle's integrals
  Cycle run_cycle(double separation);
  const OrbitMap& map_;
  TappingSystem system_;
  SimulationOptions simulation_;
  ShootingOptions shooting_;
  double metres_, newtons_, watts_;
  double omega_, model_period_, period_;  // ω and T (model units), T [s]
  double start_ = 0.0;                     // model time of a cycle's start (the top of the engaged orbit)
  TipState state_;
  double next_step_ = 0.0;                 // the adaptive integrator's step at the end of the last cycle
  double free_fraction_ = 1e-9;            // |H_c| below this fraction of Γ: the free regime (regime_of)
  CycleLockIn lockin_;
  double clock_ = 0.0, target_ = 0.0;      // [s] since the engagement: cycles done, time requested
  TipReading last_;
  long cycles_ = 0, events_ = 0, steps_ = 0;
  bool shot_ = false;
};

}  // namespace afmkit::tapping::image
