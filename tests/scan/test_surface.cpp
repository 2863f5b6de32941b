// Surface (topography + tilt anywhere in the map frame) and Tilt, checked against hand bilinear interpolation,
// planes (on which bilinear interpolation is exact) and plane fits of sampled surfaces.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/levelling.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/scan/surface.hpp"
#include "scan_test_dir.hpp"

using afmkit::InvalidParameter;
using namespace afmkit::scan;

namespace {

using scan_test::rejected;

// Values of f at the pixel centres of `grid`.
template <class F>
HeightMap sampled(const Grid& grid, F&& f) {
  std::vector<double> data;
  const double dx = grid.x_size / static_cast<double>(grid.x_resolution);
  const double dy = grid.y_size / static_cast<double>(grid.y_resolution);
  for (long j = 0; j < grid.y_resolution; ++j)
    for (long i = 0; i < grid.x_resolution; ++i)
      data.push_back(f(grid.x_offset + (i + 0.5) * dx, grid.y_offset + (j + 0.5) * dy));
  return HeightMap(grid, std::move(data));
}

}  // namespace

TEST(Tilt, ValidatesAngleAndAzimuth) {
  EXPECT_EQ(rejected([] { Tilt(-0.01, 0.0); }), "tilt_angle");
  EXPECT_EQ(rejected([] { Tilt(std::numbers::pi / 2, 0.0); }), "tilt_angle");
  EXPECT_EQ(rejected([] { Tilt(NAN, 0.0); }), "tilt_angle");
  EXPECT_EQ(rejected([] { Tilt(INFINITY, 0.0); }), "tilt_angle");
  EXPECT_EQ(rejected([] { Tilt(0.1, NAN); }), "tilt_azimuth");
  EXPECT_EQ(rejected([] { Tilt(0.1, -INFINITY); }), "tilt_azimuth");
  EXPECT_EQ(rejected([] { Tilt(std::nextafter(std::numbers::pi / 2, 0.0), -7.0); }), "(accepted)");
  try {
    Tilt(2.0, 0.0);
  } catch (const InvalidParameter& e) {
    EXPECT_NE(std::string(e.what()).find("[0, 90) degrees"), std::string::npos) << e.what();
  }
}

TEST(Tilt, RisesByTanPsiPerMetreAlongTheAzimuthAndIsLevelAcrossIt) {
  const double psi = 0.2, phi = 2.3, rho = 3e-6;
  const Tilt tilt(psi, phi);
  EXPECT_DOUBLE_EQ(tilt.slope(), std::tan(psi));
  // Along the azimuth the height grows by rho · tan ψ; perpendicular to it the plane is level.
  EXPECT_NEAR(tilt.height(rho * std::cos(phi), rho * std::sin(phi)), rho * std::tan(psi), 1e-15 * rho);
  EXPECT_NEAR(tilt.height(-rho * std::sin(phi), rho * std::cos(phi)), 0.0, 1e-15 * rho);
  EXPECT_EQ(Tilt().height(1.0, 2.0), 0.0);
}

TEST(Surface, RejectsInvalidPixelsAndNonHeightUnits) {
  const Grid g{2, 2, 1e-6, 1e-6};
  EXPECT_EQ(rejected([&] { Surface(HeightMap(g, {1, 2, 3, 4}, "m", {1, 1, 0, 1}), Tilt()); }), "sample");
  EXPECT_EQ(rejected([&] { Surface(HeightMap(g, {1, 2, 3, 4}, "V"), Tilt()); }), "sample");
  EXPECT_EQ(rejected([&] { Surface(HeightMap(g, {1, 2, 3, 4}, "m", {1, 1, 1, 1}), Tilt()); }), "(accepted)");
  Tilt bad;  // fields set directly bypass Tilt's constructor: Surface validates again
  bad.angle = 1.6;
  EXPECT_EQ(rejected([&] { Surface(HeightMap(g, {1, 2, 3, 4}), bad); }), "tilt_angle");
  bad.angle = 0.1;
  bad.azimuth = NAN;
  EXPECT_EQ(rejected([&] { Surface(HeightMap(g, {1, 2, 3, 4}), bad); }), "tilt_azimuth");
}

TEST(Surface, BilinearMatchesHandInterpolationAtAPoint) {
  // 3 columns × 2 rows, dx = 1 µm, dy = 2 µm, left edge at x = −1 µm, top edge at y = 4 µm.
  // Pixel centres: x = −0.5, 0.5, 1.5 µm; y = 5, 7 µm.
  const HeightMap m(Grid{3, 2, 3e-6, 4e-6, -1e-6, 4e-6}, {1e-9, 4e-9, -2e-9, 7e-9, 3e-9, 5e-9});
  const Surface s(m, Tilt());
  // x = 0.8 µm lies 30 % of the way from column 1 (0.5 µm) to column 2 (1.5 µm);
  // y = 6.2 µm lies 60 % of the way from row 0 (5 µm) to row 1 (7 µm).
  const double t = 0.3, u = 0.6;
  const double expected = (1 - t) * (1 - u) * 4e-9 + t * (1 - u) * -2e-9 + (1 - t) * u * 3e-9 + t * u * 5e-9;
  EXPECT_NEAR(s.topography(0.8e-6, 6.2e-6), expected, 1e-15 * 1e-8);
  EXPECT_NEAR(s(0.8e-6, 6.2e-6), expected, 1e-15 * 1e-8);  // no tilt
  // At pixel centres the pixel values (to the rounding of the centre coordinates).
  EXPECT_NEAR(s.topography(-0.5e-6, 5e-6), 1e-9, 1e-14 * 1e-8);
  EXPECT_NEAR(s.topography(1.5e-6, 7e-6), 5e-9, 1e-14 * 1e-8);
  EXPECT_NEAR(s.topography(0.5e-6, 7e-6), 3e-9, 1e-14 * 1e-8);
}

TEST(Surface, OutsideThePixelCentresTheNearestEdgeValueIsUsed) {
  const HeightMap m(Grid{3, 2, 3e-6, 4e-6, -1e-6, 4e-6}, {1e-9, 4e-9, -2e-9, 7e-9, 3e-9, 5e-9});
  const Surface s(m, Tilt());
  // Beyond the corners: the corner values.
  EXPECT_EQ(s.topography(-1e-3, -1e-3), 1e-9);
  EXPECT_EQ(s.topography(1e-3, -1e-3), -2e-9);
  EXPECT_EQ(s.topography(-1e-3, 1e-3), 7e-9);
  EXPECT_EQ(s.topography(1e-3, 1e-3), 5e-9);
  EXPECT_EQ(s.topography(-INFINITY, INFINITY), 7e-9);
  EXPECT_EQ(s.topography(NAN, NAN), 1e-9);  // documented: NaN is treated as the first centre
  // Left of the map at y = 6.5 µm (75 % from row 0 to row 1): linear in y along column 0.
  EXPECT_NEAR(s.topography(-0.8e-6, 6.5e-6), 0.25 * 1e-9 + 0.75 * 7e-9, 1e-24);
  // Below the map (y beyond the last row centre) at x = 1 µm, halfway between columns 1 and 2 of row 1.
  EXPECT_NEAR(s.topography(1e-6, 7.9e-6), 0.5 * (3e-9 + 5e-9), 1e-24);
}

TEST(Surface, BilinearIsExactOnPlanesWithTiltAddedExactly) {
  // Non-square pixels, off-centre grid; a plane topography, a tilt. Random points inside the centre rectangle and
  // outside it (where the clamped plane value applies).
  const Grid g{17, 11, 8e-6, 5e-6, -3e-6, -1.5e-6};
  const Plane plane{2e-9, 3e-3, -1.5e-3};
  const HeightMap m = sampled(g, plane);
  const Tilt tilt(0.05, 1.1);
  const Surface s(m, tilt);
  const double dx = g.x_size / 17, dy = g.y_size / 11;
  const double x_lo = g.x_offset + 0.5 * dx, x_hi = g.x_offset + 16.5 * dx;
  const double y_lo = g.y_offset + 0.5 * dy, y_hi = g.y_offset + 10.5 * dy;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ux(g.x_offset - 2e-6, g.x_offset + g.x_size + 2e-6);
  std::uniform_real_distribution<double> uy(g.y_offset - 2e-6, g.y_offset + g.y_size + 2e-6);
  for (int n = 0; n < 2000; ++n) {
    const double x = ux(rng), y = uy(rng);
    const double cx = std::clamp(x, x_lo, x_hi), cy = std::clamp(y, y_lo, y_hi);
    EXPECT_NEAR(s.topography(x, y), plane(cx, cy), 1e-14 * 1e-8) << x << ", " << y;
    EXPECT_NEAR(s(x, y), plane(cx, cy) + tilt.height(x, y), 1e-14 * 1e-6) << x << ", " << y;  // tilt ~ 0.05 · 10 µm
  }
}

TEST(Surface, SingleRowOrColumnMapsInterpolateAlongTheOtherAxis) {
  const Surface point(HeightMap(Grid{1, 1, 1e-6, 1e-6, -0.5e-6, -0.5e-6}, {3e-9}), Tilt());
  EXPECT_EQ(point.topography(0.3e-6, -7e-6), 3e-9);
  EXPECT_EQ(point.topography(0.0, 0.0), 3e-9);
  // One column, three rows at y = 0.5, 1.5, 2.5 µm.
  const Surface column(HeightMap(Grid{1, 3, 1e-6, 3e-6}, {0.0, 2e-9, 6e-9}), Tilt());
  EXPECT_NEAR(column.topography(5e-6, 2.0e-6), 4e-9, 1e-24);
  EXPECT_NEAR(column.topography(-5e-6, 1.0e-6), 1e-9, 1e-24);
  // One row, three columns.
  const Surface row(HeightMap(Grid{3, 1, 3e-6, 1e-6}, {0.0, 2e-9, 6e-9}), Tilt());
  EXPECT_NEAR(row.topography(2.25e-6, 9.0), 5e-9, 1e-24);
}

TEST(Surface, TiltIsRecoveredByAPlaneFitOfTheSampledSurface) {
  // A rough topography plus tilt, sampled at the map's own pixel centres: the plane fit is linear, so the fitted
  // plane of the samples minus that of the topography is the tilt plane tan ψ (x cos φ + y sin φ).
  const Grid g{96, 80, 12e-6, 10e-6, -6e-6, -5e-6};
  const HeightMap topography = rough(g, RoughSpec{4e-9, 1e-6, 3});
  const double psi = 0.03, phi = -2.0;
  const Surface s(topography, Tilt(psi, phi));
  const HeightMap scanned = sampled(g, [&](double x, double y) { return s(x, y); });
  const Plane with_tilt = fit_plane(scanned);
  const Plane without = fit_plane(topography);
  const double slope = std::tan(psi);
  EXPECT_NEAR(with_tilt.b - without.b, slope * std::cos(phi), 1e-12 * slope);
  EXPECT_NEAR(with_tilt.c - without.c, slope * std::sin(phi), 1e-12 * slope);
  // A flat sample: the fitted plane's normal leans by ψ from the spindle axis; the plane rises towards φ.
  const Surface tilted_flat(flat(Grid{40, 30, 4e-6, 3e-6, -1e-6, -2e-6}), Tilt(psi, phi));
  const Plane p = fit_plane(sampled(Grid{23, 19, 9e-6, 7e-6, -5e-6, -4e-6}, tilted_flat));
  EXPECT_NEAR(std::atan(std::hypot(p.b, p.c)), psi, 1e-12 * psi);
  EXPECT_NEAR(std::atan2(p.c, p.b), phi, 1e-12);
  EXPECT_NEAR(p.a, 0.0, 1e-12 * slope * 1e-6);
}

TEST(Surface, InscribedRadiusOfTheCentreRectangle) {
  // Centred 21 × 11 grid, dx = dy = 1 µm: centres span ±10 µm in x and ±5 µm in y.
  EXPECT_NEAR(Surface(flat(Grid{21, 11, 21e-6, 11e-6, -10.5e-6, -5.5e-6}), Tilt()).inscribed_radius(), 5e-6, 1e-18);
  // Off-centre: centres span x in [−2, 17] µm, y in [−9, 4] µm: nearest side is x = −2 µm.
  EXPECT_NEAR(Surface(flat(Grid{20, 14, 20e-6, 14e-6, -2.5e-6, -9.5e-6}), Tilt()).inscribed_radius(), 2e-6, 1e-18);
  // Origin outside the centre rectangle (x in [1, 10] µm): 0.
  EXPECT_EQ(Surface(flat(Grid{10, 10, 10e-6, 10e-6, 0.5e-6, -5e-6}), Tilt()).inscribed_radius(), 0.0);
}

TEST(Surface, AccessorsCopiesAndMovesKeepTheValues) {
  const HeightMap m(Grid{3, 2, 3e-6, 4e-6, -1e-6, 4e-6}, {1e-9, 4e-9, -2e-9, 7e-9, 3e-9, 5e-9});
  const Tilt tilt(0.1, 0.4);
  auto original = std::make_unique<Surface>(m, tilt);
  const double expected = (*original)(0.8e-6, 6.2e-6);
  const Surface copy = *original;
  Surface moved = std::move(*original);
  original.reset();  // the copy must not refer to the original's storage
  EXPECT_EQ(copy(0.8e-6, 6.2e-6), expected);
  EXPECT_EQ(moved(0.8e-6, 6.2e-6), expected);
  EXPECT_EQ(copy.tilt().angle, 0.1);
  EXPECT_EQ(copy.tilt().azimuth, 0.4);
  EXPECT_EQ(copy.map().data(), m.data());
  const HeightMap taken = Surface(m, tilt).map();
  EXPECT_EQ(taken.data(), m.data());
}
