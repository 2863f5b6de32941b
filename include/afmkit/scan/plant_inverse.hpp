#pragma once
// Reconstruction of the height under the tip by inverting the plant of seed 2, eq. (1) (docs/scan.md#reconstruction).
//
// The deflection obeys ẏ = −γ (y − f) + u_a (u_a: the actuator's delayed control). Remove the part the calibrated
// actuator model attributes to u (ŷ_u, z_a = −ŷ_u): w = d + z_a = d − ŷ_u, the *lagged* reconstruction, obeys
//   ẇ = −γ (w − f)          (eq. 1 without the control term, by superposition)
// so w is f seen through a first-order lag: the image is turned by atan(Ω/γ) (the first harmonic exactly; smooth
// features by about Ω/γ). The inverse removes the lag: f = w + ẇ/γ. For a sampled signal it is done exactly for the
// simulator's discretisation: over each sample interval h the height ramps linearly from f_n to f_{n+1}
// (first-order hold), so the exact solution of eq. (1) gives, with x = γh, a = e^{−x},
//   w_{n+1} = a w_n + b0 f_n + b1 f_{n+1},     b1 = 1 − (1 − a)/x,   b0 = (1 − a)/x − a,   b0 + b1 = 1 − a,
// and its inverse is the recursion
//   f̂_{n+1} = (w_{n+1} − a w_n − b0 f̂_n) / b1,     f̂_0 = w_0 (the scan starts settled: y = f).
// Its pole p = −b0/b1 lies in (−1, 0) for every x > 0 (0 < b0 < b1 ⟺ tanh(x/2) < x/2 and e^x > 1 + x), so the
// recursion is stable; p → −(1 − x/3) as x → 0: an error (noise, a restart) rings at the Nyquist frequency and
// decays by |p| per sample. White noise of RMS σ on w comes out with RMS G σ, the noise gain
//   G² = Σ h_k² = (1 + (p − a)²/(1 − p²)) / b1²        (h_0 = 1/b1, h_k = p^{k−1}(p − a)/b1)
// (G ≈ 109 at the defaults, γh = 0.126: the price of undoing a lag from samples; the lagged reconstruction passes
// noise with gain 1). With an assumed γ̂ instead of the true γ, to first order in the mismatch and for frequencies
// well below γ, f̂ − f = (1/γ̂ − 1/γ) ḟ = (γ/γ̂ − 1) (f − w): the lagged reconstruction's error scaled by γ/γ̂ − 1.
// After a gap (a saturated sample: w unknown) the recursion restarts from the interval mean of the first two samples,
// f̂_k = (w_{k+1} − a w_k)/(1 − a) (the b-weighted mean of f_k and f_{k+1}: error ≈ (f_{k+1} − f_k)/2); the restart
// error decays as |p|^j, so the next `settle_samples()` samples (|p|^j > 1 %) are reported as NaN.
#include <cmath>
#include <cstdint>

namespace afmkit::scan {

/// Which reconstruction the topography image shows (both are computed and imaged).
enum class Reconstruction {
  inverse,  ///< f̂: the plant inverted (above); the default
  lagged,   ///< w = d + z_a: deflection plus calibrated actuator displacement (the plant's lag left in)
};

/// How the inverse treats detector noise (wiener_inverse.hpp, docs/scan.md#noise-aware-inverse).
enum class InverseFilter {
  wiener,  ///< the exact inverse followed by the Wiener low-pass along the turn (none when σ_d = 0); the default
  exact,   ///< the exact inverse alone (noise gain PlantInverse::noise_gain)
};

/// The instrument's model of its own plant for the reconstruction.
struct ReconstructionSpec {
  Reconstruction method = Reconstruction::inverse;
  double assumed_bandwidth = 0.0;  ///< γ̂ [rad/s] the reconstruction (and z_a) assume; 0 = the true bandwidth γ
  InverseFilter inverse_filter = InverseFilter::wiener;
  double prior_increment = 0.0;    ///< √A [m] of the Wiener prior; 0 = from the sample (prior_increment())
  /// InvalidParameter("reconstruction_bandwidth" / "prior_increment") unless finite and >= 0
  void validate() const;
};

/// The exact discrete inverse of the first-order lag for first-order-hold input (above), one sample at a time.
class PlantInverse {
 public:
  /// bandwidth γ̂ [rad/s] > 0, sample_rate f_s [Hz] > 0 (InvalidParameter naming "reconstruction_bandwidth" /
  /// "sample_rate").
  PlantInverse(double bandwidth, double sample_rate);

  /// w_n [m] → f̂_n [m]. A non-finite w_n (a gap) returns NaN and restarts the recursion at the next finite sample,
  /// whose first settle_samples() outputs are NaN.
  double step(double w) noexcept {
    if (!std::isfinite(w)) {
      restart_ = true;
      return nan();
    }
    if (restart_) {
      restart_ = false;
      f_ = w;
      w_ = w;
      settling_ = started_ ? settle_ : 0;
      pending_ = started_;
      started_ = true;
      return settling_ > 0 ? nan() : w;
    }
    // the first sample after a gap: f̂ of the previous one is the interval mean (w_{n+1} − a w_n)/(1 − a) = the
    // b-weighted mean of f_n and f_{n+1} (error ≈ (f_{n+1} − f_n)/2, instead of the lag error f − w)
    if (pending_) {
      f_ = (w - a_ * w_) / (b0_ + 1.0 / inv_b1_);
      pending_ = false;
    }
    f_ = (w - a_ * w_ - b0_ * f_) * inv_b1_;
    w_ = w;
    if (settling_ > 0) {
      --settling_;
      return nan();
    }
    return f_;
  }

  double decay() const { return a_; }       ///< a = e^{−γ̂h}
  double b0() const { return b0_; }         ///< weight of f_n
  double b1() const { return 1.0 / inv_b1_; }  ///< weight of f_{n+1}
  double pole() const { return -b0_ * inv_b1_; }  ///< p = −b0/b1, in (−1, 0)
  double noise_gain() const;                ///< G (above), dimensionless
  /// ρ1: correlation of consecutive outputs for white noise on w, Σ h_k h_{k+1} / Σ h_k² =
  /// ((p − a) + (p − a)² p/(1 − p²)) / (G b1)² (≈ −0.98 at the defaults: the noise comes out near Nyquist)
  double noise_correlation() const;
  /// The noise gain of an image: G √((2/3)(2/3 + ρ1/3)) — the imager interpolates linearly between neighbouring
  /// samples along the turn (weights 1 − s, s; E[(1 − s)² + s² + 2 s(1 − s) ρ1] = 2/3 + ρ1/3 for s uniform) and
  /// between neighbouring turns (independent noise: 2/3); ≈ 0.48 G at the defaults.
  double image_noise_gain() const;
  std::int64_t settle_samples() const { return settle_; }  ///< samples after a restart until |p|^k <= 1 %

 private:
  static double nan() noexcept;
  double a_ = 0, b0_ = 0, inv_b1_ = 0;
  double w_ = 0, f_ = 0;
  std::int64_t settle_ = 0, settling_ = 0;
  bool restart_ = true, started_ = false, pending_ = false;
};

}  // namespace afmkit::scan
