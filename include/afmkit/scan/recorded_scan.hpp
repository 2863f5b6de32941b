#pragma once
// A recorded rotational scan filtered offline (docs/scan.md#recorded-data): the samples of a recorded spiral (CSV,
// recorded_spiral.hpp) go through the same control::RealtimeFilter an instrument embeds (the object behind the C
// API), closed around a virtual static plant so that it removes the first harmonic and keeps the others:
//   u_n = filter.step(m_n),   m_n = d_n + u_{n−1} / K      (the tilt-free signal; u_{−1} = 0)
// d_n the recorded deflection. With the plant y = f + u/K (seed-2 eq. 3 with γ = K, delay one sample) the loop is
// the one the couplings (20) are designed for, and m_n does not depend on K. The signal and the tilt-free signal
// are imaged onto a Cartesian grid (spiral_imager.hpp), and the first harmonic of each turn is measured.
#include <cstdint>
#include <functional>
#include <string>

#include "afmkit/scan/height_map.hpp"
#include "afmkit/scan/spiral_scan.hpp"
#include "afmkit/scan/turn_metrics.hpp"

namespace afmkit::scan {

/// The controller (eqs. 15, 20): N oscillators, couplings α, β in units of Ω (Ω measured from the file).
struct RecordedFilterSpec {
  int harmonics = 10;
  double alpha = 0.1;
  double beta = -0.1;
};

/// What a first pass over the file finds (every row checked).
struct RecordedSurvey {
  std::int64_t samples = 0;
  long dropped_samples = 0;       ///< index-pulse files: samples before the first / after the last pulse
  double sample_rate = 0.0;       ///< f_s [Hz]
  double rotation_frequency = 0.0;///< Ω [rad/s] (first revolution)
  double max_radius = 0.0;        ///< [m]
  /// largest radial spread of one turn [m]: max − min of the radius over a turn's samples and the first sample of
  /// the next turn, over every turn (the partial first and last ones too): the pitch of a regular spiral
  double max_pitch = 0.0;
  std::int64_t max_pitch_turn = -1;  ///< the turn k (angle in [2πk, 2π(k+1))) where max_pitch was found
  double max_pitch_time = 0.0;       ///< the time of that turn's first sample [s]
  std::int64_t turns = 0;         ///< complete turns
  bool uses_index_pulse = false;
};
RecordedSurvey survey_recorded(const std::string& path);

/// The square grid of `resolution`² pixels centred on the spindle axis covering [−r_max, r_max]²; InvalidParameter
/// "image_resolution" when the pitch exceeds the pixel size (turns would not overlap), naming the largest allowed.
Grid recorded_image_grid(const RecordedSurvey& survey, long resolution);

struct RecordedScanOptions {
  ScanObserver* extra = nullptr;  ///< every sample: deflection = recorded d, control = u, topography = tilt-free m
  std::function<void(const TurnRecord&)> on_turn;  ///< deflection_first_harmonic = tilt-free, surface_… = recorded
  std::function<void(std::int64_t, std::int64_t)> progress;
  Cancellation cancellation;  ///< checked every 65536 samples (core/cancellation.hpp)
};

struct RecordedScan {
  RecordedSurvey survey;
  HeightMap deflection;  ///< image of the recorded deflection [m]
  HeightMap tilt_free;   ///< image of the tilt-free signal [m]
  std::int64_t turns = 0;
  std::uint64_t filter_skipped = 0;
};

/// Filters and images the recorded spiral at `path` (read twice: survey, then filter).
RecordedScan filter_recorded_scan(const std::string& path, const RecordedFilterSpec& filter, long image_resolution,
                                  const RecordedScanOptions& options = {});
/// The same with the survey already made (survey_recorded(path)) and the grid chosen (recorded_image_grid), so a
/// caller can refuse bad input before it opens any output. InvalidParameter ("harmonics", "sample_rate") when the
/// filter cannot run at the file's rates.
RecordedScan filter_recorded_scan(const std::string& path, const RecordedSurvey& survey, const Grid& grid,
                                  const RecordedFilterSpec& filter, const RecordedScanOptions& options = {});
/// The real-time filter for the file's rates (validated as above).
void check_recorded_filter(const RecordedSurvey& survey, const RecordedFilterSpec& filter);

}  // namespace afmkit::scan
