// The raster scan with the amplitude loop (imaging.hpp), for any tip engine.
#include "afmkit/tapping/image/imaging.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/levelling.hpp"

namespace afmkit::tapping::image {

namespace {
bool positive_finite(double v) { return v > 0.0 && std::isfinite(v); }
}  // namespace

void RasterSpec::validate() const {
  if (pixels < 2 || pixels > 16384)
    throw InvalidParameter("pixels", fmt::format("pixels = {} is out of range: must be in [2, 16384]", pixels));
  if (lines < 1 || lines > 16384)
    throw InvalidParameter("lines", fmt::format("lines = {} is out of range: must be in [1, 16384]", lines));
  if (!positive_finite(width))
    throw InvalidParameter("scan_size", fmt::format("scan_size = {} m is out of range: must be > 0", width));
  if (!positive_finite(height))
    throw InvalidParameter("scan_height", fmt::format("scan_height = {} m is out of range: must be > 0", height));
  if (!(std::isfinite(x_centre) && std::isfinite(y_centre)))
    throw InvalidParameter("scan_centre", "the scan centre must be finite");
  if (!positive_finite(tip_speed))
    throw InvalidParameter("tip_speed", fmt::format("tip_speed = {} m/s is out of range: must be > 0", tip_speed));
}

scan::Grid RasterSpec::grid() const {
  return {pixels, lines, width, height, x_centre - 0.5 * width, y_centre - 0.5 * height};
}

void FeedbackSpec::validate() const {
  if (!(setpoint > 0.0 && setpoint < 1.0))
    throw InvalidParameter("setpoint", fmt::format("setpoint = {} is out of range: the amplitude set-point A_sp/A0 "
                                                   "must be in (0, 1)", setpoint));
  // upper bounds far beyond any stable loop, so that Z stays finite whatever the error
  if (!(proportional_gain >= 0.0 && proportional_gain <= 1e6))
    throw InvalidParameter("proportional_gain", fmt::format("proportional_gain = {} is out of range: must be >= 0 "
                                                            "(and <= 1e6)", proportional_gain));
  if (!(integral_gain >= 0.0 && integral_gain <= 1e12))
    throw InvalidParameter("integral_gain", fmt::format("integral_gain = {} 1/s is out of range: must be >= 0 (and "
                                                        "<= 1e12 1/s)", integral_gain));
  if (!(proportional_gain > 0.0 || integral_gain > 0.0))
    throw InvalidParameter("integral_gain", "proportional_gain and integral_gain are both 0: the loop would not move Z");
  if (!(std::isfinite(z_min) && std::isfinite(z_max)))
    throw InvalidParameter("z_min", "z_min and z_max must be finite");
  if (!(z_min < z_max))
    throw InvalidParameter("z_max", fmt::format("z_max = {} m must be > z_min = {} m", z_max, z_min));
  if (!positive_finite(update_rate))
    throw InvalidParameter("feedback_rate", fmt::format("feedback_rate = {} Hz is out of range: must be > 0",
                                                        update_rate));
  if (!(lockin_bandwidth >= 0.0 && std::isfinite(lockin_bandwidth)))
    throw InvalidParameter("lockin_bandwidth", fmt::format("lockin_bandwidth = {} Hz is out of range: must be >= 0",
                                                           lockin_bandwidth));
}

namespace {

struct Channels {
  std::vector<double> height, error, phase, power, force, regime;
  explicit Channels(std::size_t n)
      : height(n), error(n), phase(n), power(n), force(n), regime(n) {}
};

ImageChannels to_images(const scan::Grid& g, Channels c, std::vector<long> switches, std::vector<long> jumps) {
  return {scan::HeightMap(g, std::move(c.height), "m"),   scan::HeightMap(g, std::move(c.error), "m"),
          scan::HeightMap(g, std::move(c.phase), "deg"),  scan::HeightMap(g, std::move(c.power), "W"),
          scan::HeightMap(g, std::move(c.force), "N"),    scan::HeightMap(g, std::move(c.regime), ""),
          std::move(switches), std::move(jumps)};
}

}  // namespace

ImagingResult scan_image(TipEngine& engine, const scan::Surface& surface, const RasterSpec& raster,
                         const FeedbackSpec& feedback, const ImagingOptions& options) {
  raster.validate();
  feedback.validate();
  const auto started = std::chrono::steady_clock::now();
  const scan::Grid grid = raster.grid();
  {  // the scan must lie on the sample (the surface clamps beyond its edges: that would image the edge)
    const scan::HeightMap& m = surface.map();
    const double slack = 1e-9 * std::max(m.x_size(), m.y_size());
    if (grid.x_offset < m.x_offset() - slack || grid.x_offset + grid.x_size > m.x_offset() + m.x_size() + slack)
      throw InvalidParameter("scan_size", fmt::format("the scan [{}, {}] m in x leaves the sample [{}, {}] m",
                                                      grid.x_offset, grid.x_offset + grid.x_size, m.x_offset(),
                                                      m.x_offset() + m.x_size()));
    if (grid.y_offset < m.y_offset() - slack || grid.y_offset + grid.y_size > m.y_offset() + m.y_size() + slack)
      throw InvalidParameter("scan_height", fmt::format("the scan [{}, {}] m in y leaves the sample [{}, {}] m",
                                                        grid.y_offset, grid.y_offset + grid.y_size, m.y_offset(),
                                                        m.y_offset() + m.y_size()));
  }
  const long nx = raster.pixels, ny = raster.lines;
  const double dx = raster.width / static_cast<double>(nx), dy = raster.height / static_cast<double>(ny);
  const double x_left = grid.x_offset, y_top = grid.y_offset;
  const double pixel_time = raster.pixel_time();
  const long updates_per_pixel = std::max(1L, std::lround(pixel_time * feedback.update_rate));
  const double dt = pixel_time / static_cast<double>(updates_per_pixel);
  const double step = dx / static_cast<double>(updates_per_pixel);
  const double a0 = engine.free_amplitude(), a_sp = feedback.setpoint * a0;
  const double deg = 180.0 / std::numbers::pi;

  long updates = 0, beyond_map = 0, z_limited = 0;
  const auto n = static_cast<std::size_t>(nx * ny);
  Channels trace(n), retrace(n);
  std::vector<double> truth(n);
  std::vector<long> trace_switches(static_cast<std::size_t>(ny)), retrace_switches(static_cast<std::size_t>(ny));
  std::vector<long> trace_jumps(static_cast<std::size_t>(ny)), retrace_jumps(static_cast<std::size_t>(ny));

  // engage over the start of the first line
  const double l0 = engine.engage(a_sp);
  double z = l0 + surface(x_left, y_top + 0.5 * dy);
  if (!(z >= feedback.z_min && z <= feedback.z_max))
    throw InvalidParameter("z_max", fmt::format("the tip engages with the base at Z = {:.6g} m, outside [z_min, z_max] "
                                                "= [{:.6g}, {:.6g}] m: widen the Z range",
                                                z, feedback.z_min, feedback.z_max));
  double integral = z;
  double error = 0.0;
  int last_branch = -1;

  for (long j = 0; j < ny; ++j) {
    options.cancellation.check();
    const double y = y_top + (static_cast<double>(j) + 0.5) * dy;
    for (int direction = 0; direction < 2; ++direction) {
      Channels& c = direction == 0 ? trace : retrace;
      long& switches = (direction == 0 ? trace_switches : retrace_switches)[static_cast<std::size_t>(j)];
      long& jumps = (direction == 0 ? trace_jumps : retrace_jumps)[static_cast<std::size_t>(j)];
      int last_regime = -1;
      for (long k = 0; k < nx; ++k) {
        const long i = direction == 0 ? k : nx - 1 - k;
        // the tip crosses pixel i: left to right on the trace, right to left on the retrace
        const double start = direction == 0 ? x_left + static_cast<double>(i) * dx
                                            : x_left + static_cast<double>(i + 1) * dx;
        const double sign = direction == 0 ? 1.0 : -1.0;
        double sum_z = 0, sum_e = 0, sum_x = 0, sum_y = 0, sum_power = 0, max_force = -std::numeric_limits<double>::infinity();
        TipReading r;
        for (long u = 0; u < updates_per_pixel; ++u) {
          const double x0 = start + sign * static_cast<double>(u) * step, x1 = x0 + sign * step;
          r = engine.advance(surface, z, x0, x1, y, dt);
          if (r.beyond_map) ++beyond_map;
          if (last_branch >= 0 && r.branch != last_branch) ++jumps;
          last_branch = r.branch;
          // PI on e = A_sp − A (Z up when the amplitude is too small), the integral held at a limit
          error = a_sp - r.amplitude;
          const double increment = feedback.integral_gain * error * dt;
          integral += increment;
          double zn = integral + feedback.proportional_gain * error;
          if (zn > feedback.z_max || zn < feedback.z_min) {
            integral -= increment;
            zn = std::clamp(integral + feedback.proportional_gain * error, feedback.z_min, feedback.z_max);
            ++z_limited;
          }
          z = zn;
          sum_z += z;
          sum_e += -error;
          sum_x += r.in_phase;
          sum_y += r.quadrature;
          sum_power += r.power;
          max_force = std::max(max_force, r.peak_force);
        }
        updates += updates_per_pixel;
        const auto at = static_cast<std::size_t>(j * nx + i);
        const double inv = 1.0 / static_cast<double>(updates_per_pixel);
        c.height[at] = sum_z * inv;
        c.error[at] = sum_e * inv;
        c.phase[at] = std::atan2(sum_y, sum_x) * deg;
        c.power[at] = sum_power * inv;
        c.force[at] = max_force;
        c.regime[at] = r.regime;
        if (last_regime >= 0 && r.regime != last_regime) ++switches;
        last_regime = r.regime;
        if (direction == 0) truth[at] = surface(x_left + (static_cast<double>(i) + 0.5) * dx, y);
      }
    }
    if (options.progress) options.progress(1);
  }
  ImagingResult result{to_images(grid, std::move(trace), std::move(trace_switches), std::move(trace_jumps)),
                       to_images(grid, std::move(retrace), std::move(retrace_switches), std::move(retrace_jumps)),
                       scan::HeightMap(grid, std::move(truth), "m"),
                       l0,
                       a_sp,
                       updates,
                       beyond_map,
                       z_limited,
                       0.0};
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

ImagingMetrics imaging_metrics(const ImagingResult& r) {
  ImagingMetrics m;
  const bool plane = r.truth.x_resolution() >= 2 && r.truth.y_resolution() >= 2;
  if (plane) {
    m.trace_height_rms_error = scan::levelled_rms_difference(r.trace.height, r.truth);
    m.retrace_height_rms_error = scan::levelled_rms_difference(r.retrace.height, r.truth);
    const scan::HeightMap level = scan::level(r.truth);
    double s = 0;
    for (double v : level.data()) s += v * v;
    m.truth_rms_height = std::sqrt(s / static_cast<double>(level.size()));
  } else {
    m.trace_height_rms_error = m.retrace_height_rms_error = m.truth_rms_height =
        std::numeric_limits<double>::quiet_NaN();
  }
  m.max_peak_force = -std::numeric_limits<double>::infinity();
  long counts[3] = {0, 0, 0};
  double total = 0;
  for (const ImageChannels* c : {&r.trace, &r.retrace}) {
    for (double v : c->regime.data()) {
      const int k = static_cast<int>(v);
      if (k >= 0 && k <= 2) ++counts[k];
      total += 1;
    }
    for (double v : c->peak_force.data()) m.max_peak_force = std::max(m.max_peak_force, v);
    for (double v : c->error.data()) m.max_abs_error = std::max(m.max_abs_error, std::abs(v));
    for (long s : c->regime_switches) {
      m.switches_per_line += static_cast<double>(s);
      m.max_switches_per_line = std::max(m.max_switches_per_line, s);
    }
    for (long s : c->branch_jumps) m.jumps_per_line += static_cast<double>(s);
  }
  const double lines = 2.0 * static_cast<double>(r.trace.regime_switches.size());
  m.switches_per_line /= lines;
  m.jumps_per_line /= lines;
  m.fraction_free = static_cast<double>(counts[0]) / total;
  m.fraction_attractive = static_cast<double>(counts[1]) / total;
  m.fraction_repulsive = static_cast<double>(counts[2]) / total;
  return m;
}

}  // namespace afmkit::tapping::image
