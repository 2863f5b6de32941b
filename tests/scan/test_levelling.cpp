// Plane fit / subtraction and the levelled RMS difference, checked against exact planes plus patterns orthogonal to
// every plane, and against an independent least-squares solve (Eigen's QR on the design matrix in metres).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Dense>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/levelling.hpp"
#include "scan_test_dir.hpp"

using afmkit::InvalidParameter;
using namespace afmkit::scan;

namespace {

using scan_test::rejected;

double centre_x(const Grid& g, long i) { return g.x_offset + (i + 0.5) * g.x_size / static_cast<double>(g.x_resolution); }
double centre_y(const Grid& g, long j) { return g.y_offset + (j + 0.5) * g.y_size / static_cast<double>(g.y_resolution); }

// f(i, j, x, y) at every pixel; mask(i, j) false = invalid.
template <class F, class M>
HeightMap make_map(const Grid& g, F&& f, M&& mask) {
  std::vector<double> data;
  std::vector<std::uint8_t> valid;
  for (long j = 0; j < g.y_resolution; ++j)
    for (long i = 0; i < g.x_resolution; ++i) {
      data.push_back(f(i, j, centre_x(g, i), centre_y(g, j)));
      valid.push_back(mask(i, j) ? 1 : 0);
    }
  return HeightMap(g, std::move(data), "m", std::move(valid));
}
const auto everywhere = [](long, long) { return true; };

// Independent least squares: QR of the design matrix [1 x y] (metres, columns scaled to unit size) over the pixels
// where use(i, j) holds.
template <class Use>
Plane eigen_fit(const HeightMap& m, Use&& use) {
  std::vector<Eigen::Vector3d> rows;
  std::vector<double> values;
  const double sx = m.x_size(), sy = m.y_size();
  for (long j = 0; j < m.y_resolution(); ++j)
    for (long i = 0; i < m.x_resolution(); ++i)
      if (use(i, j)) {
        rows.emplace_back(1.0, centre_x(m.grid(), i) / sx, centre_y(m.grid(), j) / sy);
        values.push_back(m(i, j));
      }
  Eigen::MatrixXd design(static_cast<Eigen::Index>(rows.size()), 3);
  Eigen::VectorXd rhs(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    design.row(static_cast<Eigen::Index>(k)) = rows[k].transpose();
    rhs(static_cast<Eigen::Index>(k)) = values[k];
  }
  const Eigen::Vector3d solution = design.colPivHouseholderQr().solve(rhs);
  return Plane{solution(0), solution(1) / sx, solution(2) / sy};
}

}  // namespace

TEST(FitPlane, RecoversAPlaneUnderAZeroMeanPatternSymmetricAboutTheCentre) {
  // 41 × 31 pixels (odd: the centre is a pixel), off-centre offsets, non-square pixels. The pattern is even in
  // (i − 20) and in (j − 15) and has zero mean over the grid, hence orthogonal to 1, x and y: the least-squares
  // plane of plane + pattern is the plane itself.
  const Grid g{41, 31, 8e-6, 9e-6, 3e-6, -20e-6};
  const Plane truth{5e-9, -2e-3, 7e-4};
  double pattern_mean = 0;
  const auto raw = [](long i, long j) {
    const double di = i - 20.0, dj = j - 15.0;
    return 1e-9 * (di * di - 0.3 * dj * dj + std::cos(0.7 * di) * std::cos(0.4 * dj));
  };
  for (long j = 0; j < 31; ++j)
    for (long i = 0; i < 41; ++i) pattern_mean += raw(i, j) / (41.0 * 31.0);
  const HeightMap m = make_map(
      g, [&](long i, long j, double x, double y) { return truth(x, y) + raw(i, j) - pattern_mean; }, everywhere);
  const Plane p = fit_plane(m);
  const double slope_scale = 2e-3, height_scale = 2e-3 * 30e-6;
  EXPECT_NEAR(p.b, truth.b, 1e-12 * slope_scale);
  EXPECT_NEAR(p.c, truth.c, 1e-12 * slope_scale);
  EXPECT_NEAR(p.a, truth.a, 1e-12 * height_scale);
}

TEST(FitPlane, UsesOnlyValidPixelsAndAgreesWithAnIndependentSolve) {
  const Grid g{50, 40, 5e-6, 4e-6, -2.5e-6, -2e-6};
  // An exact plane on a disc of valid pixels (the rest invalid): recovered to rounding.
  const Plane truth{-3e-9, 4e-4, 1e-3};
  const auto disc = [](long i, long j) { return std::hypot(i - 24.5, j - 19.5) < 15.0; };
  const HeightMap on_disc = make_map(g, [&](long, long, double x, double y) { return truth(x, y); }, disc);
  const Plane p = fit_plane(on_disc);
  EXPECT_NEAR(p.b, truth.b, 1e-12 * 1e-3);
  EXPECT_NEAR(p.c, truth.c, 1e-12 * 1e-3);
  EXPECT_NEAR(p.a, truth.a, 1e-12 * 1e-3 * 5e-6);
  // Random heights, random mask: the same plane as Eigen's QR least squares.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 1e-9);
  std::vector<std::uint8_t> mask_bits;
  for (int k = 0; k < 2000; ++k) mask_bits.push_back(rng() % 3 != 0);
  const auto random_mask = [&](long i, long j) { return mask_bits[static_cast<std::size_t>(j * 50 + i)] != 0; };
  const HeightMap random_map =
      make_map(g, [&](long, long, double x, double y) { return truth(x, y) + noise(rng); }, random_mask);
  const Plane q = fit_plane(random_map);
  const Plane r = eigen_fit(random_map, random_mask);
  EXPECT_NEAR(q.b, r.b, 1e-10 * std::abs(r.b));
  EXPECT_NEAR(q.c, r.c, 1e-10 * std::abs(r.c));
  EXPECT_NEAR(q.a, r.a, 1e-10 * 1e-9);
}

TEST(FitPlane, NeedsThreePixelsNotOnALine) {
  const Grid g{4, 3, 4e-6, 3e-6};
  const auto ramp = [](long i, long j, double, double) { return 1e-9 * (i + 2.0 * j); };
  EXPECT_EQ(rejected([&] { fit_plane(make_map(g, ramp, [](long i, long j) { return j == 0 && i < 2; })); }), "map");
  EXPECT_EQ(rejected([&] { fit_plane(make_map(g, ramp, [](long, long j) { return j == 1; })); }), "map");   // a row
  EXPECT_EQ(rejected([&] { fit_plane(make_map(g, ramp, [](long i, long) { return i == 2; })); }), "map");   // a column
  EXPECT_EQ(rejected([&] { fit_plane(make_map(g, ramp, [](long i, long j) { return i == j; })); }), "map");  // diagonal
  EXPECT_EQ(rejected([&] { fit_plane(HeightMap(Grid{5, 1, 5e-6, 1e-6}, {1, 2, 3, 4, 5})); }), "map");  // one row
  // Three pixels in an L: the plane through them.
  const Plane p = fit_plane(make_map(g, ramp, [](long i, long j) { return (i == 0 && j < 2) || (i == 1 && j == 0); }));
  EXPECT_NEAR(p.b, 1e-9 / 1e-6, 1e-15);
  EXPECT_NEAR(p.c, 2e-9 / 1e-6, 1e-15);
}

TEST(SubtractPlane, KeepsInvalidPixelsAndSubtractsAtPixelCentres) {
  const Grid g{5, 4, 5e-6, 8e-6, -1e-6, 2e-6};
  const HeightMap m = make_map(
      g, [](long i, long j, double, double) { return 1e-9 * (i * i + j); }, [](long i, long j) { return i != 3 || j != 2; });
  const Plane plane{1e-9, 2e-4, -3e-4};
  const HeightMap d = subtract_plane(m, plane);
  EXPECT_EQ(d.mask(), m.mask());
  EXPECT_EQ(d.z_unit(), "m");
  EXPECT_TRUE(std::isnan(d(3, 2)));
  // Pixel (4, 1): centre x = −1 + 4.5 = 3.5 µm, y = 2 + 1.5·2 = 5 µm.
  EXPECT_NEAR(d(4, 1), 17e-9 - (1e-9 + 2e-4 * 3.5e-6 - 3e-4 * 5e-6), 1e-22);
  // Levelled: the residual's own plane fit is zero.
  const Plane residual = fit_plane(level(m));
  EXPECT_NEAR(residual.a, 0.0, 1e-21);
  EXPECT_NEAR(residual.b, 0.0, 1e-15);
  EXPECT_NEAR(residual.c, 0.0, 1e-15);
}

TEST(LevelledRmsDifference, IgnoresPlanesAndMeasuresWhatRemains) {
  const Grid g{41, 31, 8e-6, 6e-6, -4e-6, -3e-6};
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 2e-9);
  std::vector<double> truth_values;
  for (int k = 0; k < 41 * 31; ++k) truth_values.push_back(noise(rng));
  const HeightMap truth(g, truth_values);
  // truth + any plane: difference 0 (to rounding).
  const Plane tilt{3e-8, 1e-2, -4e-3};
  const HeightMap tilted = make_map(
      g, [&](long i, long j, double x, double y) { return truth_values[static_cast<std::size_t>(j * 41 + i)] + tilt(x, y); },
      everywhere);
  EXPECT_NEAR(levelled_rms_difference(tilted, truth), 0.0, 1e-12 * 1e-2 * 8e-6);
  // truth + plane + a zero-mean pattern even about the centre pixel (orthogonal to every plane): its RMS.
  const auto raw = [](long i, long j) { return 1e-9 * std::cos(0.5 * (i - 20.0)) * std::cos(0.3 * (j - 15.0)); };
  double mean = 0, mean_square = 0;
  for (long j = 0; j < 31; ++j)
    for (long i = 0; i < 41; ++i) mean += raw(i, j) / (41.0 * 31.0);
  for (long j = 0; j < 31; ++j)
    for (long i = 0; i < 41; ++i) mean_square += (raw(i, j) - mean) * (raw(i, j) - mean) / (41.0 * 31.0);
  const HeightMap patterned = make_map(
      g,
      [&](long i, long j, double x, double y) {
        return truth_values[static_cast<std::size_t>(j * 41 + i)] + tilt(x, y) + raw(i, j) - mean;
      },
      everywhere);
  EXPECT_NEAR(levelled_rms_difference(patterned, truth), std::sqrt(mean_square), 1e-10 * std::sqrt(mean_square));
}

TEST(LevelledRmsDifference, UsesThePixelsValidInBothAndEqualsTheResidualOfTheDifference) {
  // Masks on both maps; the result must equal the RMS residual of an independent least-squares plane fit of
  // (image − truth) over the common pixels (the fit is linear).
  const Grid g{30, 20, 3e-6, 2e-6, -1.5e-6, -1e-6};
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1e-9);
  std::vector<std::uint8_t> mask_a, mask_b;
  for (int k = 0; k < 600; ++k) {
    mask_a.push_back(rng() % 4 != 0);
    mask_b.push_back(rng() % 4 != 0);
  }
  const auto in_a = [&](long i, long j) { return mask_a[static_cast<std::size_t>(j * 30 + i)] != 0; };
  const auto in_b = [&](long i, long j) { return mask_b[static_cast<std::size_t>(j * 30 + i)] != 0; };
  const auto common = [&](long i, long j) { return in_a(i, j) && in_b(i, j); };
  const HeightMap image = make_map(g, [&](long, long, double x, double) { return 1e-3 * x + noise(rng); }, in_a);
  const HeightMap truth = make_map(g, [&](long, long, double, double y) { return 2e-3 * y + noise(rng); }, in_b);
  std::vector<double> difference;
  for (long j = 0; j < 20; ++j)
    for (long i = 0; i < 30; ++i) difference.push_back(common(i, j) ? image(i, j) - truth(i, j) : 0.0);
  const HeightMap difference_map(g, difference);
  const Plane p = eigen_fit(difference_map, common);
  double sum = 0, count = 0;
  for (long j = 0; j < 20; ++j)
    for (long i = 0; i < 30; ++i)
      if (common(i, j)) {
        const double residual = difference_map(i, j) - p(centre_x(g, i), centre_y(g, j));
        sum += residual * residual;
        count += 1;
      }
  const double expected = std::sqrt(sum / count);
  EXPECT_NEAR(levelled_rms_difference(image, truth), expected, 1e-9 * expected);
}

TEST(LevelledRmsDifference, RejectsDifferentGridsAndTooFewCommonPixels) {
  const Grid g{6, 5, 6e-6, 5e-6, -3e-6, -2.5e-6};
  const auto value = [](long i, long j, double, double) { return 1e-9 * (i * j); };
  const HeightMap a = make_map(g, value, everywhere);
  EXPECT_EQ(rejected([&] { levelled_rms_difference(a, make_map(Grid{6, 4, 6e-6, 5e-6, -3e-6, -2.5e-6}, value, everywhere)); }),
            "map");
  EXPECT_EQ(rejected([&] { levelled_rms_difference(a, make_map(Grid{6, 5, 6e-6, 5e-6, -3e-6, -2.4e-6}, value, everywhere)); }),
            "map");
  EXPECT_EQ(rejected([&] { levelled_rms_difference(a, make_map(Grid{6, 5, 6.1e-6, 5e-6, -3e-6, -2.5e-6}, value, everywhere)); }),
            "map");
  // Sizes equal to within 1e-9 of the map: the same grid.
  EXPECT_EQ(rejected([&] {
              levelled_rms_difference(a, make_map(Grid{6, 5, 6e-6 * (1 + 1e-13), 5e-6, -3e-6, -2.5e-6}, value, everywhere));
            }),
            "(accepted)");
  // Complementary masks: no common pixel.
  const HeightMap left = make_map(g, value, [](long i, long) { return i < 3; });
  const HeightMap right = make_map(g, value, [](long i, long) { return i >= 3; });
  EXPECT_EQ(rejected([&] { levelled_rms_difference(left, right); }), "map");
  // Common pixels all in one column: no plane.
  const HeightMap middle = make_map(g, value, [](long i, long) { return i >= 2; });
  EXPECT_EQ(rejected([&] { levelled_rms_difference(left, middle); }), "map");
}
