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
//     the pixel centres) after each is levelled by its own least-squares plane, over the pixels valid in the image;
//     the same for each reconstruction (lagged_rms_error, inverse_rms_error);
//   * the error budget of the inverse reconstruction (ErrorBudget; docs/scan.md#reconstruction).
// Saturated samples carry no height: they are given to the imager as NaN, so pixels that depend on them are invalid.
#include <cstdint>
#include <functional>
#include <string>

#include "afmkit/scan/height_map.hpp"
#include "afmkit/scan/plant_inverse.hpp"
#include "afmkit/scan/spiral_imager.hpp"
#include "afmkit/scan/spiral_scan.hpp"
#include "afmkit/scan/turn_metrics.hpp"

namespace afmkit::scan {

/// The square grid of `resolution`² pixels centred on the spindle axis that covers the scanned disc [−r_end, r_end]².
Grid image_grid(const InstrumentSpec& instrument, long resolution);

/// The main run's imager for this instrument and image grid (channels deflection, lagged, inverse and the true
/// height at the samples; a table of about the samples per turn): what run_virtual_scan builds when
/// VirtualScanOptions::imager is null.
SpiralImager scan_imager(const InstrumentSpec& instrument, const Grid& grid);

struct VirtualScanOptions {
  /// run the second, uncontrolled scan for the saturation radius (on a third thread beside the main run when
  /// imaging_thread is true)
  bool compare_without_control = true;
  /// image on a second thread, a batch behind the simulation (observer_thread.hpp); false: everything on the
  /// calling thread, the comparison run too (the same results)
  bool imaging_thread = true;
  /// also receives every sample of the main run (e.g. a time-series writer); called, like on_turn, on the imaging
  /// thread when there is one, never concurrently with itself or on_turn
  ScanObserver* extra = nullptr;
  std::function<void(const TurnRecord&)> on_turn;  ///< each complete turn of the main run (on that thread)
  std::function<void(std::int64_t, std::int64_t)> progress;  ///< (samples done, total) of the main run
  Cancellation cancellation;  ///< checked every 65536 samples of both runs (core/cancellation.hpp)
  /// the main run's imager, prepared by scan_imager(instrument, grid) with the same instrument and grid (e.g. on
  /// another thread while the sample is generated: its construction sorts the pixel centres) and given no sample;
  /// null: built here. std::invalid_argument if it is not such an imager.
  SpiralImager* imager = nullptr;
};

/// What the inverse reconstruction's image error is made of (plant_inverse.hpp, docs/scan.md#reconstruction).
/// Lengths in metres; each term is an RMS over the image after levelling (as topography_rms_error).
struct ErrorBudget {
  double imaging = 0.0;         ///< the true heights at the samples, imaged the same way, against the truth: the
                                ///< floor set by the sampling along the turn and the pitch (no reconstruction beats it)
  double reconstruction = 0.0;  ///< the inverse image against the imaged true heights (the previous term's image):
                                ///< what the reconstruction itself adds, whatever the sampling
  double plant_mismatch = 0.0;  ///< γ̂/γ − 1 [dimensionless]: how wrong the assumed plant rate is
  double plant = 0.0;           ///< first-order plant-knowledge term |γ/γ̂ − 1| × lagged_rms_error
  /// G of the inverse as applied [dimensionless] (white noise on w comes out × G at the samples): the exact
  /// inverse's (PlantInverse::noise_gain) or, with the Wiener low-pass, G_W (WienerLowPass::noise_gain)
  double noise_gain = 0.0;
  double image_noise_gain = 0.0;  ///< the same in the image (…::image_noise_gain) [dimensionless]
  double noise = 0.0;           ///< image_noise_gain · σ_d: the detector noise through the inverse and the imaging
  bool wiener = false;          ///< the Wiener low-pass is applied (inverse_filter wiener and σ_d > 0)
  double exact_image_noise_gain = 0.0;  ///< PlantInverse::image_noise_gain, what the exact inverse would pass
  double prior_increment = 0.0;  ///< √A of the Wiener prior [m] (0 without the low-pass)
  double cutoff = 0.0;          ///< frequency where the low-pass's gain is 1/2 [Hz] (f_s/2 without it)
  std::int64_t filter_taps = 0;  ///< 2K + 1 taps of the low-pass (1 without it)
  /// the height the low-pass removes from this sample along the spiral (sampled_resolution) [m]
  double resolution = 0.0;
  double resolution_prior = 0.0;  ///< the same for a sample of the prior, closed form (WienerLowPass) [m]
  double predicted = 0.0;       ///< √(imaging² + plant² + noise² + resolution²), to compare with inverse_rms_error
  double pole = 0.0;            ///< p = −b0/b1 of the inverse recursion [dimensionless]
  std::int64_t settle_samples = 0;  ///< samples left out after each saturated stretch
};

struct VirtualScan {
  ScanRun run;
  Reconstruction method = Reconstruction::inverse;  ///< the reconstruction `topography` shows
  HeightMap deflection;   ///< image of the detector reading d [m]
  HeightMap topography;   ///< image of the chosen reconstruction [m]
  HeightMap alternative;  ///< image of the other reconstruction (lagged when `method` is inverse, and vice versa)
  HeightMap truth;        ///< the surface (tilt included) at the pixel centres, valid where `topography` is [m]
  std::int64_t turns = 0;
  double saturated_fraction = 0.0;        ///< saturated samples / samples of the main run
  double max_radius_with_control = 0.0;   ///< [m] (see above)
  bool saturates_with_control = false;
  double max_radius_without_control = 0.0;  ///< [m]; NaN when not compared
  bool saturates_without_control = false;
  double scan_area_gain = 0.0;            ///< [dimensionless] (see above)
  bool scan_area_gain_is_lower_bound = false;
  double topography_rms_error = 0.0;      ///< [m] (see above), of the chosen reconstruction
  double lagged_rms_error = 0.0;          ///< [m] of the lagged reconstruction w = d + z_a
  double inverse_rms_error = 0.0;         ///< [m] of the inverse reconstruction f̂
  double sample_rms_height = 0.0;         ///< RMS of the levelled truth image [m]
  ErrorBudget budget;
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
