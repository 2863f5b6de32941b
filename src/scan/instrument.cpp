// The virtual rotational-scanning AFM's parameters and their checks (instrument.hpp).
#include "afmkit/scan/instrument.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::scan {

namespace v = afmkit::validate;

double SpiralSpec::rotation_frequency() const { return 2.0 * std::numbers::pi * spindle_frequency; }
double SpiralSpec::pitch() const { return radial_speed / spindle_frequency; }
double SpiralSpec::duration() const { return (end_radius - start_radius) / radial_speed; }
double SpiralSpec::samples_per_turn() const { return sample_rate / spindle_frequency; }
std::int64_t SpiralSpec::samples() const {
  return static_cast<std::int64_t>(std::floor(duration() * sample_rate)) + 1;
}

void SpiralSpec::validate() const {
  v::positive("spindle_frequency", spindle_frequency);
  v::non_negative("start_radius", start_radius);
  v::finite("end_radius", end_radius);
  v::require(end_radius > start_radius, "end_radius", end_radius,
             fmt::format("> start_radius = {} m", start_radius));
  v::positive("radial_speed", radial_speed);
  v::positive("sample_rate", sample_rate);
  v::require(samples_per_turn() >= 16.0, "sample_rate", sample_rate,
             fmt::format(">= 16 samples per turn = {} Hz (16 x spindle_frequency)", 16.0 * spindle_frequency));
  const double n = duration() * sample_rate;
  if (!(n <= 1e10))
    throw InvalidParameter("radial_speed",
                           fmt::format("the scan from {} m to {} m at radial_speed = {} m/s and sample_rate = {} Hz "
                                       "takes {:.3g} samples: must be at most 1e10 (raise radial_speed or lower "
                                       "sample_rate)", start_radius, end_radius, radial_speed, sample_rate, n));
}

void PlantSpec::validate(const SpiralSpec& spiral) const {
  v::positive("bandwidth", bandwidth);
  v::non_negative("delay", delay);
  const double period = 1.0 / spiral.spindle_frequency;
  v::require(delay + delay_drift < period, "delay", delay,
             fmt::format("< one spindle period minus delay_drift = {} s (the seed-2 loop assumes tau < T = {} s)",
                         period - delay_drift, period));
  v::in_range("delay_drift", delay_drift, 0.0, delay);
  v::positive("delay_drift_period", delay_drift_period);
  v::finite("gain_error", gain_error);
  v::require(gain_error > -1.0, "gain_error", gain_error, "> -1 (actuator sensitivity (1 + gain_error) > 0)");
}

void DetectorSpec::validate() const {
  v::positive("detector_range", range);
  v::non_negative("detector_noise", noise);
}

void ControllerSpec::validate() const {
  v::in_range("harmonics", static_cast<long>(harmonics), 1L, 10000L);
  v::finite("alpha", alpha);
  v::finite("beta", beta);
  v::non_negative("gain", gain);
}

void InstrumentSpec::validate() const {
  spiral.validate();
  plant.validate(spiral);
  detector.validate();
  controller.validate();
  reconstruction.validate();
  // the assumed plant rate is an estimate of the true one (docs/scan.md#reconstruction), and the inverse needs
  // γ̂/f_s >= 1e-6: below, its noise gain (≈ 4.9 (γ̂/f_s)^−3/2, 5e9 there) leaves nothing of the height
  const double assumed = assumed_bandwidth();
  if (reconstruction.assumed_bandwidth > 0.0 &&
      !(assumed >= 0.01 * plant.bandwidth && assumed <= 100.0 * plant.bandwidth))
    throw InvalidParameter("reconstruction_bandwidth",
                           fmt::format("reconstruction_bandwidth = {} rad/s is out of range: the plant rate the "
                                       "reconstruction assumes must lie within a factor 100 of bandwidth = {} rad/s: "
                                       "[{}, {}] rad/s (0: the true bandwidth)",
                                       assumed, plant.bandwidth, 0.01 * plant.bandwidth, 100.0 * plant.bandwidth));
  if (!(assumed >= 1e-6 * spiral.sample_rate))
    throw InvalidParameter(reconstruction.assumed_bandwidth > 0.0 ? "reconstruction_bandwidth" : "bandwidth",
                           fmt::format("{} = {} rad/s is out of range: the inverse reconstruction needs the plant rate "
                                       ">= 1e-6 x sample_rate = {:.6g} rad/s (below, its noise gain exceeds 5e9)",
                                       reconstruction.assumed_bandwidth > 0.0 ? "reconstruction_bandwidth"
                                                                              : "bandwidth",
                                       assumed, 1e-6 * spiral.sample_rate));
  if (controller.enabled) {
    const double top = controller.harmonics * spiral.spindle_frequency;
    if (!(top < 0.5 * spiral.sample_rate))
      throw InvalidParameter("harmonics",
                             fmt::format("harmonics = {} is out of range: harmonic N at N x {} Hz = {} Hz must lie "
                                         "below the Nyquist frequency sample_rate/2 = {} Hz", controller.harmonics,
                                         spiral.spindle_frequency, top, 0.5 * spiral.sample_rate));
  }
}

double InstrumentSpec::assumed_bandwidth() const {
  return reconstruction.assumed_bandwidth > 0.0 ? reconstruction.assumed_bandwidth : plant.bandwidth;
}

double InstrumentSpec::controller_gain() const { return controller.gain > 0.0 ? controller.gain : plant.bandwidth; }

}  // namespace afmkit::scan
