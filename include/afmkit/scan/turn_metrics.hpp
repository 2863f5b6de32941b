#pragma once
// Per-turn metrics of a spiral scan (docs/scan.md#metrics): over each turn k (angle in [2πk, 2π(k+1))) the first
// harmonic of the deflection — what is left of the tilt after the controller — and, for reference, the first
// harmonic of the height under the tip and the tilt's own amplitude r̄ tan ψ.
//
// First harmonic of a channel over a turn: the least-squares fit c0 + a cos θ + b sin θ to the turn's samples
// (exact for a signal made of harmonics 0 and 1, whatever the number of samples per turn); amplitude √(a² + b²).
#include <cstdint>
#include <functional>

#include "afmkit/scan/spiral_scan.hpp"

namespace afmkit::scan {

/// One complete turn. Lengths in metres.
struct TurnRecord {
  std::int64_t turn = 0;                   ///< k
  double radius = 0.0;                     ///< mean radius over the turn [m]
  double deflection_first_harmonic = 0.0;  ///< amplitude of the deflection's first harmonic [m] (residual tilt)
  double surface_first_harmonic = 0.0;     ///< amplitude of the first harmonic of f (topography + tilt) [m]
  double tilt_first_harmonic = 0.0;        ///< r̄ tan ψ [m]
  std::int64_t samples = 0;                ///< samples in the turn
  std::int64_t saturated_samples = 0;      ///< of which the detector saturated
};

/// Amplitude of the first harmonic of samples (θ_j, v_j): least squares c0 + a cos θ + b sin θ (see above).
class FirstHarmonicFit {
 public:
  void add(double cos_theta, double sin_theta, double value) noexcept;
  /// Adds one sample to two fits over the same angles (the angle sums are computed once and copied).
  static void add_pair(FirstHarmonicFit& first, FirstHarmonicFit& second, double cos_theta, double sin_theta,
                       double first_value, double second_value) noexcept;
  /// √(a² + b²); NaN with fewer than three samples or a singular fit.
  double amplitude() const noexcept;
  std::int64_t count() const noexcept { return n_; }
  void clear() noexcept { *this = FirstHarmonicFit(); }

 private:
  std::int64_t n_ = 0;
  double sc_ = 0, ss_ = 0, scc_ = 0, scs_ = 0, sss_ = 0, sv_ = 0, svc_ = 0, svs_ = 0;
};

/// Observer that reports each complete turn to `on_turn` (the last, incomplete turn is not reported).
class TurnMetrics final : public ScanObserver {
 public:
  /// tilt_slope: tan ψ of the sample's tilt (for tilt_first_harmonic).
  TurnMetrics(double tilt_slope, std::function<void(const TurnRecord&)> on_turn);
  bool sample(const ScanSample& s) override;
  std::int64_t turns() const noexcept { return turns_; }

 private:
  void close_turn();
  /// cos θ, sin θ of the sample's angle: exactly for the first sample, every 1024th and after a jump of the angle
  /// step by more than 1e-6 rad; otherwise the previous pair rotated by the previous step (cached) and by the step's
  /// change δ (second-order series: error δ³/6 <= 2e-19), a relative drift below ~1e-13 between exact anchors.
  void angle_trig(double angle) noexcept;
  double slope_;
  double last_angle_ = 0, step_ = 0, cos_step_ = 1, sin_step_ = 0, cos_ = 1, sin_ = 0;
  int since_exact_ = -1;  // −1: no sample yet
  std::function<void(const TurnRecord&)> on_turn_;
  std::int64_t current_ = -1, turns_ = 0, saturated_ = 0;
  double turn_begin_ = 0, turn_end_ = -1;  // angles [2π k, 2π (k + 1)) of the current turn k (none yet)
  double radius_sum_ = 0.0;
  FirstHarmonicFit deflection_, surface_;
};

}  // namespace afmkit::scan
