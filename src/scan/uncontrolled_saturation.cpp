// The uncontrolled run of the scan-area comparison, simulated only where it can saturate (uncontrolled_saturation.hpp).
#include "afmkit/scan/uncontrolled_saturation.hpp"

#include <algorithm>
#include <cmath>

#include "afmkit/scan/spiral_scan.hpp"

namespace afmkit::scan {

namespace {

// Stops the scan at the first saturated sample.
class StopAtFirstSaturation final : public ScanObserver {
 public:
  bool sample(const ScanSample& s) override { return !s.saturated; }
};

UncontrolledSaturation run_uncontrolled_from(const InstrumentSpec& off, const Surface& surface, std::int64_t first,
                                const Cancellation& cancellation) {
  StopAtFirstSaturation stop;
  const ScanRun run = simulate_scan(off, surface, stop, {}, cancellation, first);
  UncontrolledSaturation out;
  out.saturates = run.saturated_samples > 0;
  out.radius = out.saturates ? run.first_saturation_radius : off.spiral.end_radius;
  out.first_sample = first;
  out.samples = run.samples;
  return out;
}

InstrumentSpec with_control_off(const InstrumentSpec& instrument) {
  InstrumentSpec off = instrument;
  off.controller.enabled = false;
  off.reconstruction.inverse_filter = InverseFilter::exact;  // only the deflection matters here
  off.validate();
  return off;
}

}  // namespace

UncontrolledSaturation first_uncontrolled_saturation_full(const InstrumentSpec& instrument, const Surface& surface,
                                                          const Cancellation& cancellation) {
  return run_uncontrolled_from(with_control_off(instrument), surface, 0, cancellation);
}

UncontrolledSaturation first_uncontrolled_saturation(const InstrumentSpec& instrument, const Surface& surface,
                                                     const Cancellation& cancellation) {
  const InstrumentSpec off = with_control_off(instrument);
  if (off.detector.noise > 0.0) return run_uncontrolled_from(off, surface, 0, cancellation);  // noise is unbounded: no skip
  const SpiralSpec& s = off.spiral;
  double largest = 0.0;
  for (const double z : surface.map().data()) largest = std::max(largest, std::abs(z));
  const double reach = off.detector.range * (1.0 - 1e-9) - largest;  // B(r) >= R_d (1 − 1e-9) needs r tan ψ >= reach
  const double slope = surface.tilt().slope();
  const std::int64_t total = s.samples();
  std::int64_t critical = 0;  // first sample that may saturate
  if (reach > 0.0) {
    if (!(slope > 0.0) || reach / slope > s.end_radius) {  // |y| < R_d throughout: nothing to simulate
      UncontrolledSaturation none;
      none.radius = s.end_radius;
      none.first_sample = total;
      return none;
    }
    const double radius = reach / slope;
    critical = radius > s.start_radius
                   ? static_cast<std::int64_t>(std::floor((radius - s.start_radius) / s.radial_speed * s.sample_rate))
                   : 0;  // r_n = r0 + v_r n h: samples before `critical` have r_n < radius (one sample of slack)
    critical = std::max<std::int64_t>(critical - 1, 0);
  }
  const double gamma_h = off.plant.bandwidth / s.sample_rate;
  const auto settle = static_cast<std::int64_t>(std::ceil(45.0 / gamma_h));  // e^{−γ h W} <= e^{−45}
  std::int64_t first = std::max<std::int64_t>(critical - settle, 0);
  first -= first % 4096;
  if (first >= total) first = 0;  // (not reached: critical < total here)
  return run_uncontrolled_from(off, surface, first, cancellation);
}

}  // namespace afmkit::scan
