// afmkit tapping image: the virtual tapping-mode AFM — amplitude-modulation imaging with Z feedback
// (docs/commands.md#afmkit-tapping-image, docs/theory-tapping.md#quasi-static-imaging). A sample topography (the
// samples of `afmkit scan`) is scanned in raster lines, trace and retrace; a PI controller moves the base height Z
// to hold the lock-in amplitude at the set-point. Engines: quasi-static (the steady-state orbit map of the law,
// computed once by an instrument sweep, seen through the cantilever's and the lock-in's lags) or time-domain (the
// cantilever ODE stepped cycle by cycle under the moving tip, a lock-in over whole cycles; engaged on the map).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <memory>
#include <optional>
#include <exception>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/scan/gsf.hpp"
#include "afmkit/scan/levelling.hpp"
#include "afmkit/tapping/image/quasi_static.hpp"
#include "afmkit/tapping/image/time_domain.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "scan_outputs.hpp"
#include "scan_params.hpp"
#include "tapping_params.hpp"
#include "tapping_sim_params.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {
namespace ti = tapping::image;  // (file-local alias)

// the channels written, per direction
constexpr const char* kTappingImageChannels[] = {"height", "error", "phase", "power", "peak_force", "regime"};

std::vector<io::WrittenPath> tapping_image_files(const std::string& prefix) {
  std::vector<io::WrittenPath> paths;
  const auto add = [&](const std::string& name) {
    paths.push_back({prefix + "_" + name + ".gsf"});
    paths.push_back({scan::gsf_mask_path(prefix + "_" + name + ".gsf")});
    paths.push_back({prefix + "_" + name + ".png"});
  };
  for (const char* c : kTappingImageChannels)
    for (const char* d : {"trace", "retrace"}) add(fmt::format("{}_{}", c, d));
  add("truth");
  return paths;
}

// One scan of the set-point sweep (results: setpoint_sweep): SI values (m, N), each with its unit.
UnitTagged setpoint_sweep_record(double setpoint, double engaged_separation, const ti::ImagingMetrics& m,
                                 double apparent_height, double truth_height) {
  UnitTagged r;
  r.add("setpoint", setpoint, "dimensionless")
      .add("engaged_separation", engaged_separation, "m")
      .add("trace_height_rms_error", m.trace_height_rms_error, "m")
      .add("apparent_height", apparent_height, "m")
      .add("truth_height", truth_height, "m")
      .add("fraction_attractive", m.fraction_attractive, "dimensionless")
      .add("fraction_repulsive", m.fraction_repulsive, "dimensionless")
      .add("regime_switches_per_line", m.switches_per_line, "count")
      .add("max_peak_force", m.max_peak_force, "N");
  return r;
}

// A branch of the orbit map that holds the set-point (results: branches_at_setpoint): separation [m], phase [deg],
// peak force [N].
UnitTagged branch_at_setpoint_record(std::size_t branch, double separation, const std::string& regime,
                                     double phase_deg, double peak_force) {
  UnitTagged r;
  r.add("branch", branch, "count")
      .add("separation", separation, "m")
      .add("regime", regime)
      .add("phase", phase_deg, "deg")
      .add("peak_force", peak_force, "N");
  return r;
}

void declare_tapping_image(io::ParamSet& p) {
  add_tapping_model_params(p);
  p.set_default("units", "physical");
  p.set_default("law", "dmt");
  add_tapping_sim_params(p);
  p.set_default("max_transient_periods", "4000");
  add_sample_params(p);
  record_only_sample_keys_that_apply(p);
  // samples of a tapping-mode scan: nanometre features on a micrometre (docs/commands.md#afmkit-tapping-image)
  p.set_default("sample", "particles");
  p.set_default("sample_resolution", "512");
  p.set_default("grating_period", "250e-9");
  p.set_default("grating_height", "5e-9");
  p.set_default("steps_width", "250e-9");
  p.set_default("steps_height", "2e-9");
  p.set_default("particles_count", "12");
  p.set_default("particles_radius", "5e-9");
  p.set_default("rough_rms", "1e-9");
  p.set_default("rough_correlation_length", "50e-9");
  p.set_default("tilt_angle", "0");
  p.group("Raster scan")
      .real("scan_size", 1e-6, "width of the scanned area (fast axis x), centred on the sample", io::Range::positive())
      .unit("m")
      .default_text("the sample file's width (sample = file), else 1e-6")
      .real("scan_height", 0.0, "height of the scanned area (slow axis y; 0: scan_size)", io::Range::non_negative())
      .unit("m")
      .integer("pixels", 128, "pixels per line", 2, 16384)
      .integer("lines", 128, "lines (each scanned trace then retrace)", 2, 16384)
      .real("line_rate", 1.0, "lines per second (trace + retrace): tip speed 2 x scan_size x line_rate",
            io::Range::positive())
      .unit("Hz")
      .real("tip_speed", 0.0, "tip speed along the fast axis (0: from line_rate)", io::Range::non_negative())
      .unit("m/s")
      .group("Amplitude feedback")
      .text("engine", "quasi-static",
            "imaging engine: quasi-static (the steady-state orbit map with the loop's lags) or time-domain (the "
            "cantilever ODE stepped cycle by cycle under the moving tip, demodulated by a lock-in)",
            {"quasi-static", "time-domain"})
      .integer("lockin_cycles", 1, "time-domain engine: drive cycles the lock-in averages (boxcar), at most the "
               "cycles of one pixel", 1, 1000000)
      .real("cycle_tolerance", 1e-8, "time-domain engine: relative tolerance of the cycles' adaptive integrator "
            "(absolute: 1e-2 of it in nm; relative_tolerance stays the orbit map's and the engagement's)",
            io::Range::open(0.0, 1.0))
      .unit("dimensionless")
      .real("setpoint", 0.8, "amplitude set-point A_sp / A0, in (0, 1)", io::Range::any())
      .unit("dimensionless")
      .reals("setpoint_sweep", {}, "more set-points A_sp/A0 imaged with the same orbit map (results: setpoint_sweep)",
             io::Range::any())
      .unit("dimensionless")
      .real("proportional_gain", 0.0, "K_p: Z moves K_p x (A_sp - A) [m per m]", io::Range::any())
      .unit("dimensionless")
      .real("integral_gain", 2000.0, "K_i: Z moves K_i x integral of (A_sp - A) dt", io::Range::any())
      .unit("1/s")
      .real("z_min", -5e-6, "lowest base height Z (piezo range)", io::Range::any())
      .unit("m")
      .real("z_max", 5e-6, "highest base height Z (piezo range)", io::Range::any())
      .unit("m")
      .real("feedback_rate", 50e3, "controller updates per second (at most the drive frequency)",
            io::Range::positive())
      .unit("Hz")
      .real("lockin_bandwidth", 5e3, "-3 dB bandwidth of the lock-in's first-order output filter (< f_drive / 2)",
            io::Range::non_negative())
      .unit("Hz")
      .group("Orbit map (the steady states of the law, computed once; the time-domain engine engages on it)")
      .real("map_separation_min", 0.0, "smallest separation of the map", io::Range::closed(-1e6, 1e6))
      .unit("nm")
      .real("map_separation_max", 0.0, "largest separation of the map (0: 1.25 x free_amplitude)",
            io::Range::closed(-1e6, 1e6))
      .unit("nm")
      .integer("map_points", 200, "separations of the map's approach and retract", 8, 100000)
      .group("Images and files")
      .file("image_output", "out/tapping_image/image",
            "prefix of the images <prefix>_<channel>_<trace|retrace>.gsf/.png and <prefix>_truth (empty: none)")
      .writes(tapping_image_files);
  add_output_params(p, "out/tapping_image/lines.csv", "per-line metrics (regime switches, jumps, peak force)");
  add_quiet_flag(p);
  p.applies_when("lockin_cycles", "engine", {"time-domain"});
  p.applies_when("cycle_tolerance", "engine", {"time-domain"});
}

std::vector<io::Column> tapping_image_line_columns() {
  return {{"line", "count", "line (row of the images, from 0 at the top)"},
          {"direction", "label", "trace (left to right) or retrace"},
          {"regime_switches", "count", "changes of regime between consecutive pixels of the line"},
          {"branch_jumps", "count", "jumps between branches of the orbit map during the line"},
          {"attractive_fraction", "dimensionless", "pixels of the line in the attractive regime"},
          {"repulsive_fraction", "dimensionless", "pixels of the line in the repulsive regime"},
          {"max_peak_force", "N", "largest peak force of the line"},
          {"rms_amplitude_error", "m", "RMS of the amplitude error over the line"}};
}

/// The sample must cover the scanned area (the surface clamps beyond its edges: that would image the edge).
void require_sample_covers_scan(const io::ParamSet& p, const scan::HeightMap& map, const ti::RasterSpec& r) {
  const double slack = 1e-9;
  const bool file = p.text("sample") == "file";
  const std::string what = file ? fmt::format("the sample file {} is {} m x {} m", p.text("sample_file"),
                                              map.x_size(), map.y_size())
                                : fmt::format("the sample is {} m x {} m (sample_size)", map.x_size(), map.y_size());
  const std::string key = !file && p.real("sample_size") > 0.0 ? "sample_size" : "scan_size";
  if (r.width > map.x_size() * (1.0 + slack))
    throw InvalidParameter(key, fmt::format("scan_size = {} m is wider than the sample: {}; the scan must lie on the "
                                            "sample", r.width, what));
  if (r.height > map.y_size() * (1.0 + slack))
    throw InvalidParameter(p.was_set("scan_height") ? "scan_height" : key,
                           fmt::format("the scan height {} m is taller than the sample: {}; the scan must lie on the "
                                       "sample", r.height, what));
}

/// The time-domain engine demodulates whole drive cycles: a pixel must last at least one cycle, and the lock-in's
/// window (lockin_cycles) at most one pixel (else each pixel reads its neighbours).
void require_whole_cycles(const io::ParamSet& p, const ti::RasterSpec& r, const ti::FeedbackSpec& fb, double f_drive) {
  const double cycles_per_pixel = r.pixel_time() * f_drive;
  const std::string speed_key = p.real("tip_speed") > 0.0 ? "tip_speed" : "line_rate";
  if (!(cycles_per_pixel >= 1.0))
    throw InvalidParameter(speed_key, fmt::format("engine = time-domain: a pixel lasts {:.4g} drive cycles ({} at tip "
                                                  "speed {:.6g} m/s, drive {:.6g} Hz): it must last at least 1 cycle (lower "
                                                  "{} or the pixels)",
                                                  cycles_per_pixel, io::quantity(r.pixel_time(), "s"), r.tip_speed,
                                                  f_drive, speed_key));
  const long cycles = p.integer("lockin_cycles");
  if (static_cast<double>(cycles) > cycles_per_pixel * (1.0 + 1e-9))
    throw InvalidParameter("lockin_cycles", fmt::format("lockin_cycles = {} is more than the {:.6g} drive cycles of one "
                                                        "pixel: the lock-in would average over the neighbouring "
                                                        "pixels; must be in [1, {}]",
                                                        cycles, cycles_per_pixel,
                                                        static_cast<long>(std::floor(cycles_per_pixel * (1.0 + 1e-9)))));
  // the controller samples the lock-in's output once per update: its bandwidth must be below the Nyquist frequency
  if (!(fb.lockin_bandwidth < 0.5 * fb.update_rate))
    throw InvalidParameter("lockin_bandwidth",
                           fmt::format("engine = time-domain: lockin_bandwidth = {} Hz aliases in the controller, "
                                       "which samples the lock-in at feedback_rate = {} Hz: it must be below {} Hz",
                                       fb.lockin_bandwidth, fb.update_rate, 0.5 * fb.update_rate));
}

void run_tapping_image(const io::ParamSet& p, Captured* capture) {
  if (p.text("units") != "physical")
    throw InvalidParameter("units", fmt::format("units = {}: tapping image works in physical units (sizes in m, "
                                                "rates in Hz): use units = physical", p.text("units")));
  const tapping::TappingModel model = tapping_model_from(p, law_object_of(capture));
  const TappingScales scales = tapping_scales_from(p);
  const double nm = 1e-9;
  const double f0 = p.real("resonance_frequency") * 1e3, q = p.real("quality_factor");
  const double f_drive = f0 * p.real("frequency_ratio");

  ti::FeedbackSpec fb;
  fb.setpoint = p.real("setpoint");
  fb.proportional_gain = p.real("proportional_gain");
  fb.integral_gain = p.real("integral_gain");
  fb.z_min = p.real("z_min");
  fb.z_max = p.real("z_max");
  fb.update_rate = p.real("feedback_rate");
  fb.lockin_bandwidth = p.real("lockin_bandwidth");
  fb.validate();
  if (!(fb.update_rate <= f_drive))
    throw InvalidParameter("feedback_rate",
                           fmt::format("feedback_rate = {} Hz is above the drive frequency {} Hz: the lock-in gives at "
                                       "most one amplitude per drive cycle", fb.update_rate, f_drive));
  if (!(fb.lockin_bandwidth < 0.5 * f_drive))
    throw InvalidParameter("lockin_bandwidth",
                           fmt::format("lockin_bandwidth = {} Hz aliases the lock-in: it must be below half the drive "
                                       "frequency ({} Hz), so that the 2f ripple of the demodulation is filtered",
                                       fb.lockin_bandwidth, 0.5 * f_drive));

  for (double sp : p.reals("setpoint_sweep"))
    if (!(sp > 0.0 && sp < 1.0))
      throw InvalidParameter("setpoint_sweep", fmt::format("setpoint_sweep contains {}: every set-point A_sp/A0 must be "
                                                           "in (0, 1)", sp));
  require_sample_memory(p);
  // 13 images and their files (8 bytes a value, GSF 4 + PNG 2 per image, levelled previews): 200 bytes a pixel
  memory::require_fits("lines", static_cast<double>(p.integer("lines")), 200.0 * static_cast<double>(p.integer("pixels")));
  // the sample: a file keeps its own size; a generator covers the scan (sample_size, else the scan's larger side)
  ti::RasterSpec raster;
  raster.pixels = p.integer("pixels");
  raster.lines = p.integer("lines");
  const bool file = p.text("sample") == "file";
  // a generated sample: sample_size, else (0) the larger side of the scan
  const double generated_size =
      p.real("sample_size") > 0.0 ? p.real("sample_size")
                                  : std::max(p.real("scan_size"), std::max(p.real("scan_height"), 0.0));
  scan::HeightMap map = sample_map_from(p, generated_size);
  raster.width = file && !p.was_set("scan_size") ? map.x_size() : p.real("scan_size");
  raster.height = p.real("scan_height") > 0.0 ? p.real("scan_height")
                  : file && !p.was_set("scan_size") ? map.y_size() : raster.width;
  raster.tip_speed = p.real("tip_speed") > 0.0 ? p.real("tip_speed") : 2.0 * raster.width * p.real("line_rate");
  raster.validate();
  require_sample_covers_scan(p, map, raster);
  const bool time_domain = p.text("engine") == "time-domain";
  if (time_domain) require_whole_cycles(p, raster, fb, f_drive);
  if (!time_domain && p.was_set("cycle_tolerance"))
    throw InvalidParameter("cycle_tolerance", fmt::format("cycle_tolerance does not apply to engine = {}: it is the "
                                                          "time-domain engine's integrator tolerance",
                                                          p.text("engine")));
  if (!time_domain && p.was_set("lockin_cycles"))
    throw InvalidParameter("lockin_cycles", fmt::format("lockin_cycles does not apply to engine = {}: the lock-in "
                                                        "window of whole cycles is the time-domain engine's",
                                                        p.text("engine")));
  const double tilt_angle = p.real("tilt_angle");
  if (!(tilt_angle < 90.0))
    throw InvalidParameter("tilt_angle", fmt::format("tilt_angle = {} deg is out of range: must be in [0, 90) deg",
                                                     tilt_angle));
  const scan::Surface surface(std::move(map), scan::Tilt(tilt_angle * std::numbers::pi / 180.0,
                                                         p.real("tilt_azimuth") * std::numbers::pi / 180.0));

  // the orbit map
  const double a0_nm = model.free_amplitude() * scales.length;
  ti::OrbitMapOptions mo;
  mo.separation_min = p.real("map_separation_min") / scales.length;
  mo.separation_max = (p.real("map_separation_max") != 0.0 ? p.real("map_separation_max") : 1.25 * a0_nm) / scales.length;
  mo.points = static_cast<int>(p.integer("map_points"));
  mo.sweep.shooting = shooting_options_from(p);
  mo.sweep.transient = transient_options_from(p);
  mo.sweep.cancellation = cancellation_of(capture);
  mo.validate();
  const bool quiet = p.flag("json") || p.flag("quiet");
  io::Progress map_progress("tapping image: orbit map (approach + retract)", 2L * mo.points, !quiet);
  mo.sweep.progress = [&map_progress](long n) { map_progress.advance(n); };
  const ti::OrbitMap orbit_map = computed("orbit map", [&] { return ti::OrbitMap::build(model, mo); });
  map_progress.finish();

  const double time_constant = 2.0 * q / (2.0 * std::numbers::pi * f0);  // τ_c = 2Q/ω0
  ti::TimeDomainOptions td;
  if (time_domain) {
    td.lockin_cycles = p.integer("lockin_cycles");
    td.lockin_bandwidth = fb.lockin_bandwidth;
    td.shooting = shooting_options_from(p);
    td.cycle_tolerance = p.real("cycle_tolerance");
    td.validate();
  }
  // a new engine for each scan (the main one and every set-point of the sweep)
  const auto make_engine = [&]() -> std::unique_ptr<ti::TipEngine> {
    if (time_domain) return std::make_unique<ti::TimeDomainEngine>(model, orbit_map, scales, td);
    return std::make_unique<ti::QuasiStaticEngine>(orbit_map, scales, time_constant, fb.lockin_bandwidth);
  };
  const std::unique_ptr<ti::TipEngine> engine = make_engine();
  io::Progress progress("tapping image", raster.lines, !quiet);
  ti::ImagingOptions io_options;
  io_options.progress = [&progress](long n) { progress.advance(n); };
  io_options.cancellation = cancellation_of(capture);
  const ti::ImagingResult r = ti::scan_image(*engine, surface, raster, fb, io_options);
  progress.finish();
  const ti::ImagingMetrics m = ti::imaging_metrics(r);
  // the set-point sweep: the same sample and map at each set-point (the height of the features against the truth's)
  const auto range_of = [](const scan::HeightMap& h) {
    const scan::HeightMap levelled = scan::level(h);
    const auto [lo, hi] = std::minmax_element(levelled.data().begin(), levelled.data().end());
    return *hi - *lo;
  };
  const double truth_range = range_of(r.truth);
  // the set-point sweep's scans are independent of each other and of the main one (each its own engine on the
  // shared, read-only map and sample): computed in parallel (OpenMP), each exactly as alone; the first failure in
  // the list's order is the one reported, as in a serial run
  const std::vector<double>& setpoints = p.reals("setpoint_sweep");
  std::vector<std::optional<UnitTagged>> swept(setpoints.size());
  std::vector<std::exception_ptr> sweep_errors(setpoints.size());
#pragma omp parallel for schedule(dynamic) if (setpoints.size() > 1)
  for (std::size_t k = 0; k < setpoints.size(); ++k) {
    try {
      const double sp = setpoints[k];
      ti::FeedbackSpec at = fb;
      at.setpoint = sp;
      const std::unique_ptr<ti::TipEngine> e = make_engine();
      ti::ImagingOptions o;
      o.cancellation = io_options.cancellation;
      const ti::ImagingResult rs = [&] {
        try {
          return ti::scan_image(*e, surface, raster, at, o);
        } catch (const InvalidParameter& error) {  // the approach does not reach it: name the list
          throw InvalidParameter("setpoint_sweep", fmt::format("setpoint_sweep contains {}: {}", sp, error.what()));
        }
      }();
      const ti::ImagingMetrics ms = ti::imaging_metrics(rs);
      swept[k] = setpoint_sweep_record(sp, rs.engaged_separation, ms, range_of(rs.trace.height), truth_range);
    } catch (...) {
      sweep_errors[k] = std::current_exception();
    }
  }
  std::vector<UnitTagged> setpoint_sweep;
  for (std::size_t k = 0; k < setpoints.size(); ++k) {
    if (sweep_errors[k]) std::rethrow_exception(sweep_errors[k]);
    setpoint_sweep.push_back(std::move(*swept[k]));
  }

  // the record: the sizes the run used
  io::ParamSet as_run = p;
  as_run.record_used("scan_size", raster.width);
  as_run.record_used("scan_height", raster.height);
  if (!file) as_run.record_used("sample_size", generated_size);
  as_run.record_used("map_separation_max", mo.separation_max * scales.length);
  CommandOutput out(as_run, capture, "tapping image");
  out.open(tapping_image_line_columns());
  for (long j = 0; j < raster.lines; ++j) {
    for (int d = 0; d < 2; ++d) {
      const ti::ImageChannels& c = d == 0 ? r.trace : r.retrace;
      long attractive = 0, repulsive = 0;
      double force = 0, e2 = 0;
      for (long i = 0; i < raster.pixels; ++i) {
        const int regime = static_cast<int>(c.regime(i, j));
        attractive += regime == 1;
        repulsive += regime == 2;
        force = std::max(force, c.peak_force(i, j));
        e2 += c.error(i, j) * c.error(i, j);
      }
      const double n = static_cast<double>(raster.pixels);
      out.row(j, d == 0 ? "trace" : "retrace", c.regime_switches[static_cast<std::size_t>(j)],
              c.branch_jumps[static_cast<std::size_t>(j)], static_cast<double>(attractive) / n,
              static_cast<double>(repulsive) / n, force, std::sqrt(e2 / n));
    }
  }
  std::vector<std::string> files;
  const std::string prefix = p.text("image_output");
  if (!prefix.empty()) {
    std::vector<NamedImage> images;
    const struct {
      const char* name;
      const char* title;
      bool level;
    } channels[] = {{"height", "Height (Z)", true},          {"error", "Amplitude error", false},
                    {"phase", "Phase", false},                {"power", "Dissipated power", false},
                    {"peak_force", "Peak force", false},      {"regime", "Regime (0 free, 1 attractive, 2 repulsive)", false}};
    for (int d = 0; d < 2; ++d) {
      const ti::ImageChannels& c = d == 0 ? r.trace : r.retrace;
      const scan::HeightMap* maps[] = {&c.height, &c.error, &c.phase, &c.power, &c.peak_force, &c.regime};
      for (std::size_t k = 0; k < 6; ++k)
        images.push_back({fmt::format("{}_{}", channels[k].name, d == 0 ? "trace" : "retrace"),
                          fmt::format("{} ({})", channels[k].title, d == 0 ? "trace" : "retrace"), maps[k],
                          channels[k].level});
    }
    images.push_back({"truth", "Ground truth (topography + tilt)", &r.truth, true});
    files = stage_images(prefix, images, out.outputs());
  }

  // the branches that hold the set-point: where the loop can sit, and the height change between them
  std::vector<UnitTagged> at_setpoint;
  const double a_sp_model = fb.setpoint * model.free_amplitude();
  for (std::size_t b = 0; b < orbit_map.branches().size(); ++b)
    for (double l : orbit_map.separations_at_amplitude(static_cast<int>(b), a_sp_model)) {
      if (!orbit_map.contains(static_cast<int>(b), l)) continue;
      const ti::SteadyState s = orbit_map.at(static_cast<int>(b), l);
      at_setpoint.push_back(branch_at_setpoint_record(
          b, l * scales.length * nm, ti::regime_name(ti::regime_of(s.in_phase_force, orbit_map.drive_amplitude())),
          s.phase() * 180.0 / std::numbers::pi, s.peak_force * scales.force * nm));
    }
  const double a_sp = r.setpoint_amplitude;
  // SI results (m, s, Hz, N), each with its unit; the records of the lists with the units of their prototypes
  UnitTagged tagged;
  tagged.add("engine", p.text("engine"))
      .add("cycles_per_pixel", raster.pixel_time() * f_drive, "count")
      .add("drive_cycles",
           time_domain ? static_cast<double>(dynamic_cast<const ti::TimeDomainEngine&>(*engine).cycles())
                       : 2.0 * static_cast<double>(raster.pixels * raster.lines) * raster.pixel_time() * f_drive,
           "count")
      .add("free_amplitude", a0_nm * nm, "m")
      .add("setpoint_amplitude", a_sp, "m")
      .add("drive_frequency", f_drive, "Hz")
      .add("cantilever_time_constant", time_constant, "s")
      .add("lockin_time_constant",
           fb.lockin_bandwidth > 0 ? 1.0 / (2.0 * std::numbers::pi * fb.lockin_bandwidth) : 0.0, "s")
      .add("tip_speed", raster.tip_speed, "m/s")
      .add("pixel_time", raster.pixel_time(), "s")
      .add("updates", r.updates, "count")
      .add("engaged_separation", r.engaged_separation, "m")
      .add("trace_height_rms_error", m.trace_height_rms_error, "m")
      .add("retrace_height_rms_error", m.retrace_height_rms_error, "m")
      .add("truth_rms_height", m.truth_rms_height, "m")
      .add("fraction_free", m.fraction_free, "dimensionless")
      .add("fraction_attractive", m.fraction_attractive, "dimensionless")
      .add("fraction_repulsive", m.fraction_repulsive, "dimensionless")
      .add("regime_switches_per_line", m.switches_per_line, "count")
      .add("max_regime_switches_per_line", m.max_switches_per_line, "count")
      .add("branch_jumps_per_line", m.jumps_per_line, "count")
      .add("max_peak_force", m.max_peak_force, "N")
      .add("max_amplitude_error", m.max_abs_error, "m")
      .add("beyond_map_updates", r.beyond_map_updates, "count")
      .add("z_limited_updates", r.z_limited_updates, "count")
      .add("map_branches", orbit_map.branches().size(), "count")
      .add("map_jumps", orbit_map.jumps(), "count")
      .add("map_non_periodic_points", orbit_map.non_periodic_points(), "count")
      .add("branches_at_setpoint", at_setpoint, branch_at_setpoint_record(0, 0.0, "", 0.0, 0.0))
      .add("apparent_height", range_of(r.trace.height), "m")
      .add("truth_height", truth_range, "m")
      .add("setpoint_sweep", setpoint_sweep, setpoint_sweep_record(0.0, 0.0, ti::ImagingMetrics{}, 0.0, 0.0))
      .add("scan_seconds", r.seconds, "s")
      .add("files", files);
  const nlohmann::json results = std::move(tagged).summary();
  if (r.beyond_map_updates > 0)
    io::message_line(fmt::format("afmkit tapping image: warning: {} of {} controller updates had the separation "
                                 "outside the orbit map [{}, {}] (clamped): widen map_separation_min/max",
                                 r.beyond_map_updates, r.updates, io::quantity(orbit_map.separation_min() * scales.length * nm, "m"),
                                 io::quantity(orbit_map.separation_max() * scales.length * nm, "m")));
  const std::string summary = fmt::format(
      "afmkit tapping image ({} engine): {} x {} pixels, trace and retrace, set-point {} ({}), engaged at {}; height RMS error "
      "{} (trace) / {} (retrace) against the truth's {} after plane levelling; regime: {:.3g} % attractive, "
      "{:.3g} % repulsive, {:.3g} % free; {:.3g} regime switches per line; largest peak force {}; orbit map {} "
      "branches, {} jumps; scan {:.3g} s{}",
      p.text("engine"), raster.pixels, raster.lines, fb.setpoint, io::quantity(a_sp, "m"),
      io::quantity(r.engaged_separation, "m"), io::quantity(m.trace_height_rms_error, "m"), io::quantity(m.retrace_height_rms_error, "m"),
      io::quantity(m.truth_rms_height, "m"), 100.0 * m.fraction_attractive, 100.0 * m.fraction_repulsive,
      100.0 * m.fraction_free, m.switches_per_line, io::quantity(m.max_peak_force, "N"),
      orbit_map.branches().size(), orbit_map.jumps(), r.seconds,
      files.empty() ? std::string() : fmt::format("; wrote {} files with prefix {}", files.size(), prefix));
  out.finish(results, summary);
}

}  // namespace

void register_tapping_image(CLI::App& tapping) {
  add_command(tapping, "image",
              "virtual tapping-mode AFM: a sample scanned in raster lines (trace, retrace) with the amplitude held at "
              "the set-point by a PI loop on Z; height, amplitude error, phase, dissipated power, peak force and "
              "regime images (GSF, PNG); quasi-static engine on the orbit map of the law, or the exact time-domain "
              "engine (--engine time-domain)",
              declare_tapping_image, run_tapping_image);
}

}  // namespace afmkit::cli
