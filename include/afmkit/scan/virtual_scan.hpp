#pragma once
// The whole virtual rotational scan (docs/scan.md): simulate the spiral with the controller in the loop, image the
// deflection and the reconstructed topography onto a Cartesian grid, measure what the controller buys.
//
//   Surface sample(rough(grid, {}), Tilt(0.05 * pi / 180, 0));
//   InstrumentSpec instrument;                         // defaults: 50 Hz, γ = 2π·1 kHz, τ = 1 ms, ±2 µm
//   VirtualScan scan = run_virtual_scan(instrument, sample, image_grid(instrument, 512));
//   scan.topography.valid_count(); scan.scan_area_gain; …
//
// Metrics:
//   * max_radius_with_control / _without_control: the radius of the first saturated sample of the run with the
//     controller as specified / of a second run with the controller off (stopped at its first saturation); r_end
//     when the run never saturates (then `saturates_…` is false);
//   * scan_area_gain = (r_on² − r_0²) / (r_off² − r_0²): how much more area is scanned before the detector
//     saturates; a lower bound when the controlled run never saturates, NaN when the uncontrolled one never does;
//   * topography_rms_error: RMS of the topography image against the ground truth (the surface, tilt included, at
//     the pixel centres) after each is levelled by its own least-squares plane, over the pixels valid in the image.
// Saturated samples carry no height: they are given to the imager as NaN, so pixels that depend on them are invalid.
#include <cstdint>
#include <functional>
#include <string>

#include "afmkit/scan/height_map.hpp"
#include "afmkit/scan/spiral_scan.hpp"
#include "afmkit/scan/turn_metrics.hpp"

namespace afmkit::scan {

/// The square grid of `resolution`² pixels centred on the spindle axis that covers the scanned disc [−r_end, r_end]².
Grid image_grid(const InstrumentSpec& instrument, long resolution);

struct VirtualScanOptions {
  bool compare_without_control = true;  ///< run the second, uncontrolled scan for the saturation radius
  ScanObserver* extra = nullptr;        ///< also receives every sample of the main run (e.g. a time-series writer)
  std::function<void(const TurnRecord&)> on_turn;  ///< each complete turn of the main run
  std::function<void(std::int64_t, std::int64_t)> progress;  ///< (samples done, total) of the main run
  Cancellation cancellation;  ///< checked every 65536 samples of both runs (core/cancellation.hpp)
};

struct VirtualScan {
  ScanRun run;
  HeightMap deflection;   ///< image of the detector reading d [m]
  HeightMap topography;   ///< image of the reconstruction d + z_a (deflection + actuator displacement) [m]
  HeightMap truth;        ///< the surface (tilt included) at the pixel centres, valid where `topography` is [m]
  std::int64_t turns = 0;
  double saturated_fraction = 0.0;        ///< saturated samples / samples of the main run
  double max_radius_with_control = 0.0;   ///< [m] (see above)
  bool saturates_with_control = false;
  double max_radius_without_control = 0.0;  ///< [m]; NaN when not compared
  bool saturates_without_control = false;
  double scan_area_gain = 0.0;            ///< [dimensionless] (see above)
  bool scan_area_gain_is_lower_bound = false;
  double topography_rms_error = 0.0;      ///< [m] (see above)
  double deflection_rms = 0.0;            ///< RMS of the levelled deflection image [m]
};

/// Checks that the turns overlap at the image resolution: the pitch v_r / f_rot must not exceed the pixel size
/// (InvalidParameter "radial_speed", naming the largest allowed speed); and that the sample covers the disc
/// (InvalidParameter "end_radius" when r_end exceeds the surface's inscribed radius).
void check_scan_geometry(const InstrumentSpec& instrument, const Surface& surface, const Grid& grid);

/// Runs the scan (validated first, then check_scan_geometry).
VirtualScan run_virtual_scan(const InstrumentSpec& instrument, const Surface& surface, const Grid& grid,
                             const VirtualScanOptions& options = {});

}  // namespace afmkit::scan
