// The whole virtual rotational scan: simulation, imaging, metrics (virtual_scan.hpp).
#include "afmkit/scan/virtual_scan.hpp"

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <numbers>
#include <tuple>
#include <utility>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/levelling.hpp"
#include "afmkit/scan/observer_thread.hpp"
#include "afmkit/scan/spiral_imager.hpp"
#include "afmkit/scan/uncontrolled_saturation.hpp"
#include "afmkit/scan/wiener_inverse.hpp"

namespace afmkit::scan {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The imager's channels.
enum VirtualScanChannel : std::size_t { kDeflectionChannel, kLaggedChannel, kInverseChannel, kSampledTruthChannel };

// Feeds the imager: deflection, both reconstructions (NaN where the detector saturated; the inverse also while it
// settles) and the true height at the samples (for the imaging floor).
class ImagingObserver final : public ScanObserver {
 public:
  explicit ImagingObserver(SpiralImager& imager) : imager_(imager) {}
  bool sample(const ScanSample& s) override {
    const double values[4] = {s.saturated ? kNaN : s.deflection, s.saturated ? kNaN : s.topography, s.inverse,
                              s.saturated ? kNaN : s.surface};
    imager_.add(s.angle, s.radius, values);
    return true;
  }

 private:
  SpiralImager& imager_;
};

HeightMap truth_on(const HeightMap& image, const Surface& surface) {
  const Grid& g = image.grid();
  std::vector<double> z(image.size(), kNaN);
  std::vector<std::uint8_t> valid(image.size(), 0);
  for (long j = 0; j < g.y_resolution; ++j)
    for (long i = 0; i < g.x_resolution; ++i) {
      if (!image.valid(i, j) || !std::isfinite(image(i, j))) continue;
      const double x = g.x_offset + (static_cast<double>(i) + 0.5) * image.dx();
      const double y = g.y_offset + (static_cast<double>(j) + 0.5) * image.dy();
      const auto k = static_cast<std::size_t>(j * g.x_resolution + i);
      z[k] = surface(x, y);
      valid[k] = 1;
    }
  return HeightMap(g, std::move(z), "m", std::move(valid));
}

double annulus(double outer, double inner) { return outer * outer - inner * inner; }

// The levelled RMS difference of two images; NaN when fewer than three pixels valid in both (or only collinear
// ones) leave no plane to level by — a degenerate image (e.g. a detector saturated nearly everywhere), reported as
// a NaN error (null in the sidecar), not as an error of the user's input.
double levelled_error(const HeightMap& image, const HeightMap& truth) {
  if (image.valid_count() < 3 || truth.valid_count() < 3) return kNaN;
  try {
    return levelled_rms_difference(image, truth);
  } catch (const InvalidParameter&) {  // the plane fit's degenerate case (the grids are the same by construction)
    return kNaN;
  }
}

}  // namespace

Grid image_grid(const InstrumentSpec& instrument, long resolution) {
  if (resolution < 2 || resolution > 16384)
    throw InvalidParameter("image_resolution",
                           fmt::format("image_resolution = {} is out of range: must be an integer in [2, 16384]",
                                       resolution));
  const double r = instrument.spiral.end_radius;
  return Grid{resolution, resolution, 2.0 * r, 2.0 * r, -r, -r};
}

SpiralImager scan_imager(const InstrumentSpec& instrument, const Grid& grid) {
  const double per_turn = std::clamp(std::round(instrument.spiral.samples_per_turn()), 16.0, 4194304.0);
  return SpiralImager(grid, {"m", "m", "m", "m"}, static_cast<int>(per_turn));
}

void check_scan_geometry(const InstrumentSpec& instrument, const Surface& surface, const Grid& grid) {
  const SpiralSpec& s = instrument.spiral;
  const double pixel = std::min(grid.x_size / static_cast<double>(grid.x_resolution),
                                grid.y_size / static_cast<double>(grid.y_resolution));
  if (s.pitch() > pixel)
    throw InvalidParameter(
        "radial_speed",
        fmt::format("radial_speed = {} m/s is out of range: the spiral's pitch radial_speed/spindle_frequency = {} m "
                    "exceeds the image pixel {} m, so neighbouring turns would not overlap at this resolution; must "
                    "be <= {} m/s (or lower image_resolution)", s.radial_speed, s.pitch(), pixel,
                    pixel * s.spindle_frequency));
  const double inscribed = surface.inscribed_radius();
  if (s.end_radius > inscribed)
    throw InvalidParameter("end_radius",
                           fmt::format("end_radius = {} m is out of range: the sample covers the disc of radius {} m "
                                       "about the spindle axis; must be <= {} m (or give a larger sample)",
                                       s.end_radius, inscribed, inscribed));
}

VirtualScan run_virtual_scan(const InstrumentSpec& instrument, const Surface& surface, const Grid& grid,
                             const VirtualScanOptions& options) {
  instrument.validate();
  check_scan_geometry(instrument, surface, grid);
  const SpiralSpec& spiral = instrument.spiral;

  std::optional<SpiralImager> own;
  if (options.imager) {
    const SpiralImager& given = *options.imager;
    const auto per_turn = static_cast<int>(std::clamp(std::round(spiral.samples_per_turn()), 16.0, 4194304.0));
    const Grid& g = given.grid();
    if (given.samples() != 0 || given.channels() != 4 || given.angular_samples() != per_turn ||
        g.x_resolution != grid.x_resolution || g.y_resolution != grid.y_resolution || g.x_size != grid.x_size ||
        g.y_size != grid.y_size || g.x_offset != grid.x_offset || g.y_offset != grid.y_offset)
      throw std::invalid_argument("run_virtual_scan: options.imager is not scan_imager(instrument, grid) unused");
  } else {
    own.emplace(scan_imager(instrument, grid));
  }
  SpiralImager& imager = options.imager ? *options.imager : *own;
  ImagingObserver imaging(imager);
  std::int64_t turns = 0;
  TurnMetrics metrics(surface.tilt().slope(), [&](const TurnRecord& r) {
    ++turns;
    if (options.on_turn) options.on_turn(r);
  });
  std::vector<ScanObserver*> chain{&imaging, &metrics};
  if (options.extra) chain.push_back(options.extra);
  ObserverChain observers(chain);
  // the imaging, the per-turn metrics and the extra observer run on a second thread, a batch behind the simulation
  // (none of them stops the scan: the samples and the images are those of the direct chain)
  // the uncontrolled comparison (simulated only where it can saturate: uncontrolled_saturation.hpp) needs nothing
  // of the main run: on its own thread beside it (its future waits in its destructor if the main run throws), or
  // after it on this thread when everything runs here (imaging_thread = false)
  std::future<UncontrolledSaturation> uncontrolled;
  if (options.compare_without_control)
    uncontrolled = std::async(options.imaging_thread ? std::launch::async : std::launch::deferred,
                              [&instrument, &surface, &options] {
      return first_uncontrolled_saturation(instrument, surface, options.cancellation);
    });
  ScanRun run;
  if (options.imaging_thread) {
    ObserverThread behind(observers);
    run = simulate_scan(instrument, surface, behind, options.progress, options.cancellation);
    if (behind.finish()) run.stopped_early = true;
  } else {
    run = simulate_scan(instrument, surface, observers, options.progress, options.cancellation);
  }
  std::vector<HeightMap> images = imager.finish();

  const bool inverse = instrument.reconstruction.method == Reconstruction::inverse;
  HeightMap& chosen = images.at(inverse ? kInverseChannel : kLaggedChannel);
  HeightMap& other = images.at(inverse ? kLaggedChannel : kInverseChannel);
  VirtualScan out{run, instrument.reconstruction.method, std::move(images.at(kDeflectionChannel)), std::move(chosen),
                  std::move(other), HeightMap(Grid{}, std::vector<double>{0.0}), 0, 0.0, 0.0, false, 0.0, false, 0.0,
                  false, 0.0, 0.0, 0.0, 0.0, ErrorBudget{}, 0.0};
  out.truth = truth_on(out.topography, surface);
  out.turns = turns;
  out.saturated_fraction =
      run.samples > 0 ? static_cast<double>(run.saturated_samples) / static_cast<double>(run.samples) : 0.0;
  const double r0 = spiral.start_radius;
  out.saturates_with_control = run.saturated_samples > 0;
  out.max_radius_with_control = out.saturates_with_control ? run.first_saturation_radius : spiral.end_radius;

  out.max_radius_without_control = kNaN;
  out.scan_area_gain = kNaN;
  if (options.compare_without_control) {
    const UncontrolledSaturation without = uncontrolled.get();
    out.saturates_without_control = without.saturates;
    out.max_radius_without_control = without.radius;
    if (out.saturates_without_control && out.max_radius_without_control > r0) {
      out.scan_area_gain = annulus(out.max_radius_with_control, r0) / annulus(out.max_radius_without_control, r0);
      out.scan_area_gain_is_lower_bound = !out.saturates_with_control;
    }
  }
  const auto error_of = [&](const HeightMap& image) { return levelled_error(image, out.truth); };
  const HeightMap& lagged = inverse ? out.alternative : out.topography;
  const HeightMap& inverted = inverse ? out.topography : out.alternative;
  // the budget's two image differences (the sampled truth against the truth, the inverse against the sampled truth)
  // on a second thread beside the others (read-only on the same images)
  const HeightMap& sampled_truth = images.at(kSampledTruthChannel);
  std::future<std::pair<double, double>> budget_errors =
      std::async(options.imaging_thread ? std::launch::async : std::launch::deferred, [&] {
        const double imaging = error_of(sampled_truth);
        const double reconstruction = levelled_error(inverted, sampled_truth);
        return std::pair{imaging, reconstruction};
      });
  out.lagged_rms_error = error_of(lagged);
  out.inverse_rms_error = error_of(inverted);
  out.sample_rms_height = kNaN;
  if (out.truth.valid_count() >= 3) {  // the truth minus its least-squares plane, without building that map
    const Plane plane = fit_plane(out.truth);
    const Grid& g = out.truth.grid();
    double sum = 0.0;
    std::size_t n = 0;
    for (long j = 0; j < g.y_resolution; ++j) {
      const double y = g.y_offset + (static_cast<double>(j) + 0.5) * out.truth.dy();
      for (long i = 0; i < g.x_resolution; ++i)
        if (out.truth.valid(i, j)) {
          const double v = out.truth(i, j) - plane(g.x_offset + (static_cast<double>(i) + 0.5) * out.truth.dx(), y);
          sum += v * v;
          ++n;
        }
    }
    out.sample_rms_height = std::sqrt(sum / static_cast<double>(n));
  }
  // the budget of the inverse reconstruction (plant_inverse.hpp)
  const PlantInverse model(instrument.assumed_bandwidth(), spiral.sample_rate);
  ErrorBudget& b = out.budget;
  std::tie(b.imaging, b.reconstruction) = budget_errors.get();
  b.plant_mismatch = instrument.assumed_bandwidth() / instrument.plant.bandwidth - 1.0;
  b.plant = std::abs(instrument.plant.bandwidth / instrument.assumed_bandwidth() - 1.0) * out.lagged_rms_error;
  b.exact_image_noise_gain = model.image_noise_gain();
  b.noise_gain = model.noise_gain();
  b.image_noise_gain = model.image_noise_gain();
  b.cutoff = 0.5 * spiral.sample_rate;
  b.filter_taps = 1;
  if (const std::optional<WienerLowPass> low_pass = noise_aware_filter(instrument, surface)) {  // as simulate_scan
    b.wiener = true;
    b.noise_gain = low_pass->noise_gain();
    b.image_noise_gain = low_pass->image_noise_gain();
    b.prior_increment = low_pass->prior_increment();
    b.cutoff = low_pass->cutoff() * spiral.sample_rate / (2.0 * std::numbers::pi);
    b.filter_taps = 2 * low_pass->half_width() + 1;
    b.resolution = sampled_resolution(instrument, surface, *low_pass);
    b.resolution_prior = low_pass->resolution();
  }
  b.noise = b.image_noise_gain * instrument.detector.noise;
  b.predicted = std::sqrt(b.imaging * b.imaging + b.plant * b.plant + b.noise * b.noise + b.resolution * b.resolution);
  b.pole = model.pole();
  b.settle_samples = model.settle_samples();
  if (out.topography.valid_count() >= 3) {
    out.topography_rms_error = inverse ? out.inverse_rms_error : out.lagged_rms_error;  // computed above
    const HeightMap flat_deflection = level(out.deflection);
    double sum = 0.0;
    std::size_t n = 0;
    for (double v : flat_deflection.data())
      if (std::isfinite(v)) {
        sum += v * v;
        ++n;
      }
    out.deflection_rms = n > 0 ? std::sqrt(sum / static_cast<double>(n)) : kNaN;
  } else {
    out.topography_rms_error = kNaN;
    out.deflection_rms = kNaN;
  }
  return out;
}

}  // namespace afmkit::scan
