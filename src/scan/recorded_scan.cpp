// A recorded rotational scan filtered offline through the real-time filter (recorded_scan.hpp).
#include "afmkit/scan/recorded_scan.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/numbers.hpp"
#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/scan/recorded_spiral.hpp"
#include "afmkit/scan/spiral_imager.hpp"

namespace afmkit::scan {

namespace {
using afmkit::numbers::two_pi;

// Turn metrics on the tilt-free signal, with the recorded one as the reference column.
class SwappedMetrics final : public ScanObserver {
 public:
  explicit SwappedMetrics(TurnMetrics& metrics) : metrics_(metrics) {}
  bool sample(const ScanSample& s) override {
    ScanSample t = s;
    t.deflection = s.topography;
    t.surface = s.deflection;
    return metrics_.sample(t);
  }

 private:
  TurnMetrics& metrics_;
};
}  // namespace

RecordedSurvey survey_recorded(const std::string& path) {
  RecordedSpiralReader reader(path);
  RecordedSurvey s;
  s.sample_rate = reader.sample_rate();
  s.rotation_frequency = reader.rotation_frequency();
  s.uses_index_pulse = reader.uses_index_pulse();
  // The radial spread of every turn — its samples and the first sample of the next turn, the partial first and
  // last turns included — bounds how far apart neighbouring turns can be: a radius outlier anywhere shows here.
  SpiralSample sample{};
  std::int64_t turn = -1;
  double turn_min = 0.0, turn_max = 0.0, turn_time = 0.0;
  auto close_turn = [&] {
    if (turn_max - turn_min > s.max_pitch) {
      s.max_pitch = turn_max - turn_min;
      s.max_pitch_turn = turn;
      s.max_pitch_time = turn_time;
    }
  };
  while (reader.next(sample)) {
    ++s.samples;
    s.max_radius = std::max(s.max_radius, sample.radius);
    const auto k = static_cast<std::int64_t>(std::floor(sample.angle / two_pi));
    if (s.samples == 1 || k != turn) {
      if (s.samples > 1) {
        turn_min = std::min(turn_min, sample.radius);  // the turn ends where the next one starts
        turn_max = std::max(turn_max, sample.radius);
        close_turn();
        ++s.turns;
      }
      turn = k;
      turn_min = turn_max = sample.radius;
      turn_time = sample.time;
    } else {
      turn_min = std::min(turn_min, sample.radius);
      turn_max = std::max(turn_max, sample.radius);
    }
  }
  if (s.samples > 0) close_turn();  // the last, partial, turn
  s.dropped_samples = reader.dropped_samples();
  return s;
}

Grid recorded_image_grid(const RecordedSurvey& survey, long resolution) {
  if (resolution < 2 || resolution > 16384)
    throw InvalidParameter("image_resolution",
                           fmt::format("image_resolution = {} is out of range: must be an integer in [2, 16384]",
                                       resolution));
  const double r = survey.max_radius > 0.0 ? survey.max_radius : 1e-9;
  const double pixel = 2.0 * r / static_cast<double>(resolution);
  if (survey.max_pitch > pixel) {
    const auto largest = static_cast<long>(std::floor(2.0 * r / survey.max_pitch));
    throw InvalidParameter(
        "image_resolution",
        fmt::format("image_resolution = {} is out of range: the recorded spiral advances up to {} m per turn (its "
                    "radius spans that much in the turn starting at t = {} s, a radius outlier or a gap in the "
                    "recording), more than the pixel {} m, so neighbouring turns would not overlap; must be <= {}",
                    resolution, survey.max_pitch, survey.max_pitch_time, pixel, std::max(largest, 1L)));
  }
  return Grid{resolution, resolution, 2.0 * r, 2.0 * r, -r, -r};
}

namespace {
constexpr double kGain = 1.0;  // K: the tilt-free signal does not depend on it (see the header)

control::RealtimeFilter filter_for(const RecordedSurvey& survey, const RecordedFilterSpec& spec) {
  const double omega = survey.rotation_frequency;
  if (spec.harmonics < 1 || !(spec.harmonics * omega < std::numbers::pi * survey.sample_rate))
    throw InvalidParameter("harmonics",
                           fmt::format("harmonics = {} is out of range: harmonic N at N x {:.6g} Hz (the recorded "
                                       "spindle) must lie below the Nyquist frequency {:.6g} Hz of the recording; must "
                                       "be an integer in [1, {}]", spec.harmonics, omega / two_pi,
                                       0.5 * survey.sample_rate,
                                       static_cast<long>(std::ceil(std::numbers::pi * survey.sample_rate / omega)) - 1));
  return control::RealtimeFilter::with_couplings(survey.sample_rate, omega, spec.harmonics, spec.alpha * omega,
                                                 spec.beta * omega, kGain);
}
}  // namespace

void check_recorded_filter(const RecordedSurvey& survey, const RecordedFilterSpec& spec) {
  (void)filter_for(survey, spec);
}

RecordedScan filter_recorded_scan(const std::string& path, const RecordedFilterSpec& spec, long image_resolution,
                                  const RecordedScanOptions& options) {
  const RecordedSurvey survey = survey_recorded(path);
  return filter_recorded_scan(path, survey, recorded_image_grid(survey, image_resolution), spec, options);
}

RecordedScan filter_recorded_scan(const std::string& path, const RecordedSurvey& survey, const Grid& grid,
                                  const RecordedFilterSpec& spec, const RecordedScanOptions& options) {
  const double omega = survey.rotation_frequency;
  control::RealtimeFilter filter = filter_for(survey, spec);

  const auto per_turn = static_cast<int>(std::clamp(std::round(two_pi * survey.sample_rate / omega), 16.0, 4194304.0));
  SpiralImager imager(grid, {"m", "m"}, per_turn);
  std::int64_t turns = 0;
  TurnMetrics metrics(0.0, [&](const TurnRecord& r) {
    ++turns;
    if (options.on_turn) options.on_turn(r);
  });
  SwappedMetrics swapped(metrics);

  RecordedSpiralReader reader(path);
  SpiralSample in{};
  double previous_u = 0.0;
  std::int64_t n = 0;
  while (reader.next(in)) {
    const double m = in.deflection + previous_u / kGain;
    const double u = filter.step(m);
    previous_u = u;
    const ScanSample s{n, in.time, in.angle, in.radius, in.deflection, in.deflection, u, m - in.deflection, m, m,
                       false};
    const double values[2] = {in.deflection, m};
    imager.add(in.angle, in.radius, values);
    swapped.sample(s);
    if (options.extra) options.extra->sample(s);
    ++n;
    if ((n & 65535) == 0) {
      options.cancellation.check();
      if (options.progress) options.progress(n, survey.samples);
    }
  }
  if (options.progress) options.progress(n, survey.samples);
  std::vector<HeightMap> images = imager.finish();
  RecordedScan out{survey, std::move(images.at(0)), std::move(images.at(1)), turns, filter.skipped_samples()};
  return out;
}

}  // namespace afmkit::scan
