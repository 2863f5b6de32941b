#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/height_map.hpp"

using afmkit::InvalidParameter;
using afmkit::scan::Grid;
using afmkit::scan::HeightMap;

namespace {
std::string rejected_field(const Grid& g, std::vector<double> data, std::string unit = "m",
                           std::vector<std::uint8_t> valid = {}) {
  try {
    HeightMap(g, std::move(data), std::move(unit), std::move(valid));
  } catch (const InvalidParameter& e) {
    EXPECT_NE(std::string(e.what()).find(e.parameter()), std::string::npos) << e.what();
    return e.parameter();
  }
  return "(accepted)";
}
}  // namespace

TEST(HeightMap, LayoutIsRowMajorFromTheTopRow) {
  const Grid g{3, 2, 3e-6, 1e-6, -1e-6, 2e-6};
  const HeightMap m(g, {0, 1, 2, 10, 11, 12});
  EXPECT_EQ(m(2, 0), 2.0);
  EXPECT_EQ(m(0, 1), 10.0);
  EXPECT_DOUBLE_EQ(m.dx(), 1e-6);
  EXPECT_DOUBLE_EQ(m.dy(), 0.5e-6);
  EXPECT_EQ(m.x_offset(), -1e-6);
  EXPECT_EQ(m.y_offset(), 2e-6);
  EXPECT_EQ(m.z_unit(), "m");
  EXPECT_FALSE(m.has_mask());
  EXPECT_EQ(m.valid_count(), 6u);
}

TEST(HeightMap, InvalidPixelsHoldNaNAndValidOnesMustBeFinite) {
  const Grid g{2, 2, 1e-6, 1e-6};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const HeightMap m(g, {1, 99, nan, 4}, "m", {1, 0, 0, 1});
  EXPECT_TRUE(std::isnan(m(1, 0)));  // 99 replaced: an invalid pixel's value is never used
  EXPECT_TRUE(std::isnan(m(0, 1)));
  EXPECT_FALSE(m.valid(1, 0));
  EXPECT_TRUE(m.valid(1, 1));
  EXPECT_EQ(m.valid_count(), 2u);
  EXPECT_EQ(rejected_field(g, {1, nan, 3, 4}), "data");                    // NaN at a valid pixel
  EXPECT_EQ(rejected_field(g, {1, INFINITY, 3, 4}, "m", {1, 1, 1, 1}), "data");
}

TEST(HeightMap, EachBadFieldIsNamed) {
  const std::vector<double> four{1, 2, 3, 4};
  EXPECT_EQ(rejected_field({0, 2, 1, 1}, {}), "x_resolution");
  EXPECT_EQ(rejected_field({2, -1, 1, 1}, four), "y_resolution");
  EXPECT_EQ(rejected_field({2, 2, 0.0, 1}, four), "x_size");
  EXPECT_EQ(rejected_field({2, 2, 1, -1e-6}, four), "y_size");
  EXPECT_EQ(rejected_field({2, 2, INFINITY, 1}, four), "x_size");
  EXPECT_EQ(rejected_field({2, 2, 1, 1, NAN, 0}, four), "x_offset");
  EXPECT_EQ(rejected_field({2, 2, 1, 1, 0, INFINITY}, four), "y_offset");
  EXPECT_EQ(rejected_field({2, 2, 1, 1}, {1, 2, 3}), "data");
  EXPECT_EQ(rejected_field({3, 2, 1, 1}, four), "data");
  EXPECT_EQ(rejected_field({2, 2, 1, 1}, four, "m", {1, 1, 1}), "valid");
  EXPECT_EQ(rejected_field({2, 2, 1, 1}, four, "m", {1, 2, 1, 1}), "valid");
  EXPECT_EQ(rejected_field({2, 2, 1, 1}, four, "m\n"), "z_unit");
  EXPECT_EQ(rejected_field({2, 2, 1, 1}, four, " m"), "z_unit");
  EXPECT_EQ(rejected_field({2, 2, 1, 1}, four, ""), "(accepted)");  // dimensionless
}
