#pragma once
// Time-domain simulation of the virtual rotational scan (instrument.hpp, docs/scan.md): one sample per 1/f_s,
// handed to an observer as it is produced (nothing is stored: memory does not grow with the number of samples).
//
// Stepping (exact for the model as sampled): over each sample interval [t_n, t_n + h), h = 1/f_s, the height under
// the tip ramps linearly from f(t_n) to f(t_{n+1}) (first-order hold: no lag of the sampled surface even for a very
// fast plant) and the controller output is held at u_n (zero-order hold, as a DAC holds it); the actuator applies u
// late by τ(t_n), so the interval splits where the delayed control switches from u_{n−i−1} to u_{n−i}
// (i = floor(τ f_s)), and on each piece the plant (eq. 1) is advanced by its exact solution for a ramped target
// g = f + (1 + ε) u / γ with slope ġ:
//   y ← g(end) − ġ/γ + (y − g(start) + ġ/γ) e^{−γ δ}.
// The same update with the nominal values (γ̂ = InstrumentSpec::assumed_bandwidth(), ε = 0, τ without drift) gives
// ŷ_u, the part of y the calibrated actuator model attributes to u; the calibrated actuator displacement is
// z_a = −ŷ_u (it moves the tip by what it removes from the deflection), so the lagged reconstruction is
// w = d + z_a, and the inverse one f̂ = PlantInverse(γ̂) applied to w (plant_inverse.hpp; exact for this stepping
// when γ̂ = γ, ε = 0, no drift, no noise, no saturation).
// The sample observed at t_n is taken before the update: d_n from y(t_n), u_n = filter output for the state before
// d_n is added (the real-time filter has no direct feed-through).
#include <cstdint>
#include <functional>
#include <vector>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/scan/instrument.hpp"
#include "afmkit/scan/surface.hpp"

namespace afmkit::scan {

/// One sample of the scan. Lengths in metres, u in m/s.
struct ScanSample {
  std::int64_t index;  ///< n
  double time;         ///< t_n [s]
  double angle;        ///< θ = Ω t_n [rad], unwrapped
  double radius;       ///< r [m]
  double surface;      ///< f: topography + tilt under the tip [m]
  double deflection;   ///< detector reading d_n [m] (clamped to ±R_d when saturated)
  double control;      ///< controller output u_n [m/s] (0 with the controller off)
  double actuator;     ///< calibrated actuator displacement z_a = −ŷ_u(t_n) [m]
  double topography;   ///< lagged reconstruction w_n = d_n + z_a [m]
  /// inverse reconstruction f̂_n [m] (NaN when saturated and while settling after it); with detector noise and the
  /// Wiener low-pass (ReconstructionSpec::inverse_filter, wiener_inverse.hpp) the filtered one
  double inverse;
  bool saturated;      ///< |y + noise| > R_d at this sample
};

/// Receives the samples in time order. Return false to stop the scan early.
class ScanObserver {
 public:
  virtual ~ScanObserver() = default;
  virtual bool sample(const ScanSample& s) = 0;
};

/// Several observers in turn (the scan stops when any of them asks).
class ObserverChain final : public ScanObserver {
 public:
  explicit ObserverChain(std::vector<ScanObserver*> observers) : observers_(std::move(observers)) {}
  bool sample(const ScanSample& s) override {
    bool go = true;
    for (ScanObserver* o : observers_) go = o->sample(s) && go;
    return go;
  }

 private:
  std::vector<ScanObserver*> observers_;
};

struct ScanRun {
  std::int64_t samples = 0;            ///< samples produced
  std::int64_t saturated_samples = 0;  ///< samples with the detector saturated
  bool stopped_early = false;          ///< an observer stopped the scan
  double first_saturation_radius = -1; ///< r at the first saturated sample [m]; −1 when none saturated
  std::uint64_t filter_skipped = 0;    ///< samples the real-time filter refused (non-finite; 0 in a sound run)
};

/// Runs the scan of `surface` by `instrument` (validated first: InvalidParameter naming the field), calling
/// `observer` for every sample, in order (with the Wiener low-pass of the inverse, noise_aware_filter(), each sample
/// is handed on K samples late, when the window after it has been simulated; the last K after the loop). `progress(done, total)` (may be empty) is called about every 2^16 samples.
/// `cancellation` is checked every 65536 samples (core/cancellation.hpp).
/// `first_sample` > 0 starts the scan at that sample (a multiple of 4096, where the tip's angle is computed exactly,
/// so every later tip position is the full run's to the bit; InvalidParameter "first_sample" otherwise, or when it is
/// not below samples()), with the plant settled on the surface there (y = f) and no control history: for the
/// uncontrolled run, whose state forgets its start as e^{−γ t} (uncontrolled_saturation.hpp).
ScanRun simulate_scan(const InstrumentSpec& instrument, const Surface& surface, ScanObserver& observer,
                      const std::function<void(std::int64_t, std::int64_t)>& progress = {},
                      const Cancellation& cancellation = {}, std::int64_t first_sample = 0);

}  // namespace afmkit::scan
