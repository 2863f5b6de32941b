// afmkit scan recorded = FILE: the recorded spiral through the real-time filter, offline (scan_recorded.hpp).
#include "scan_recorded.hpp"

#include <cmath>
#include <numbers>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/io/progress.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/scan/recorded_scan.hpp"
#include "command.hpp"
#include "scan_outputs.hpp"
#include "scan_params.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

void run_recorded(const io::ParamSet& p, Captured* capture) {
  const std::string path = p.text("recorded"), prefix = p.text("image_output"), series_path = p.text("series_output"),
                    points_path = p.text("points_output");
  scan::RecordedFilterSpec spec;
  spec.harmonics = static_cast<int>(p.integer("harmonics"));
  spec.alpha = p.real("alpha");
  spec.beta = p.real("beta");

  require_scan_memory(p, true);  // the images, before the file is read
  // every row of the file is checked (and the grid and filter chosen) before any output is opened
  const scan::RecordedSurvey survey = scan::survey_recorded(path);
  const scan::Grid grid = scan::recorded_image_grid(survey, p.integer("image_resolution"));
  scan::check_recorded_filter(survey, spec);

  CommandOutput out(p, capture, "scan (recorded)");
  out.open({{"turn", "count", "turn k (spindle angle in [2 pi k, 2 pi (k+1)))"},
            {"radius", "m", "mean radius over the turn"},
            {"tilt_free_first_harmonic", "m", "amplitude of the first harmonic of the tilt-free signal"},
            {"recorded_first_harmonic", "m", "amplitude of the first harmonic of the recorded deflection"},
            {"samples", "count", "samples in the turn"}});
  std::optional<SeriesWriter> series;
  if (!series_path.empty()) series.emplace(series_path, p.integer("series_every"), true);
  std::optional<PointCloud> points;
  if (!points_path.empty()) points.emplace(p.integer("points_every"), true, 0);
  std::vector<scan::ScanObserver*> extra;
  if (series) extra.push_back(&*series);
  if (points) extra.push_back(&*points);
  scan::ObserverChain chain(extra);

  std::optional<io::Progress> progress;
  std::int64_t reported = 0;
  scan::RecordedScanOptions options;
  options.extra = &chain;
  options.cancellation = cancellation_of(capture);
  options.on_turn = [&](const scan::TurnRecord& r) {
    out.row(r.turn, r.radius, r.deflection_first_harmonic, r.surface_first_harmonic, r.samples);
  };
  options.progress = [&](std::int64_t done, std::int64_t total) {
    if (!progress) progress.emplace("scan (recorded)", static_cast<long>(total), true, 1.0);
    progress->advance(static_cast<long>(done - reported));
    reported = done;
  };
  const scan::RecordedScan result = scan::filter_recorded_scan(path, survey, grid, spec, options);
  if (progress) progress->finish();

  std::vector<std::string> files;
  if (!prefix.empty())
    files = stage_images(prefix, {{"deflection", "Deflection (recorded)", &result.deflection},
                                  {"tilt_free", "Deflection, first harmonic removed", &result.tilt_free}},
                         out.outputs());
  std::size_t n_points = 0;
  if (points) {
    n_points = points->stage(points_path, out.outputs());
    files.push_back(points_path);
  }
  const scan::RecordedSurvey& s = result.survey;
  UnitTagged tagged;  // SI results, each with its unit
  tagged.add("samples", s.samples, "count")
      .add("turns", result.turns, "count")
      .add("dropped_samples", s.dropped_samples, "count")
      .add("sample_rate", s.sample_rate, "Hz")
      .add("spindle_frequency", s.rotation_frequency / (2.0 * std::numbers::pi), "Hz")
      .add("max_radius", s.max_radius, "m")
      .add("max_pitch", s.max_pitch, "m")
      .add("uses_index_pulse", s.uses_index_pulse, "boolean (0/1)")
      .add("valid_pixels", result.tilt_free.valid_count(), "count")
      .add("filter_skipped_samples", result.filter_skipped, "count")
      .add("point_cloud_points", n_points, "count")
      .add("files", files);
  const nlohmann::json results = std::move(tagged).summary();
  if (series) series->stage(io::make_sidecar("scan (recorded, time series)", p, results), out.outputs());
  out.finish(results, fmt::format("afmkit scan (recorded {}): {} samples, {} turns at {} spindle, {} sampling, "
                                  "radius up to {}; {} samples dropped outside the index pulses{}",
                                  path, s.samples, result.turns,
                                  io::quantity(s.rotation_frequency / (2.0 * std::numbers::pi), "Hz", 6),
                                  io::quantity(s.sample_rate, "Hz", 6), io::quantity(s.max_radius, "m"),
                                  s.dropped_samples,
                                  files.empty() ? std::string()
                                                : fmt::format("; wrote {} files with prefix {}", files.size(), prefix)));
}

}  // namespace afmkit::cli
