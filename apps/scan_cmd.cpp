// afmkit scan: the virtual rotational-scanning AFM (docs/scan.md, docs/commands.md#scan). A tilted sample spins
// under the tip, which follows a spiral; the seed-2 controller (through the real-time filter) removes the tilt's
// first harmonic from the deflection. Writes the per-turn metrics (CSV), the images (GSF + mask, PNG preview) and,
// on request, the time series (CSV) and the raw point cloud (GXYZF). With `recorded`, a recorded spiral (CSV) is
// filtered offline instead (scan_recorded.cpp).
#include <cmath>
#include <future>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/settings.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/scan/virtual_scan.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "scan_outputs.hpp"
#include "scan_params.hpp"
#include "scan_recorded.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

std::vector<io::Column> turn_columns() {
  return {{"turn", "count", "turn k (spindle angle in [2 pi k, 2 pi (k+1)))"},
          {"radius", "m", "mean radius over the turn"},
          {"deflection_first_harmonic", "m", "amplitude of the deflection's first harmonic (residual tilt)"},
          {"surface_first_harmonic", "m", "amplitude of the first harmonic of the true height (topography + tilt)"},
          {"tilt_first_harmonic", "m", "tilt amplitude radius x tan(tilt_angle)"},
          {"samples", "count", "samples in the turn"},
          {"saturated_samples", "count", "samples of the turn with the detector saturated"}};
}

// Spectral abscissa of the continuous-time loop at the nominal delay [rad/s] (NaN when it cannot be certified).
double loop_spectral_abscissa(const scan::InstrumentSpec& s) {
  if (!s.controller.enabled) return std::numeric_limits<double>::quiet_NaN();
  control::ControlSettings c;
  const double omega = s.spiral.rotation_frequency();
  c.rotation_frequency = omega;
  c.harmonics = s.controller.harmonics;
  c.alpha = s.controller.alpha;
  c.beta = s.controller.beta;
  c.gain = s.controller_gain() / omega;
  c.plant = control::PlantKind::FirstOrder;
  c.plant_rate = s.plant.bandwidth / omega;
  c.delay = s.plant.delay / (2.0 * std::numbers::pi / omega);
  try {
    return control::spectral_abscissa(control::loop_from(c));
  } catch (const NumericalFailure&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

void run_simulated(const io::ParamSet& p, Captured* capture) {
  const scan::InstrumentSpec instrument = instrument_from(p);
  require_scan_memory(p, false);  // before the sample map and the images are allocated
  const scan::Grid grid = scan::image_grid(instrument, p.integer("image_resolution"));
  std::optional<scan::Surface> surface;
  std::optional<scan::SpiralImager> imager;
  if (p.text("sample") == "file") {
    // a sample file is read and checked first, its geometry too: a bad file is reported before the imager is built
    // (25 ms at 512² pixels, seconds at 16384²)
    surface.emplace(surface_from(p));
    scan::check_scan_geometry(instrument, *surface, grid);
    imager.emplace(scan::scan_imager(instrument, grid));
  } else {
    // a generated sample is made on a second thread while this one builds the imager (its pixel centres sorted by
    // radius); the imager's tables stay in this thread's heap, where the images and the files are made after the scan
    std::future<scan::Surface> sample = std::async(std::launch::async, [&p] { return surface_from(p); });
    try {
      imager.emplace(scan::scan_imager(instrument, grid));
    } catch (...) {
      sample.wait();  // the thread reads p: let it finish before the error unwinds
      throw;
    }
    surface.emplace(sample.get());
    scan::check_scan_geometry(instrument, *surface, grid);
  }
  const std::int64_t total = instrument.spiral.samples();
  const std::string series_path = p.text("series_output"), points_path = p.text("points_output"), prefix = p.text("image_output");
  const long series_every = p.integer("series_every"), points_every = p.integer("points_every");
  const auto expected_points = static_cast<double>(total / points_every + 1);
  if (!points_path.empty()) memory::require_fits("points_every", expected_points, 4.0 * sizeof(double));
  const double abscissa = loop_spectral_abscissa(instrument);
  if (abscissa >= 0.0)
    io::message_line(fmt::format("afmkit scan: warning: the loop is unstable at the nominal delay (spectral abscissa "
                                 "{:.4g} rad/s >= 0; see `afmkit control chart`)", abscissa));

  // the record says what the run used: a generated sample's side when sample_size was left at 0 (2.04 x end_radius)
  io::ParamSet as_run = p;
  if (p.text("sample") != "file" && !p.was_set("sample_size"))
    as_run.record_used("sample_size", generated_sample_size(p));
  CommandOutput out(as_run, capture, "scan");
  out.open(turn_columns());
  std::optional<SeriesWriter> series;
  if (!series_path.empty()) series.emplace(series_path, series_every, false);
  std::optional<PointCloud> points;
  if (!points_path.empty())
    points.emplace(points_every, false, static_cast<std::size_t>(expected_points),
                   instrument.reconstruction.method == scan::Reconstruction::inverse);
  std::vector<scan::ScanObserver*> extra;
  if (series) extra.push_back(&*series);
  if (points) extra.push_back(&*points);
  scan::ObserverChain chain(extra);

  io::Progress progress("scan", total, true, 1.0);
  std::int64_t reported = 0;
  scan::VirtualScanOptions options;
  options.extra = &chain;
  options.on_turn = [&](const scan::TurnRecord& r) {
    out.row(r.turn, r.radius, r.deflection_first_harmonic, r.surface_first_harmonic, r.tilt_first_harmonic,
            r.samples, r.saturated_samples);
  };
  options.progress = [&](std::int64_t done, std::int64_t) {
    progress.advance(static_cast<long>(done - reported));
    reported = done;
  };
  options.compare_without_control = instrument.controller.enabled;
  options.imager = &*imager;
  options.cancellation = cancellation_of(capture);
  const scan::VirtualScan result = scan::run_virtual_scan(instrument, *surface, grid, options);
  imager.reset();  // the spent imager and the sample map are not needed for the files: their memory goes first
  surface.reset();
  progress.finish();

  const bool inverse = result.method == scan::Reconstruction::inverse;
  if (inverse && result.inverse_rms_error > result.lagged_rms_error)
    fmt::print(stderr, "afmkit scan: warning: the lagged reconstruction is closer to the truth in this run ({} against "
                       "{} for the inverse, whose image noise gain {:.4g} turns detector_noise into {}): see "
                       "--reconstruction lagged{} (docs/scan.md#reconstruction)\n",
               io::quantity(result.lagged_rms_error, "m"), io::quantity(result.inverse_rms_error, "m"),
               result.budget.image_noise_gain, io::quantity(result.budget.noise, "m"),
               !result.budget.wiener && instrument.detector.noise > 0.0 ? " or --inverse wiener" : "");
  const std::string method = inverse ? "inverse" : "lagged", other = inverse ? "lagged" : "inverse";
  const scan::ErrorBudget& budget = result.budget;
  // errors relative to the sample's RMS height; a truth that levels to a plane (sample = flat: rounding, ~1e-19 m)
  // has none (null in the sidecar)
  const bool flat_truth = !(result.sample_rms_height > 1e-15);
  const auto relative = [&](double error) {
    return flat_truth ? std::numeric_limits<double>::quiet_NaN() : error / result.sample_rms_height;
  };
  std::vector<std::string> files;
  if (!prefix.empty())
    files = stage_images(prefix, {{"deflection", "Deflection", &result.deflection, false},
                                  {"topography", fmt::format("Topography (reconstructed, {})", method), &result.topography,
                                   true},
                                  {"topography_" + other, fmt::format("Topography (reconstructed, {})", other),
                                   &result.alternative, true},
                                  {"truth", "Ground truth (topography + tilt)", &result.truth, true}},
                         out.outputs());
  std::size_t n_points = 0;
  if (points) {
    n_points = points->stage(points_path, out.outputs());
    files.push_back(points_path);
  }
  // SI results (m, 1/s), each with its unit; the error budget's terms under error_budget (docs/scan.md)
  UnitTagged error_budget;
  error_budget.add("imaging", budget.imaging, "m")
      .add("imaging_relative", relative(budget.imaging), "dimensionless")
      .add("reconstruction", budget.reconstruction, "m")
      .add("reconstruction_relative", relative(budget.reconstruction), "dimensionless")
      .add("plant_mismatch", budget.plant_mismatch, "dimensionless")
      .add("plant", budget.plant, "m")
      .add("noise_gain", budget.noise_gain, "dimensionless")
      .add("image_noise_gain", budget.image_noise_gain, "dimensionless")
      .add("noise", budget.noise, "m")
      .add("inverse", nlohmann::json(budget.wiener ? "wiener" : "exact"))
      .add("exact_image_noise_gain", budget.exact_image_noise_gain, "dimensionless")
      .add("prior_increment", budget.prior_increment, "m")
      .add("cutoff", budget.cutoff, "Hz")
      .add("filter_taps", budget.filter_taps, "count")
      .add("resolution", budget.resolution, "m")
      .add("resolution_prior", budget.resolution_prior, "m")
      .add("predicted", budget.predicted, "m")
      .add("pole", budget.pole, "dimensionless")
      .add("settle_samples", budget.settle_samples, "count");
  // No answer (docs/commands.md#exit-status): fewer than three valid pixels leave no image to level or compare
  const long valid_pixels = static_cast<long>(result.topography.valid_count());
  const bool no_image = valid_pixels < 3;
  const std::string note =
      no_image ? fmt::format("{} valid pixel(s): the detector saturated on {:.3g} % of the samples (detector_range "
                             "{}, detector_noise {}), so the images carry no height and every error is null",
                             valid_pixels, 100.0 * result.saturated_fraction,
                             io::quantity(instrument.detector.range, "m"), io::quantity(instrument.detector.noise, "m"))
               : std::string();
  UnitTagged tagged;
  tagged.add("status", no_image ? "no_image" : "ok").add("note", note);
  tagged.add("samples", result.run.samples, "count")
      .add("turns", result.turns, "count")
      .add("pitch", instrument.spiral.pitch(), "m")
      .add("saturated_fraction", result.saturated_fraction, "dimensionless")
      .add("saturates_with_control", result.saturates_with_control, "boolean (0/1)")
      .add("max_radius_with_control", result.max_radius_with_control, "m")
      .add("saturates_without_control", result.saturates_without_control, "boolean (0/1)")
      .add("max_radius_without_control", result.max_radius_without_control, "m")
      .add("scan_area_gain", result.scan_area_gain, "dimensionless")
      .add("scan_area_gain_is_lower_bound", result.scan_area_gain_is_lower_bound, "boolean (0/1)")
      .add("reconstruction", method)
      .add("topography_rms_error", result.topography_rms_error, "m")
      .add("topography_relative_error", relative(result.topography_rms_error), "dimensionless")
      .add("inverse_rms_error", result.inverse_rms_error, "m")
      .add("lagged_rms_error", result.lagged_rms_error, "m")
      .add("sample_rms_height", result.sample_rms_height, "m")
      .add("error_budget", std::move(error_budget))
      .add("deflection_rms", result.deflection_rms, "m")
      .add("valid_pixels", valid_pixels, "count")
      .add("loop_spectral_abscissa", abscissa, "1/s")
      .add("filter_skipped_samples", result.run.filter_skipped, "count")
      .add("point_cloud_points", n_points, "count")
      .add("files", files);
  const nlohmann::json results = std::move(tagged).summary();
  if (series) series->stage(io::make_sidecar("scan (time series)", as_run, results), out.outputs());
  const std::string gain =
      std::isnan(result.scan_area_gain)
          ? std::string("nan (the uncontrolled scan does not saturate)")
          : fmt::format("{}{:.3f}", result.scan_area_gain_is_lower_bound ? ">= " : "", result.scan_area_gain);
  const auto percent = [&](double error) {
    return flat_truth ? std::string("flat truth") : fmt::format("{:.3g} %", 100.0 * relative(error));
  };
  const std::string summary = fmt::format(
      "afmkit scan: {} samples, {} turns, controller {}; saturated {:.3g} % of samples; largest radius before the "
      "detector saturates {} in this run{}, {} with the controller off; scan-area gain {}; topography RMS "
      "error {} (levelled; {} reconstruction; {}; {} reconstruction: {}); error "
      "budget of the inverse: imaging {} ({} against the real truth: the sampling's floor), reconstruction {} ({} "
      "against the truth imaged through the same sampling), plant knowledge {} (assumed rate {:+.3g} %), "
      "noise {} (gain {:.4g} at the samples, {:.4g} in the image{}), predicted {}{}",
      result.run.samples, result.turns, instrument.controller.enabled ? "on" : "off",
      100.0 * result.saturated_fraction, io::quantity(result.max_radius_with_control, "m"),
      result.saturates_with_control ? "" : " (never saturated)",
      !instrument.controller.enabled ? std::string("(this run)") : io::quantity(result.max_radius_without_control, "m"),
      gain, io::quantity(result.topography_rms_error, "m"), method,
      flat_truth ? std::string("no relative error: the levelled truth is flat")
                 : fmt::format("{} of the sample's RMS height {}", percent(result.topography_rms_error),
                               io::quantity(result.sample_rms_height, "m")),
      other, io::quantity(inverse ? result.lagged_rms_error : result.inverse_rms_error, "m"),
      io::quantity(budget.imaging, "m"), percent(budget.imaging), io::quantity(budget.reconstruction, "m"),
      percent(budget.reconstruction),
      io::quantity(budget.plant, "m"), 100.0 * budget.plant_mismatch,
      io::quantity(budget.noise, "m"), budget.noise_gain, budget.image_noise_gain,
      budget.wiener ? fmt::format("; Wiener low-pass: cutoff {}, {} taps, exact inverse's image gain {:.4g}; "
                                  "resolution {}", io::quantity(budget.cutoff, "Hz"), budget.filter_taps,
                                  budget.exact_image_noise_gain, io::quantity(budget.resolution, "m"))
                    : std::string(),
      io::quantity(budget.predicted, "m"),
      files.empty() ? std::string() : fmt::format("; wrote {} files with prefix {}", files.size(), prefix));
  out.finish(results, no_image ? summary + "; status no_image: " + note : summary);
}

void run_scan(const io::ParamSet& p, Captured* capture) {
  if (!p.text("recorded").empty()) {
    for (const std::string& key : simulation_only_keys())
      if (p.was_set(key))
        throw InvalidParameter(key, fmt::format("{} describes the simulated instrument: it cannot be given with "
                                                "recorded = {} (the recorded file is the scan)", key,
                                                p.text("recorded")));
    run_recorded(p, capture);
    return;
  }
  run_simulated(p, capture);
}

}  // namespace

void register_scan(CLI::App& app) {
  add_command(
      app, "scan",
      "virtual rotational-scanning AFM: a tilted sample scanned along a spiral with the seed-2 controller in the "
      "loop; images (GSF, PNG), point cloud (GXYZF), per-turn metrics and the scan-area gain; or a recorded spiral "
      "filtered offline (recorded = FILE)",
      [](io::ParamSet& p) {
        add_scan_params(p);
        p.group("Recorded data")
            .file("recorded", "", "recorded spiral CSV (time, radius, deflection, angle or index) to filter offline "
                                  "instead of simulating (docs/scan.md#recorded-data)");
        record_only_what_applies(p);
        p.group("Images and files")
            .integer("image_resolution", 512, "pixels per side of the images (square, covering the scanned disc)", 2,
                     16384)
            .file("image_output", "out/scan/scan", "prefix of the image files <prefix>_<channel>.gsf/.png (empty: none)")
            .writes(image_paths)
            .file("series_output", "", "time-series CSV (empty: none)")
            .writes(io::table_and_sidecar)
            .integer("series_every", 1, "write every n-th sample to the series", 1, 1000000000)
            .file("points_output", "", "raw spiral point cloud, GXYZF (empty: none)")
            .writes()
            .integer("points_every", 10, "keep every n-th sample in the point cloud", 1, 1000000000);
        add_output_params(p, "out/scan/turns.csv", "per-turn metrics (residual first harmonic against radius)");
      },
      run_scan);
}

}  // namespace afmkit::cli
