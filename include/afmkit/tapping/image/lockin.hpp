#pragma once
// The lock-in of the imaging engines (docs/theory-tapping.md#quasi-static-imaging, #time-domain-imaging), on the
// complex amplitude X + iY = B e^{iφ} of x ≈ B cos(ωt − φ):
//   * PhasorLag — a first-order lag (time constant τ) on X + iY, exact for an input held over each step
//     (zero-order hold): out ← in + e^{−Δt/τ} (out − in). The lock-in's output filter (τ = 1/(2π f_li), f_li its
//     −3 dB bandwidth) in both engines, and the quasi-static engine's cantilever lag (τ_c = 2Q/ω0);
//   * CycleLockIn — the time-domain engine's demodulator: the per-cycle X + iY (2/T ∫ x e^{−iωt} dt over one
//     drive cycle, exact zeros at 2ω and every harmonic) averaged over the last N cycles (boxcar), then the
//     PhasorLag output filter stepped once per cycle.
#include <complex>
#include <cmath>
#include <vector>

namespace afmkit::tapping::image {

class PhasorLag {
 public:
  /// τ >= 0 [s] (0: no lag, the output follows the input).
  explicit PhasorLag(double time_constant = 0.0) : time_constant_(time_constant) {}
  void reset(std::complex<double> value) { out_ = value; }
  /// One step of dt [s] with the input held at `in`; returns the output.
  std::complex<double> step(std::complex<double> in, double dt) {
    if (dt != last_dt_) {
      last_dt_ = dt;
      decay_ = time_constant_ > 0.0 ? std::exp(-dt / time_constant_) : 0.0;
    }
    out_ = in + decay_ * (out_ - in);
    return out_;
  }
  std::complex<double> output() const { return out_; }
  double time_constant() const { return time_constant_; }

 private:
  double time_constant_;
  std::complex<double> out_{};
  double last_dt_ = -1.0, decay_ = 0.0;
};

/// The lock-in's time constant of a −3 dB bandwidth [Hz] (0: none).
inline double lockin_time_constant(double bandwidth) {
  return bandwidth > 0.0 ? 1.0 / (2.0 * 3.14159265358979323846 * bandwidth) : 0.0;
}

class CycleLockIn {
 public:
  /// `cycles` N >= 1 of the boxcar, `period` T [s] of the drive, `bandwidth` of the output filter [Hz]. Allocates
  /// its window here, never in step().
  CycleLockIn(long cycles, double period, double bandwidth)
      : window_(static_cast<std::size_t>(cycles)), period_(period), filter_(lockin_time_constant(bandwidth)) {}
  /// Settled on a steady value (engagement).
  void reset(std::complex<double> value) {
    for (auto& w : window_) w = value;
    sum_ = value * static_cast<double>(window_.size());
    next_ = 0;
    filter_.reset(value);
  }
  /// One drive cycle's demodulated X + iY in; the output after the cycle.
  std::complex<double> step(std::complex<double> cycle) {
    sum_ += cycle - window_[next_];
    window_[next_] = cycle;
    if (++next_ == window_.size()) {  // re-sum once per window: no drift of the running sum
      next_ = 0;
      sum_ = {};
      for (const auto& w : window_) sum_ += w;
    }
    return filter_.step(sum_ / static_cast<double>(window_.size()), period_);
  }
  std::complex<double> output() const { return filter_.output(); }

 private:
  std::vector<std::complex<double>> window_;
  std::size_t next_ = 0;
  std::complex<double> sum_{};
  double period_;
  PhasorLag filter_;
};

}  // namespace afmkit::tapping::image
