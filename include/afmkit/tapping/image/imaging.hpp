#pragma once
// Amplitude-modulation imaging with Z feedback (docs/commands.md#afmkit-tapping-image, docs/theory-tapping.md
// #quasi-static-imaging): a raster scan of a sample (scan::Surface: topography + tilt, metres) under a tapping
// cantilever whose base height Z a PI controller moves to hold the lock-in amplitude at the set-point.
//
// The loop is the same for every engine; the engine (TipEngine) is what answers "which amplitude and phase does the
// lock-in read, and what does the tip do to the sample" while the base is at Z and the tip moves over the sample.
// The quasi-static engine (quasi_static.hpp) answers from the steady-state orbit map; the exact time-domain engine
// (time_domain.hpp) by stepping the cantilever ODE cycle by cycle under the moving tip.
//
// SI units throughout: m, s, N, W, rad.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/scan/height_map.hpp"
#include "afmkit/scan/surface.hpp"

namespace afmkit::tapping::image {

/// The raster: `lines` lines of `pixels` pixels over width × height centred on (x_centre, y_centre) of the sample
/// frame (x right = fast axis, y down = slow axis, row 0 the first line). Each line is scanned left to right (trace)
/// then right to left (retrace) at `tip_speed`; both images sample the same pixel centres.
struct RasterSpec {
  long pixels = 256;
  long lines = 256;
  double width = 1e-6;
  double height = 1e-6;
  double x_centre = 0.0, y_centre = 0.0;
  double tip_speed = 2e-6;  // m/s (line rate f: 2 · width · f)
  void validate() const;    // InvalidParameter naming pixels, lines, scan_size, scan_height, tip_speed
  scan::Grid grid() const;  // the images' grid
  double pixel_time() const { return width / static_cast<double>(pixels) / tip_speed; }
};

/// The amplitude loop: lock-in, PI controller, Z limits.
struct FeedbackSpec {
  double setpoint = 0.8;               // A_sp / A0, in (0, 1)
  double proportional_gain = 0.0;      // K_p >= 0 [m of Z per m of amplitude error]
  double integral_gain = 2000.0;       // K_i >= 0 [1/s]
  double z_min = -5e-6, z_max = 5e-6;  // limits of the base height Z [m], z_min < z_max
  double update_rate = 50e3;           // controller updates per second [Hz] (at most the drive frequency)
  double lockin_bandwidth = 5e3;       // -3 dB bandwidth of the lock-in's first-order output filter [Hz]
  void validate() const;  // InvalidParameter naming setpoint, proportional_gain, integral_gain, z_min, z_max, ...
};

/// What the lock-in reads and what the tip does, after one controller period.
struct TipReading {
  double amplitude = 0.0;       // lock-in amplitude R [m]
  double in_phase = 0.0;        // lock-in outputs X = R cos φ, Y = R sin φ [m] (φ: lag behind the drive)
  double quadrature = 0.0;
  double separation = 0.0;      // l = Z − h under the tip [m]
  double peak_force = 0.0;      // largest tip–sample force of the cycle [N] (positive = repulsive)
  double power = 0.0;           // power the sample dissipates [W]
  int regime = 0;               // Regime as int (orbit_map.hpp)
  int branch = 0;               // the branch of the orbit (engine-defined; a change is a jump)
  bool beyond_map = false;      // the separation left the engine's range (clamped)
};

/// A tip engine: the cantilever, the sample's force law and the lock-in.
class TipEngine {
 public:
  virtual ~TipEngine() = default;
  /// The free amplitude A0 [m].
  virtual double free_amplitude() const = 0;
  /// The drive frequency [Hz].
  virtual double drive_frequency() const = 0;
  /// Brings the tip down from far to the amplitude `amplitude` [m] (lock-in settled): returns the separation [m].
  /// InvalidParameter("setpoint") when the approach never reaches it.
  virtual double engage(double amplitude) = 0;
  /// Advances by dt [s] with the base at z [m] while the tip moves from (x0, y) to (x1, y) over the surface.
  virtual TipReading advance(const scan::Surface& surface, double z, double x0, double x1, double y, double dt) = 0;
};

/// One direction's images.
struct ImageChannels {
  scan::HeightMap height;           // Z at the pixel (mean over the dwell) [m]
  scan::HeightMap error;            // lock-in amplitude − set-point amplitude [m]
  scan::HeightMap phase;            // lock-in phase [deg]: of the mean X, Y over the dwell
  scan::HeightMap power;            // dissipated power [W]
  scan::HeightMap peak_force;       // largest peak force over the dwell [N]
  scan::HeightMap regime;           // regime at the end of the dwell (0 free, 1 attractive, 2 repulsive)
  std::vector<long> regime_switches;  // per line: changes of regime between consecutive pixels
  std::vector<long> branch_jumps;     // per line: jumps between branches during the line
};

struct ImagingResult {
  ImageChannels trace, retrace;
  scan::HeightMap truth;            // sample height (topography + tilt) at the pixel centres [m]
  double engaged_separation = 0.0;  // [m]
  double setpoint_amplitude = 0.0;  // [m]
  long updates = 0;                 // controller updates
  long beyond_map_updates = 0;      // updates with the separation outside the engine's range
  long z_limited_updates = 0;       // updates with Z at a limit
  double seconds = 0.0;             // wall time of the scan
};

struct ImagingOptions {
  std::function<void(long)> progress;  // lines done (trace + retrace = 1)
  Cancellation cancellation;
};

/// Scans the raster (line 0 first; each line trace then retrace; the slow axis steps between lines) after engaging
/// at the set-point over the first pixel. Controller (updates every 1/update_rate): e = A_sp − A_lock-in,
/// Z = Z_engage + K_p e + K_i ∫e dt, clamped to [z_min, z_max] (the integral held while clamped).
ImagingResult scan_image(TipEngine& engine, const scan::Surface& surface, const RasterSpec& raster,
                         const FeedbackSpec& feedback, const ImagingOptions& options = {});

/// Metrics of a result (docs/commands.md#afmkit-tapping-image).
struct ImagingMetrics {
  double trace_height_rms_error = 0.0;    // RMS(height − truth) after the same plane levelling [m]
  double retrace_height_rms_error = 0.0;
  double truth_rms_height = 0.0;          // RMS of the levelled truth [m]
  double fraction_free = 0.0, fraction_attractive = 0.0, fraction_repulsive = 0.0;  // of all pixels (both)
  double switches_per_line = 0.0;         // mean over trace and retrace lines
  long max_switches_per_line = 0;
  double jumps_per_line = 0.0;
  double max_peak_force = 0.0;            // [N]
  double max_abs_error = 0.0;             // largest |amplitude error| pixel [m]
};
ImagingMetrics imaging_metrics(const ImagingResult& result);

}  // namespace afmkit::tapping::image
