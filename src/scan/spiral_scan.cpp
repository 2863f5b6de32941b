// Time-domain simulation of the virtual rotational scan (spiral_scan.hpp, docs/scan.md).
#include "afmkit/scan/spiral_scan.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include <fmt/format.h>

#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/scan/wiener_inverse.hpp"

namespace afmkit::scan {

namespace {

// The split of one sample interval by the actuator delay τ = (i + φ) h: the control applied over the first φh is
// u_{n−i−1}, over the remaining (1 − φ)h it is u_{n−i}; e_first/e_second are the plant's decay factors over them.
struct DelaySplit {
  std::int64_t whole = 0;  // i
  double fraction = 0.0;   // φ
  double e_first = 1.0, e_second = 1.0;
  static DelaySplit of(double delay, double sample_rate, double bandwidth) {
    const double h = 1.0 / sample_rate;
    const double samples = delay * sample_rate;
    DelaySplit s;
    s.whole = static_cast<std::int64_t>(std::floor(samples));
    s.fraction = samples - static_cast<double>(s.whole);
    s.e_first = std::exp(-bandwidth * s.fraction * h);
    s.e_second = std::exp(-bandwidth * (1.0 - s.fraction) * h);
    return s;
  }
};

// Exact step of ẏ = −γ (y − target) over a piece with decay factor e = e^{−γδ}.
inline double relax(double y, double target, double e) { return target + (y - target) * e; }

// Exact step of ẏ = −γ (y − g(t)) over a piece where g ramps linearly from g_start to g_end at the rate `slope`:
// the particular solution g(t) − slope/γ plus the decaying homogeneous part.
inline double relax_ramp(double y, double g_start, double g_end, double lag, double e) {
  return g_end - lag + (y - g_start + lag) * e;
}

// The Wiener low-pass (wiener_inverse.hpp) on the inverse channel, applied as the samples stream: each sample is
// handed on K samples late, its inverse replaced by Σ g_|j−c| f̂_j over the window j = c − K … c + K. Where the
// window reaches past the scan's ends or holds non-finite values (saturated or settling samples) the finite taps
// are renormalised (NaN when their weights sum below 1/2, or when f̂_c itself is NaN).
class DelayedLowPass {
 public:
  DelayedLowPass(const WienerLowPass& filter, std::int64_t first)
      : taps_(filter.taps()), k_(filter.half_width()), first_(first), next_(first), last_(first - 1) {
    const auto size = std::bit_ceil(static_cast<std::uint64_t>(2 * k_ + 2));
    mask_ = size - 1;
    samples_.resize(size);
    values_.resize(2 * size);  // each value twice (slot and slot + size): every window is contiguous
    for (std::int64_t k = -k_; k <= k_; ++k) window_.push_back(taps_[static_cast<std::size_t>(k < 0 ? -k : k)]);
  }

  /// Stores s (the next sample); true with `out` = the sample K back, filtered, when there is one.
  bool push(const ScanSample& s, ScanSample& out) {
    const std::int64_t n = s.index;
    const std::int64_t leaving = n - 2 * k_ - 1;
    if (leaving >= first_ && !std::isfinite(values_[slot(leaving)])) --bad_;
    samples_[slot(n)] = s;
    values_[slot(n)] = s.inverse;
    values_[slot(n) + mask_ + 1] = s.inverse;
    if (!std::isfinite(s.inverse)) ++bad_;
    last_ = n;
    if (n - k_ < next_) return false;
    emit(out);
    return true;
  }
  /// After the last sample: the ones still held, in order (false when none is left).
  bool pop(ScanSample& out) {
    if (next_ > last_) return false;
    emit(out);
    return true;
  }

 private:
  std::uint64_t slot(std::int64_t n) const { return static_cast<std::uint64_t>(n) & mask_; }
  void emit(ScanSample& out) {
    const std::int64_t c = next_++;
    out = samples_[slot(c)];
    const double centre = values_[slot(c)];
    if (!std::isfinite(centre)) return;  // NaN stays NaN
    const std::int64_t lo = std::max(first_, c - k_), hi = std::min(last_, c + k_);
    if (bad_ == 0 && lo == c - k_ && hi == c + k_) {  // the full window, contiguous
      const double* x = values_.data() + slot(c - k_);
      const double* g = window_.data();
      const auto n = static_cast<std::int64_t>(window_.size());
      double a[8] = {0, 0, 0, 0, 0, 0, 0, 0};  // eight independent partial sums (the adds' latency hidden)
      std::int64_t j = 0;
      for (; j + 8 <= n; j += 8)
        for (int l = 0; l < 8; ++l) a[l] += g[j + l] * x[j + l];
      for (; j < n; ++j) a[0] += g[j] * x[j];
      out.inverse = ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7]));
      return;
    }
    double sum = 0.0, weights = 0.0;
    for (std::int64_t j = lo; j <= hi; ++j) {
      const double v = values_[slot(j)];
      if (!std::isfinite(v)) continue;
      const double g = taps_[static_cast<std::size_t>(j > c ? j - c : c - j)];
      sum += g * v;
      weights += g;
    }
    out.inverse = weights >= 0.5 ? sum / weights : std::numeric_limits<double>::quiet_NaN();
  }

  std::vector<double> taps_, window_;  // g_0 … g_K; g_{−K} … g_K
  std::int64_t k_, first_, next_, last_;
  std::uint64_t mask_ = 0;
  std::vector<ScanSample> samples_;
  std::vector<double> values_;
  std::int64_t bad_ = 0;  // non-finite values among the last 2K + 1 pushed
};

}  // namespace

ScanRun simulate_scan(const InstrumentSpec& instrument, const Surface& surface, ScanObserver& observer,
                      const std::function<void(std::int64_t, std::int64_t)>& progress,
                      const Cancellation& cancellation, std::int64_t first_sample) {
  instrument.validate();
  const SpiralSpec& spiral = instrument.spiral;
  const PlantSpec& plant = instrument.plant;
  const DetectorSpec& detector = instrument.detector;
  const double fs = spiral.sample_rate, h = 1.0 / fs;
  const double omega = spiral.rotation_frequency();
  const double gamma = plant.bandwidth;
  const std::int64_t total = spiral.samples();
  if (first_sample < 0 || first_sample % 4096 != 0 || (first_sample > 0 && first_sample >= total))
    throw InvalidParameter("first_sample", fmt::format("first_sample = {} is out of range: must be a multiple of 4096 "
                                                       "below the scan's {} samples (or 0)", first_sample, total));

  std::optional<control::RealtimeFilter> filter;
  if (instrument.controller.enabled)
    filter.emplace(control::RealtimeFilter::with_couplings(fs, omega, instrument.controller.harmonics,
                                                           instrument.controller.alpha * omega,
                                                           instrument.controller.beta * omega,
                                                           instrument.controller_gain()));

  // Past controller outputs, as far back as the longest delay reaches (a power-of-two ring).
  const auto reach = static_cast<std::int64_t>(std::floor((plant.delay + plant.delay_drift) * fs)) + 2;
  const auto ring_size = std::bit_ceil(static_cast<std::uint64_t>(reach));
  const std::uint64_t mask = ring_size - 1;
  std::vector<double> history(ring_size, 0.0);
  const auto past = [&](std::int64_t j) { return j < 0 ? 0.0 : history[static_cast<std::uint64_t>(j) & mask]; };

  const double gamma_hat = instrument.assumed_bandwidth();
  const DelaySplit actual = DelaySplit::of(plant.delay, fs, gamma);      // the plant at the nominal delay
  const DelaySplit nominal = DelaySplit::of(plant.delay, fs, gamma_hat);  // the calibrated actuator model
  PlantInverse inverse(gamma_hat, fs);
  std::optional<DelayedLowPass> low_pass;  // the noise-aware inverse's low-pass (none: the exact inverse as it is)
  if (const std::optional<WienerLowPass> filter = noise_aware_filter(instrument, surface))
    low_pass.emplace(*filter, first_sample);
  ScanSample delayed{};
  const bool drifts = plant.delay_drift > 0.0;
  const double drift_rate = 2.0 * std::numbers::pi / plant.delay_drift_period;
  const double actuator_gain = (1.0 + plant.gain_error) / gamma;  // y* = f + (1 + ε) u / γ
  const double calibrated_gain = 1.0 / gamma_hat;
  const double lag_per_step = fs / gamma;  // (slope / γ) per unit height change over one sample

  std::mt19937_64 rng(detector.seed);
  std::normal_distribution<double> noise(0.0, detector.noise > 0.0 ? detector.noise : 1.0);

  ScanRun run;
  const double cos_step = std::cos(omega * h), sin_step = std::sin(omega * h);
  // tip position of sample n: exact angle now and then, a rotation recurrence in between
  double cos_theta = 1.0, sin_theta = 0.0;
  const auto height_at = [&](std::int64_t n) {
    const double t = static_cast<double>(n) * h;
    if ((n & 4095) == 0) {
      cos_theta = std::cos(omega * t);
      sin_theta = std::sin(omega * t);
    }
    const double r = spiral.start_radius + spiral.radial_speed * t;
    return surface(r * cos_theta, r * sin_theta);
  };
  const auto rotate = [&] {
    const double c = cos_theta * cos_step - sin_theta * sin_step;
    sin_theta = sin_theta * cos_step + cos_theta * sin_step;
    cos_theta = c;
  };
  double f = height_at(first_sample);
  double y = f, y_hat = 0.0;  // the deflection settled on the surface before the scan starts; no actuator motion
  for (std::int64_t n = first_sample; n < total; ++n) {
    const double t = static_cast<double>(n) * h;
    const double theta = omega * t;
    const double r = spiral.start_radius + spiral.radial_speed * t;

    const double reading = detector.noise > 0.0 ? y + noise(rng) : y;
    const bool saturated = !(std::abs(reading) <= detector.range);
    const double d = std::clamp(reading, -detector.range, detector.range);
    const double u = filter ? filter->step(d) : 0.0;
    history[static_cast<std::uint64_t>(n) & mask] = u;
    if (saturated) {
      if (run.saturated_samples == 0) run.first_saturation_radius = r;
      ++run.saturated_samples;
    }
    ++run.samples;
    const double w = d - y_hat;
    const double f_hat = inverse.step(saturated ? std::numeric_limits<double>::quiet_NaN() : w);
    const ScanSample s{n, t, theta, r, f, d, u, -y_hat, w, f_hat, saturated};
    if (low_pass ? low_pass->push(s, delayed) && !observer.sample(delayed) : !observer.sample(s)) {
      run.stopped_early = true;
      break;
    }

    // advance the plant (eq. 1) and the calibrated actuator model over [t_n, t_n + h); the height under the tip
    // ramps linearly from f_n to f_{n+1} (first-order hold), the delayed control is piecewise constant
    rotate();
    const double f_next = height_at(n + 1);
    const DelaySplit split = drifts ? DelaySplit::of(plant.delay + plant.delay_drift * std::sin(drift_rate * t),
                                                     fs, gamma)
                                    : actual;
    const double lag = (f_next - f) * lag_per_step;  // slope / γ
    const double f_split = f + (f_next - f) * split.fraction;
    const double before = actuator_gain * past(n - split.whole - 1), after = actuator_gain * past(n - split.whole);
    y = relax_ramp(y, f + before, f_split + before, lag, split.e_first);
    y = relax_ramp(y, f_split + after, f_next + after, lag, split.e_second);
    y_hat = relax(y_hat, calibrated_gain * past(n - nominal.whole - 1), nominal.e_first);
    y_hat = relax(y_hat, calibrated_gain * past(n - nominal.whole), nominal.e_second);
    f = f_next;
    if ((n & 65535) == 65535) {
      cancellation.check();
      if (progress) progress(n + 1, total);
    }
  }
  if (low_pass && !run.stopped_early)
    while (low_pass->pop(delayed))
      if (!observer.sample(delayed)) {
        run.stopped_early = true;
        break;
      }
  if (filter) run.filter_skipped = filter->skipped_samples();
  if (progress) progress(run.samples, total);
  return run;
}

}  // namespace afmkit::scan
