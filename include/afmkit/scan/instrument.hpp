#pragma once
// The virtual rotational-scanning AFM (docs/scan.md): what the instrument is, in SI units.
//
// The sample spins on a spindle at f_rot (Ω = 2π f_rot) while the tip moves outwards at the radial speed v_r, so in
// the sample's frame the tip follows the spiral
//   θ(t) = Ω t,   r(t) = r_0 + v_r t,   (x, y) = r (cos θ, sin θ),   pitch = v_r / f_rot per turn.
// The height under the tip, f(t) = S(x, y) (topography + tilt, surface.hpp), drives the deflection signal y of the
// plant of seed 2, eq. (1), with an actuator that applies the controller's output u late by τ(t) and with a gain
// error ε:
//   ẏ = −γ (y − f) + (1 + ε) u(t − τ(t)),      τ(t) = τ + δτ sin(2π t / P_τ)     (slow drift)
// The deflection detector reads d = clamp(y + n, −R_d, R_d) (n: white Gaussian noise of RMS σ_d; beyond the linear
// range ±R_d the reading saturates). The controller of seed 2 (bank of N oscillators, couplings (20), gain K;
// eqs. 15, 6, 20) runs on the samples d_n through control::RealtimeFilter, exactly as it would be embedded.
// The topography is reconstructed from w = d + z_a, the deflection plus the calibrated actuator displacement
// z_a = −ŷ_u, ŷ_u the response of the nominal plant (γ̂, τ, ε = 0, no drift) to u: either w itself (the lagged
// reconstruction) or w with the plant's first-order lag removed (the inverse, plant_inverse.hpp).
#include <cstdint>

#include "afmkit/scan/plant_inverse.hpp"

namespace afmkit::scan {

/// The spindle and the spiral. The defaults here are a quick scan (5·10⁵ samples); `afmkit scan` samples denser by
/// default (radial_speed 150e-6 m/s, sample_rate 300e3 Hz: 8·10⁶ samples, the grating within 1 % of its RMS height,
/// docs/scan.md#reconstruction).
struct SpiralSpec {
  double spindle_frequency = 50.0;  ///< f_rot [Hz], > 0
  double start_radius = 0.0;        ///< r_0 [m], >= 0
  double end_radius = 4e-3;         ///< r_end [m], > r_0: the scan stops when r reaches it
  double radial_speed = 400e-6;     ///< v_r [m/s], > 0 (pitch 8 µm at 50 Hz)
  double sample_rate = 50e3;        ///< f_s [Hz], > 0, at least 16 samples per turn

  double rotation_frequency() const;  ///< Ω = 2π f_rot [rad/s]
  double pitch() const;               ///< radial advance per turn v_r / f_rot [m]
  double duration() const;           ///< (r_end − r_0) / v_r [s]
  std::int64_t samples() const;       ///< number of samples: floor(duration · f_s) + 1
  double samples_per_turn() const;    ///< f_s / f_rot
  /// InvalidParameter naming the field and its range (every value finite; samples() ≤ 10^10).
  void validate() const;
};

/// The z plant and actuator (seed-2 eq. 1 with an actuator delay that drifts, and a gain error).
struct PlantSpec {
  double bandwidth = 6283.185307179586;  ///< γ [rad/s], > 0 (default 2π · 1 kHz)
  double delay = 1e-3;                   ///< τ [s], >= 0, below one spindle period
  double delay_drift = 0.0;              ///< δτ [s], amplitude of the slow drift, 0 <= δτ <= τ
  double delay_drift_period = 10.0;      ///< P_τ [s], > 0
  double gain_error = 0.0;               ///< ε [dimensionless]: actuator sensitivity (1 + ε) × calibrated, > −1
  void validate(const SpiralSpec& spiral) const;
};

/// The deflection detector.
struct DetectorSpec {
  double range = 2e-6;    ///< R_d [m]: linear range ±R_d, > 0
  double noise = 0.0;     ///< σ_d [m]: RMS of white Gaussian noise added before the clamp, >= 0
  std::uint64_t seed = 1; ///< noise generator seed (std::mt19937_64; same seed, same noise)
  void validate() const;
};

/// The seed-2 controller (eqs. 15, 6, 20) in the loop, or off.
struct ControllerSpec {
  bool enabled = true;
  int harmonics = 10;   ///< N, >= 1 (N Ω below the Nyquist frequency π f_s)
  double alpha = 0.1;   ///< α in units of Ω (couplings 20: a0 = α, a_k = 2α)
  double beta = -0.1;   ///< β in units of Ω (couplings 20: b_k = −2β/k)
  double gain = 0.0;    ///< K [rad/s]; 0 = the design rule K = γ
  void validate() const;
};

struct InstrumentSpec {
  SpiralSpec spiral;
  PlantSpec plant;
  DetectorSpec detector;
  ControllerSpec controller;
  ReconstructionSpec reconstruction;
  /// All of the above, plus the cross-checks (delay below a period, Nyquist for N Ω).
  void validate() const;
  double controller_gain() const;  ///< K [rad/s]: controller.gain, or γ when it is 0
  /// γ̂ [rad/s] of the reconstruction and of the calibrated actuator model: reconstruction.assumed_bandwidth, or γ
  /// when it is 0.
  double assumed_bandwidth() const;
};

}  // namespace afmkit::scan
