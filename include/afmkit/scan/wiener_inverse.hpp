#pragma once
// The noise-aware plant inverse (docs/scan.md#noise-aware-inverse): the exact inverse f̂ (plant_inverse.hpp)
// followed by the Wiener low-pass along the turn.
//
// On the samples, w = L f + n with L(z) = (b1 + b0 z⁻¹)/(1 − a z⁻¹) the sampled lag and n white detector noise of
// variance σ². The exact inverse H = 1/L gives f̂ = f + H n, whose noise spectrum σ²|H(ω)|² grows near the Nyquist
// frequency (|H(π)| = (1 + a)/(b1 − b0) ≈ 12/(γh)²). The linear estimate of f from w with the least mean squared
// error for a signal spectrum S_f(ω) is (Wiener) H·W with
//   W(ω) = S_f / (S_f + σ²|H(ω)|²)                                              (0 ≤ W ≤ 1, W(0) = 1)
// i.e. the exact inverse followed by the zero-phase low-pass W. The prior: the height changes from sample to sample
// by white increments of variance A, S_f = A/|D(ω)|², |D|² = 2(1 − cos ω) — the first-difference (Tikhonov) prior
// of edges and steps: f̂_W minimises Σ(w − L f)²/σ² + Σ(Δf)²/A. Then
//   W(ω) = 1 / (1 + (σ²/A) |H(ω)|² |D(ω)|²),
// a low-pass whose half-power point is about ω_c ≈ (A (γh)²/σ²)^{1/4} rad/sample (|H| ≈ ω/γh, |D| ≈ ω above γh):
// the frequency where the lagged signal's spectrum meets the noise floor. W → 1 as σ/√A → 0 (the exact inverse).
// A = E[(f_{n+1} − f_n)²], the mean squared height change between consecutive samples, is the sample's: taken from
// the sample map along the scan's spiral (prior_increment below), or stated (ReconstructionSpec::prior_increment).
//
// When W stays within 1e−6 of 1 at every frequency the filter is the identity (one tap: the exact inverse as it is).
// Otherwise it is applied as the symmetric FIR g_k = (1/π)∫₀^π W(ω) cos kω dω, |k| ≤ K (the taps beyond K below
// 1e−7 g_0; at most kMaxHalfWidth, Hann-tapered when cut there), normalised to Σ g = 1 (a plane passes unchanged).
// Its error budget, for the taps as applied (G(ω) = g_0 + 2 Σ g_k cos kω), in closed form (integrals over ω):
//   noise:       σ² G_W² = σ² (1/π)∫₀^π |H|² G² dω   (white noise through the inverse and the low-pass)
//   ρ1:          (1/π)∫₀^π |H|² G² cos ω dω / G_W²    (consecutive outputs' correlation, for the imager)
//   resolution:  (1/π)∫₀^π |1 − G|² A/|D|² dω       (the height the low-pass removes, for a sample of the prior)
// The image noise gain is G_W √((2/3)(2/3 + ρ1/3)), as for the exact inverse (PlantInverse::image_noise_gain).
#include <optional>
#include <vector>

#include "afmkit/scan/instrument.hpp"
#include "afmkit/scan/plant_inverse.hpp"
#include "afmkit/scan/surface.hpp"

namespace afmkit::scan {

class WienerLowPass {
 public:
  static constexpr int kMaxHalfWidth = 128;

  /// The low-pass for the exact inverse `inverse`, detector noise σ_d = `noise` [m] > 0 and the prior's RMS
  /// height change per sample √A = `prior_increment` [m] > 0 (InvalidParameter "detector_noise" /
  /// "prior_increment" otherwise).
  WienerLowPass(const PlantInverse& inverse, double noise, double prior_increment);

  const std::vector<double>& taps() const { return taps_; }  ///< g_0 … g_K (g_{−k} = g_k), Σ over ±k = 1
  int half_width() const { return static_cast<int>(taps_.size()) - 1; }  ///< K
  double noise_gain() const { return noise_gain_; }                     ///< G_W (above), dimensionless
  double noise_correlation() const { return correlation_; }             ///< ρ1 (above)
  double image_noise_gain() const;                                      ///< G_W √((2/3)(2/3 + ρ1/3))
  double resolution() const { return resolution_; }                     ///< RMS bias for the prior [m]
  double cutoff() const { return cutoff_; }  ///< ω where G(ω) = 1/2 [rad/sample] (π if G stays above)
  double prior_increment() const { return prior_; }  ///< √A [m] as given

 private:
  std::vector<double> taps_;
  double noise_gain_ = 0, correlation_ = 0, resolution_ = 0, cutoff_ = 0, prior_ = 0;
};

/// √A [m]: the RMS change of the topography (the tilt left out: a first harmonic of the turn, not an edge) between
/// consecutive samples of the instrument's spiral, from 65536 pairs of samples spread evenly over the scan.
double prior_increment(const InstrumentSpec& instrument, const Surface& surface);

/// The height the taps remove from this sample along the instrument's spiral [m]: RMS(g * f − f) over 64 stretches
/// of 2048 consecutive samples spread evenly over the scan (the true heights f, tilt included, at the sample
/// positions; the filter's full window only) — the resolution term of the budget for the sample itself, where
/// WienerLowPass::resolution() is that of the prior.
double sampled_resolution(const InstrumentSpec& instrument, const Surface& surface, const WienerLowPass& filter);

/// The least √A [m] for which W ≥ 0.99 up to the rotation's harmonic N + 1 (ω = 2π (N + 1) f_rot/f_s, `harmonics`
/// N of the controller): the harmonics the tilt and the controller put into w pass whatever the prior (a flat
/// topography has A = 0, which would filter them away with the noise).
double prior_increment_floor(const PlantInverse& inverse, double noise, int harmonics, double turns_per_sample);

/// The low-pass the instrument's reconstruction applies after the exact inverse on this surface: none when
/// reconstruction.inverse_filter is `exact`, the detector has no noise (σ_d = 0) or the filter is the identity
/// (above): the exact inverse, unchanged.
/// The prior: reconstruction.prior_increment when > 0, else prior_increment(instrument, surface), at least
/// prior_increment_floor.
std::optional<WienerLowPass> noise_aware_filter(const InstrumentSpec& instrument, const Surface& surface);

}  // namespace afmkit::scan
