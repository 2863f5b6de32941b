// The whole virtual scan: images cover the scanned disc with no holes, the reconstructed topography matches the
// ground truth (evaluated independently on the grid), the controller buys scan area, bad geometry is named.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/levelling.hpp"
#include "afmkit/scan/observer_thread.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/scan/uncontrolled_saturation.hpp"
#include "afmkit/scan/virtual_scan.hpp"

namespace {
using namespace afmkit::scan;

// 50 Hz, 400 samples per turn, 4 mm disc at 20 µm pitch: 200 turns, 80 000 samples.
InstrumentSpec small_scan() {
  InstrumentSpec s;
  s.spiral.sample_rate = 20e3;
  s.spiral.end_radius = 4e-3;
  s.spiral.radial_speed = 1e-3;
  return s;
}

Surface rough_tilted(double half, double tilt_deg) {
  const Grid g{512, 512, 2 * half, 2 * half, -half, -half};
  return Surface(rough(g, RoughSpec{20e-9, 400e-6, 3}), Tilt(tilt_deg * std::numbers::pi / 180, 0.3));
}

TEST(VirtualScan, ImagesCoverTheDiscAndTheReconstructionMatchesTheTruth) {
  InstrumentSpec s = small_scan();
  s.reconstruction.method = Reconstruction::lagged;  // the plant's lag left in (test_plant_inverse.cpp: the inverse)
  const Surface surface = rough_tilted(4.1e-3, 0.05);
  const Grid grid = image_grid(s, 128);
  const VirtualScan v = run_virtual_scan(s, surface, grid);
  // every pixel whose centre lies within r_end − pitch is valid, none beyond r_end + pitch
  long inside = 0, inside_valid = 0, outside_valid = 0;
  for (long j = 0; j < grid.y_resolution; ++j)
    for (long i = 0; i < grid.x_resolution; ++i) {
      const double x = grid.x_offset + (i + 0.5) * v.topography.dx(), y = grid.y_offset + (j + 0.5) * v.topography.dy();
      const double r = std::hypot(x, y);
      if (r < s.spiral.end_radius - s.spiral.pitch()) {
        ++inside;
        inside_valid += v.topography.valid(i, j) && v.deflection.valid(i, j);
      }
      if (r > s.spiral.end_radius + s.spiral.pitch()) outside_valid += v.topography.valid(i, j);
    }
  EXPECT_EQ(inside_valid, inside);
  EXPECT_EQ(outside_valid, 0);
  // the truth image is the surface at the pixel centres (independent evaluation here)
  const long i = 70, j = 40;
  ASSERT_TRUE(v.truth.valid(i, j));
  EXPECT_DOUBLE_EQ(v.truth(i, j), surface(grid.x_offset + (i + 0.5) * v.truth.dx(),
                                          grid.y_offset + (j + 0.5) * v.truth.dy()));
  // reconstruction at 1 kHz plant bandwidth: the plant lags by 1/γ = 0.16 ms, i.e. up to 0.2 mm along the turn at
  // the 1.26 m/s tip speed of the rim — half the correlation length; so the error is a good part of the roughness
  EXPECT_LT(v.topography_rms_error, 0.6 * 20e-9);
  EXPECT_EQ(v.topography_rms_error, levelled_rms_difference(v.topography, v.truth));
  // with a plant 1000 times faster the image is the sample up to the imaging error (interpolation across 20 µm
  // turns and 62.5 µm pixels of a surface correlated over 400 µm: (20/400)² · 20 nm ≈ 0.05 nm; and the sample's own
  // bilinear map at 16 µm pixels)
  InstrumentSpec fast = s;
  fast.plant.bandwidth = 2 * std::numbers::pi * 1e6;
  fast.controller.enabled = false;
  fast.detector.range = 1e-3;
  const VirtualScan w = run_virtual_scan(fast, surface, grid);
  EXPECT_LT(w.topography_rms_error, 0.02 * 20e-9);
  EXPECT_LT(w.topography_rms_error, 0.1 * v.topography_rms_error);
  EXPECT_FALSE(v.saturates_with_control);
  EXPECT_EQ(v.saturated_fraction, 0.0);
  EXPECT_GT(v.turns, 195);
}

TEST(VirtualScan, ControllerBuysScanArea) {
  const InstrumentSpec s = small_scan();
  const Surface surface = rough_tilted(4.1e-3, 0.05);
  const VirtualScan on = run_virtual_scan(s, surface, image_grid(s, 128));
  ASSERT_TRUE(on.saturates_without_control);
  // without control: the steady amplitude r tan ψ γ/√(γ² + Ω²) (± the 20 nm roughness) reaches 2 µm
  const double omega = s.spiral.rotation_frequency(), gamma = s.plant.bandwidth;
  const double predicted = s.detector.range * std::hypot(gamma, omega) / (gamma * surface.tilt().slope());
  EXPECT_NEAR(on.max_radius_without_control, predicted, 0.03 * predicted);
  EXPECT_FALSE(on.saturates_with_control);
  EXPECT_TRUE(on.scan_area_gain_is_lower_bound);
  EXPECT_DOUBLE_EQ(on.scan_area_gain, std::pow(s.spiral.end_radius / on.max_radius_without_control, 2));
  EXPECT_GT(on.scan_area_gain, 2.5);

  InstrumentSpec off = s;
  off.controller.enabled = false;
  const VirtualScan v = run_virtual_scan(off, surface, image_grid(off, 128));
  EXPECT_TRUE(v.saturates_with_control);  // "with control" = as specified (off here)
  EXPECT_NEAR(v.max_radius_with_control, on.max_radius_without_control, 1e-12);
  EXPECT_GT(v.saturated_fraction, 0.1);
  // saturated samples carry no height: fewer valid pixels than the controlled scan
  EXPECT_LT(v.topography.valid_count(), on.topography.valid_count());
}

TEST(VirtualScan, TurnsMustOverlapAtTheImageResolution) {
  InstrumentSpec s = small_scan();
  const Surface surface = rough_tilted(4.1e-3, 0.05);
  // pitch 20 µm; 1024 pixels over 8 mm are 7.8 µm
  try {
    run_virtual_scan(s, surface, image_grid(s, 1024));
    FAIL() << "no error";
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "radial_speed");
    EXPECT_NE(std::string(e.what()).find("<= 0.00039"), std::string::npos) << e.what();
  }
  s.spiral.end_radius = 5e-3;  // beyond the sample
  try {
    run_virtual_scan(s, surface, image_grid(s, 128));
    FAIL() << "no error";
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "end_radius");
  }
  EXPECT_THROW(image_grid(s, 1), afmkit::InvalidParameter);
}

}  // namespace

namespace {
// The uncontrolled comparison run, started where the convex-combination bound lets it saturate, against the full
// run from sample 0: the same first saturated sample (bit-equal radius) in every case, and far fewer samples.
InstrumentSpec uncontrolled_case(double sample_rate, double radial_speed, double start_radius) {
  InstrumentSpec s;
  s.spiral.sample_rate = sample_rate;
  s.spiral.end_radius = 4e-3;
  s.spiral.start_radius = start_radius;
  s.spiral.radial_speed = radial_speed;
  return s;
}
}  // namespace

TEST(UncontrolledSaturation, SkippedRunFindsTheFullRunsFirstSaturatedSample) {
  const Surface rough_surface = rough_tilted(4.1e-3, 0.05);
  const Grid g{256, 256, 8.2e-3, 8.2e-3, -4.1e-3, -4.1e-3};
  const Surface grating_surface(grating(g, GratingSpec{800e-6, 50e-9, 0.5, 0.0}), Tilt(0.05 * std::numbers::pi / 180, 2.0));
  const Surface steep(flat(g), Tilt(0.1 * std::numbers::pi / 180, -1.0));     // saturates early (r ≈ 1.15 mm)
  const Surface gentle(flat(g), Tilt(0.02 * std::numbers::pi / 180, 0.0));    // never saturates within 4 mm
  struct Case {
    const Surface* surface;
    InstrumentSpec spec;
  };
  InstrumentSpec slow_plant = uncontrolled_case(20e3, 1e-3, 0.0);
  slow_plant.plant.bandwidth = 2 * std::numbers::pi * 200;  // a longer memory: the settling stretch grows
  for (const Case& c : {Case{&rough_surface, uncontrolled_case(20e3, 1e-3, 0.0)},
                        Case{&grating_surface, uncontrolled_case(50e3, 2e-3, 0.5e-3)},
                        Case{&steep, uncontrolled_case(20e3, 1e-3, 0.0)},
                        Case{&gentle, uncontrolled_case(20e3, 1e-3, 0.0)}, Case{&rough_surface, slow_plant}}) {
    const UncontrolledSaturation fast = first_uncontrolled_saturation(c.spec, *c.surface);
    const UncontrolledSaturation full = first_uncontrolled_saturation_full(c.spec, *c.surface);
    EXPECT_EQ(fast.saturates, full.saturates);
    EXPECT_EQ(fast.radius, full.radius);  // the same sample: bit-equal
    if (fast.samples > 0) EXPECT_EQ(fast.first_sample % 4096, 0);  // where the tip angle is exact
    if (full.saturates) {
      EXPECT_LT(fast.samples, full.samples);
    } else {
      EXPECT_EQ(fast.samples, 0);  // nothing simulated: the bound holds to the end
    }
  }
  // the steep tilt saturates where the steady first harmonic r tan ψ γ/√(γ² + Ω²) reaches R_d (independent check
  // that the case exercises a saturation); the rough one starts late in the scan
  EXPECT_TRUE(first_uncontrolled_saturation(uncontrolled_case(20e3, 1e-3, 0.0), steep).saturates);
  EXPECT_GT(first_uncontrolled_saturation(uncontrolled_case(20e3, 1e-3, 0.0), rough_surface).first_sample, 0);
}

TEST(UncontrolledSaturation, NoisyDetectorRunsFromTheStart) {
  InstrumentSpec s = uncontrolled_case(20e3, 1e-3, 0.0);
  s.detector.noise = 1e-9;
  const Surface surface = rough_tilted(4.1e-3, 0.05);
  const UncontrolledSaturation fast = first_uncontrolled_saturation(s, surface);
  EXPECT_EQ(fast.first_sample, 0);
  EXPECT_EQ(fast.radius, first_uncontrolled_saturation_full(s, surface).radius);
}

namespace {
// Records the sample indices it sees; stops or throws at a chosen index.
struct IndexRecorder final : ScanObserver {
  std::vector<std::int64_t> seen;
  std::int64_t stop_at = -1, throw_at = -1;
  bool sample(const ScanSample& s) override {
    if (s.index == throw_at) throw std::runtime_error("observer failed");
    seen.push_back(s.index);
    return s.index != stop_at;
  }
};
ScanSample sample_numbered(std::int64_t n) { return ScanSample{n, 0, 0, 0, 0, 0, 0, 0, 0, 0, false}; }
}  // namespace

TEST(ObserverThread, SeesEverySampleInOrderAndStopsOrRethrowsLikeTheObserver) {
  IndexRecorder all;
  {
    ObserverThread behind(all, 7);
    for (std::int64_t n = 0; n < 1000; ++n) ASSERT_TRUE(behind.sample(sample_numbered(n)));
    EXPECT_FALSE(behind.finish());
  }
  ASSERT_EQ(all.seen.size(), 1000U);
  for (std::int64_t n = 0; n < 1000; ++n) EXPECT_EQ(all.seen[static_cast<std::size_t>(n)], n);

  IndexRecorder stopping;
  stopping.stop_at = 100;
  ObserverThread behind(stopping, 8);
  std::int64_t handed = 0;
  while (handed < 100000 && behind.sample(sample_numbered(handed))) ++handed;
  EXPECT_TRUE(behind.finish());
  EXPECT_EQ(stopping.seen.back(), 100);  // nothing after the stop reaches the observer
  EXPECT_LT(handed, 100 + 4 * 8 + 8);    // the caller is told within a few batches

  IndexRecorder failing;
  failing.throw_at = 50;
  ObserverThread failing_behind(failing, 8);
  for (std::int64_t n = 0; n < 200 && failing_behind.sample(sample_numbered(n)); ++n) {
  }
  EXPECT_THROW(failing_behind.finish(), std::runtime_error);
  EXPECT_EQ(failing.seen.size(), 50U);
}

namespace {
// The imaging floor against the sampling (issue 27 §5): an ideal instrument (no noise, the plant known) whose
// reconstruction is exact, on a 0.8 mm disc, 50 Hz spindle, 4 µm pitch, imaged to 128² (12.5 µm pixels).
InstrumentSpec floor_scan(double sample_rate) {
  InstrumentSpec s;
  s.spiral.sample_rate = sample_rate;
  s.spiral.end_radius = 0.8e-3;
  s.spiral.radial_speed = 200e-6;
  return s;
}
const Grid& floor_map_grid() {
  static const Grid g{256, 256, 1.64e-3, 1.64e-3, -0.82e-3, -0.82e-3};  // 6.4 µm pixels
  return g;
}
}  // namespace

TEST(ImagingFloor, SharpEdgesCostTheStraightEdgeEstimateAndFallWithDenserSampling) {
  // grating lines along y, period P = 160 µm, H = 50 nm: each edge crossed by a turn becomes, by the linear
  // interpolation along the turn, a ramp over one sample step w = Δθ |y| (projected on x), mean squared error H²/6
  // over it; summed over the edges (density 2/P) and the disc: MSE = (4 / 9π) H² Δθ R / P — an estimate for steps
  // (the truth's own ramps, one map pixel wide, lower it)
  const double period = 160e-6, height = 50e-9;
  const Surface surface(grating(floor_map_grid(), GratingSpec{period, height, 0.5, 0.0}), Tilt(0.0, 0.0));
  double floors[2];
  int k = 0;
  for (const double rate : {10e3, 40e3}) {  // 200 and 800 samples per turn: 25 and 6.3 µm apart at the rim
    const InstrumentSpec s = floor_scan(rate);
    const VirtualScan v = run_virtual_scan(s, surface, image_grid(s, 128));
    EXPECT_LT(v.budget.reconstruction, 1e-9 * v.sample_rms_height);  // the instrument adds nothing
    EXPECT_NEAR(v.inverse_rms_error, v.budget.imaging, 1e-9 * v.sample_rms_height);
    const double dtheta = 2 * std::numbers::pi / (rate / s.spiral.spindle_frequency);
    const double estimate = height * std::sqrt(4.0 / (9.0 * std::numbers::pi) * dtheta * s.spiral.end_radius / period);
    if (k == 0) {  // steps 25 µm apart against 6.4 µm ramps: near the estimate, below it
      EXPECT_LT(v.budget.imaging, estimate);
      EXPECT_GT(v.budget.imaging, 0.4 * estimate);
    }
    floors[k++] = v.budget.imaging;
  }
  EXPECT_GT(floors[0] / floors[1], 1.8);  // 4× denser: at least the √4 of steps
}

TEST(ImagingFloor, ASmoothSampleFallsAsTheSquareOfTheAngularStep) {
  // correlation length 300 µm: the header's bound (Δθ² + Δφ²) K / 8 dominates the pitch term p² H / 8, so the floor
  // falls about 16× for 4× the samples per turn
  const Surface surface(rough(floor_map_grid(), RoughSpec{20e-9, 300e-6, 5}), Tilt(0.0, 0.0));
  double floors[2];
  int k = 0;
  for (const double rate : {10e3, 40e3}) {
    const InstrumentSpec s = floor_scan(rate);
    const VirtualScan v = run_virtual_scan(s, surface, image_grid(s, 128));
    EXPECT_LT(v.budget.reconstruction, 1e-9 * v.sample_rms_height);
    floors[k++] = v.budget.imaging;
  }
  EXPECT_GT(floors[0] / floors[1], 8.0);
  EXPECT_LT(floors[0] / floors[1], 20.0);
}

TEST(VirtualScanPreparedImager, AnImagerBuiltAheadGivesTheSameScanAndAWrongOneIsRefused) {
  const InstrumentSpec s = small_scan();
  const Surface surface = rough_tilted(4.1e-3, 0.05);
  const Grid grid = image_grid(s, 48);
  const VirtualScan here = run_virtual_scan(s, surface, grid);
  SpiralImager ahead = scan_imager(s, grid);
  VirtualScanOptions given;
  given.imager = &ahead;
  const VirtualScan there = run_virtual_scan(s, surface, grid, given);
  ASSERT_EQ(here.topography.size(), there.topography.size());
  for (std::size_t k = 0; k < here.topography.size(); ++k)
    if (std::isfinite(here.topography.data()[k]) || std::isfinite(there.topography.data()[k]))
      ASSERT_EQ(here.topography.data()[k], there.topography.data()[k]) << k;
  EXPECT_EQ(here.inverse_rms_error, there.inverse_rms_error);
  EXPECT_EQ(here.budget.imaging, there.budget.imaging);
  // spent (it has seen the samples), another grid, another table size: refused
  EXPECT_THROW(run_virtual_scan(s, surface, grid, given), std::invalid_argument);
  SpiralImager other_grid = scan_imager(s, image_grid(s, 32));
  given.imager = &other_grid;
  EXPECT_THROW(run_virtual_scan(s, surface, grid, given), std::invalid_argument);
  InstrumentSpec denser = s;
  denser.spiral.sample_rate *= 2;
  SpiralImager other_table = scan_imager(denser, grid);
  given.imager = &other_table;
  EXPECT_THROW(run_virtual_scan(s, surface, grid, given), std::invalid_argument);
}

TEST(ObserverThread, TheScanImagedOnASecondThreadIsTheScanImagedDirectly) {
  const InstrumentSpec s = small_scan();
  const Surface surface = rough_tilted(4.1e-3, 0.05);
  VirtualScanOptions direct;
  direct.imaging_thread = false;
  std::vector<double> turns_direct, turns_threaded;
  direct.on_turn = [&](const TurnRecord& r) { turns_direct.push_back(r.deflection_first_harmonic); };
  VirtualScanOptions threaded;
  threaded.on_turn = [&](const TurnRecord& r) { turns_threaded.push_back(r.deflection_first_harmonic); };
  const VirtualScan a = run_virtual_scan(s, surface, image_grid(s, 64), direct);
  const VirtualScan b = run_virtual_scan(s, surface, image_grid(s, 64), threaded);
  EXPECT_EQ(turns_direct, turns_threaded);
  EXPECT_EQ(a.topography.data().size(), b.topography.data().size());
  for (std::size_t k = 0; k < a.topography.size(); ++k)
    if (std::isfinite(a.topography.data()[k]) || std::isfinite(b.topography.data()[k]))
      ASSERT_EQ(a.topography.data()[k], b.topography.data()[k]) << k;
  EXPECT_EQ(a.topography_rms_error, b.topography_rms_error);
  EXPECT_EQ(a.run.samples, b.run.samples);
}
