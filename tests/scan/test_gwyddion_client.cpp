// Gwyddion as the real client: the GSF / GXYZF files written by afmkit are opened by Gwyddion's own loaders
// (gwyddion-thumbnailer, see gwyddion_client.hpp) and what Gwyddion read is compared with the map written: the
// grid size (Thumb::Image::Width / Height), the physical size and its unit (Thumb::X-Gwyddion::RealSize) and every
// pixel's grey level, which Gwyddion's default grey gradient makes a clamped linear function of the float32 value it
// read. Corrupted files show that the checks can fail. When the thumbnailer is missing every test fails
// with a message naming scripts/bootstrap.sh (no silent skip).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/gsf.hpp"
#include "afmkit/scan/gxyzf.hpp"
#include "afmkit/scan/height_map.hpp"
#include "gwyddion_client.hpp"
#include "scan_test_dir.hpp"

using afmkit::scan::Grid;
using afmkit::scan::HeightMap;

namespace {

constexpr double pi = 3.141592653589793;

/// A smooth surface with noise on `grid`; with `disc`, the pixels whose centre lies outside the inscribed ellipse
/// are invalid (what a rotational scan leaves).
HeightMap test_map(const Grid& grid, bool disc, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.3e-9);
  const long n = grid.x_resolution * grid.y_resolution;
  std::vector<double> data(static_cast<std::size_t>(n));
  std::vector<std::uint8_t> valid;
  if (disc) valid.assign(static_cast<std::size_t>(n), 0);
  for (long j = 0; j < grid.y_resolution; ++j) {
    for (long i = 0; i < grid.x_resolution; ++i) {
      const double u = (static_cast<double>(i) + 0.5) / static_cast<double>(grid.x_resolution);  // 0 … 1
      const double v = (static_cast<double>(j) + 0.5) / static_cast<double>(grid.y_resolution);
      const auto k = static_cast<std::size_t>(j * grid.x_resolution + i);
      data[k] = 4e-9 * std::sin(2 * pi * 1.5 * u) * std::cos(2 * pi * v) + 6e-9 * u * v + noise(rng);
      if (disc) valid[k] = (u - 0.5) * (u - 0.5) + (v - 0.5) * (v - 0.5) <= 0.25 ? 1 : 0;
    }
  }
  return HeightMap(grid, std::move(data), "m", std::move(valid));
}

/// The float32 values a GSF reader finds in the data file of `map`, computed here without the library: valid
/// pixels as float, invalid ones as the float of the mean of the valid values (Gwyddion's bad-data convention).
std::vector<double> expected_file_values(const HeightMap& map) {
  double sum = 0.0;
  long count = 0;
  for (std::size_t k = 0; k < map.size(); ++k)
    if (std::isfinite(map.data()[k])) sum += map.data()[k], ++count;
  const double fill = count > 0 ? static_cast<double>(static_cast<float>(sum / static_cast<double>(count))) : 0.0;
  std::vector<double> out(map.size());
  for (std::size_t k = 0; k < map.size(); ++k)
    out[k] = std::isfinite(map.data()[k]) ? static_cast<double>(static_cast<float>(map.data()[k])) : fill;
  return out;
}

/// Checks the rendered thumbnail pixel by pixel against `values` (row-major, x_res × y_res, unscaled). Gwyddion
/// draws thumbnails in its "auto" colour range (the full range minus sparse histogram tails), grey level
/// clamp(255 · (z − lo) / (hi − lo), 0, 255) with lo >= min z, hi <= max z. So: every pixel grey (R = G = B); a
/// straight line grey = a + b·z fitted to the unclipped pixels (1 … 254) with b > 0; every pixel, clipped ones
/// too, within 1 level of clamp(a + b·z); the range [lo, hi] = [−a/b, (255 − a)/b] inside [min, max] (to 1 %)
/// and covering at least `min_coverage` of it. A transposed, flipped, shifted or mis-decoded image fails.
void expect_grey_levels(const gwyddion_client::Png& image, long x_res, long y_res, const std::vector<double>& values,
                        double min_coverage = 0.5) {
  ASSERT_EQ(image.width, x_res);
  ASSERT_EQ(image.height, y_res);
  const auto [lo_it, hi_it] = std::minmax_element(values.begin(), values.end());
  const double z_min = *lo_it, z_span = *hi_it - *lo_it;
  ASSERT_GT(z_span, 0.0) << "constant data: no grey scale to compare";
  double n = 0, sz = 0, sg = 0, szz = 0, szg = 0;  // least squares on z scaled to 0 … 1
  for (long j = 0; j < y_res; ++j) {
    for (long i = 0; i < x_res; ++i) {
      const int g = image.green(i, j);
      ASSERT_TRUE(image.red(i, j) == g && image.blue(i, j) == g) << "pixel (" << i << ", " << j << ") not grey";
      if (g < 1 || g > 254) continue;
      const double z = (values[static_cast<std::size_t>(j * x_res + i)] - z_min) / z_span;
      n += 1, sz += z, sg += g, szz += z * z, szg += z * g;
    }
  }
  ASSERT_GE(n, std::max(2.0, 0.1 * static_cast<double>(x_res * y_res))) << "too few unclipped pixels";
  const double slope = (n * szg - sz * sg) / (n * szz - sz * sz);
  const double intercept = (sg - slope * sz) / n;
  ASSERT_GT(slope, 0.0);
  const double lo = -intercept / slope, hi = (255.0 - intercept) / slope;  // in units of the span, from z_min
  EXPECT_GE(lo, -0.01);
  EXPECT_LE(hi, 1.01);
  EXPECT_GE(hi - lo, min_coverage) << "colour range [" << lo << ", " << hi << "] of the data span";
  long bad = 0;
  for (long j = 0; j < y_res; ++j) {
    for (long i = 0; i < x_res; ++i) {
      const double z = (values[static_cast<std::size_t>(j * x_res + i)] - z_min) / z_span;
      const double expected = std::clamp(intercept + slope * z, 0.0, 255.0);
      const int g = image.green(i, j);
      if (std::abs(g - expected) > 1.0 && ++bad <= 5)
        ADD_FAILURE() << "pixel (" << i << ", " << j << "): grey " << g << ", expected " << expected;
    }
  }
  EXPECT_EQ(bad, 0) << "pixels off the line";
}

/// Checks a rendered mask file: one grey level at every valid pixel, a darker one at every invalid pixel.
void expect_mask_levels(const gwyddion_client::Png& image, const HeightMap& map) {
  ASSERT_EQ(image.width, map.x_resolution());
  ASSERT_EQ(image.height, map.y_resolution());
  int valid_grey = -1, invalid_grey = -1;
  for (long j = 0; j < map.y_resolution(); ++j) {
    for (long i = 0; i < map.x_resolution(); ++i) {
      const int g = image.green(i, j);
      ASSERT_TRUE(image.red(i, j) == g && image.blue(i, j) == g);
      int& level = map.valid(i, j) ? valid_grey : invalid_grey;
      if (level < 0) level = g;
      ASSERT_EQ(g, level) << "pixel (" << i << ", " << j << "), valid " << map.valid(i, j);
    }
  }
  EXPECT_GT(valid_grey, invalid_grey);
}

/// Checks Thumb::X-Gwyddion::RealSize ("<x>×<y> <prefix>m") against the map's x_size × y_size, to the digits
/// Gwyddion printed.
void expect_real_size(const gwyddion_client::Png& image, double x_size, double y_size) {
  const std::string text = image.text_value("Thumb::X-Gwyddion::RealSize");
  const std::string times = "\xC3\x97";  // U+00D7 ×
  const std::size_t cross = text.find(times);
  const std::size_t blank = text.rfind(' ');
  ASSERT_TRUE(cross != std::string::npos && blank != std::string::npos && blank > cross) << "RealSize '" << text << "'";
  const std::string x_text = text.substr(0, cross);
  const std::string y_text = text.substr(cross + times.size(), blank - cross - times.size());
  const std::string unit = text.substr(blank + 1);
  double magnitude = 0.0;
  if (unit == "m") magnitude = 1.0;
  if (unit == "mm") magnitude = 1e-3;
  if (unit == "\xC2\xB5m") magnitude = 1e-6;  // µm
  if (unit == "nm") magnitude = 1e-9;
  if (unit == "pm") magnitude = 1e-12;
  ASSERT_GT(magnitude, 0.0) << "unit '" << unit << "' in RealSize '" << text << "'";
  for (const auto& [printed, size] : {std::pair{x_text, x_size}, std::pair{y_text, y_size}}) {
    const std::size_t dot = printed.find('.');
    const int digits = dot == std::string::npos ? 0 : static_cast<int>(printed.size() - dot - 1);
    const double half_digit = 0.5 * std::pow(10.0, -digits);
    EXPECT_NEAR(std::strtod(printed.c_str(), nullptr), size / magnitude, half_digit * (1 + 1e-9))
        << "RealSize '" << text << "'";
  }
}

class GwyddionClient : public ::testing::Test {
 protected:
  void SetUp() override {
    thumbnailer_ = gwyddion_client::find_thumbnailer();
    ASSERT_FALSE(thumbnailer_.empty()) << gwyddion_client::missing_thumbnailer_message;
  }
  gwyddion_client::Thumbnail render(const std::string& file, int max_size = 256) const {
    return gwyddion_client::render(thumbnailer_, file, dir_.path.string(), max_size);
  }
  /// Renders `path` and expects success: exit 0, a PNG of x_res × y_res (unscaled), the width / height texts.
  gwyddion_client::Thumbnail render_ok(const std::string& path, long x_res, long y_res, int max_size = 256) const {
    auto t = render(path, max_size);
    EXPECT_EQ(t.exit_status, 0) << path << ": " << t.error_output;
    EXPECT_TRUE(t.png_written) << path;
    EXPECT_EQ(t.image.error, "") << path;
    EXPECT_EQ(t.image.text_value("Thumb::Image::Width"), std::to_string(x_res));
    EXPECT_EQ(t.image.text_value("Thumb::Image::Height"), std::to_string(y_res));
    return t;
  }
  std::string thumbnailer_;
  scan_test::TempDir dir_{"afmkit_gwyddion_client"};
};

}  // namespace

TEST(GwyddionClientHelper, FindsOnlyExecutableFilesOnThePath) {
  scan_test::TempDir dir("afmkit_gwyddion_find");
  const std::string fake = dir.file(gwyddion_client::thumbnailer_name);
  EXPECT_EQ(gwyddion_client::find_on_path(gwyddion_client::thumbnailer_name, dir.path.string()), "");
  scan_test::spit(fake, "#!/bin/sh\n");
  std::filesystem::permissions(fake, std::filesystem::perms::owner_read);
  EXPECT_EQ(gwyddion_client::find_on_path(gwyddion_client::thumbnailer_name, dir.path.string()), "");
  std::filesystem::permissions(fake, std::filesystem::perms::owner_all);
  EXPECT_EQ(gwyddion_client::find_on_path(gwyddion_client::thumbnailer_name, "/nonexistent::" + dir.path.string()),
            fake);
  EXPECT_NE(std::string(gwyddion_client::missing_thumbnailer_message).find("scripts/bootstrap.sh"), std::string::npos);
  EXPECT_EQ(gwyddion_client::decode_png("GIF89a").error, "not a PNG (bad signature)");
}

TEST_F(GwyddionClient, MaskedDiscOpensAsDataFileAndMaskFile) {
  const Grid grid{61, 47, 6e-6, 4.5e-6, -3e-6, 2.25e-6};
  const HeightMap map = test_map(grid, true, 1);
  ASSERT_GT(map.valid_count(), 0u);
  ASSERT_LT(map.valid_count(), map.size());
  const std::string path = dir_.file("disc.gsf");
  const auto written = afmkit::scan::write_gsf(path, map, "spiral disc");
  ASSERT_EQ(written.size(), 2u);

  const auto data = render_ok(written[0], 61, 47);
  expect_grey_levels(data.image, 61, 47, expected_file_values(map));
  expect_real_size(data.image, 6e-6, 4.5e-6);

  const auto mask = render_ok(written[1], 61, 47);
  expect_mask_levels(mask.image, map);  // dark outside the disc, bright inside
}

TEST_F(GwyddionClient, MapWithEveryPixelValidOpensWithAndWithoutAMask) {
  const Grid grid{40, 30, 2e-6, 1.5e-6, 0.0, 0.0};
  const HeightMap plain = test_map(grid, false, 2);
  const auto one = afmkit::scan::write_gsf(dir_.file("plain.gsf"), plain);
  ASSERT_EQ(one.size(), 1u);  // no mask, no mask file
  const auto t = render_ok(one[0], 40, 30);
  expect_grey_levels(t.image, 40, 30, expected_file_values(plain));

  const HeightMap all_valid(grid, plain.data(), "m", std::vector<std::uint8_t>(plain.size(), 1));
  const auto two = afmkit::scan::write_gsf(dir_.file("all_valid.gsf"), all_valid);
  ASSERT_EQ(two.size(), 2u);
  const auto data = render_ok(two[0], 40, 30);
  expect_grey_levels(data.image, 40, 30, expected_file_values(plain));
  const auto mask = render_ok(two[1], 40, 30);  // constant 1: Gwyddion opens it, every pixel the same grey
  ASSERT_EQ(mask.image.rgb.size(), 40u * 30u * 3u);
  EXPECT_TRUE(std::all_of(mask.image.rgb.begin(), mask.image.rgb.end(),
                          [&](std::uint8_t c) { return c == mask.image.rgb[0]; }));
}

TEST_F(GwyddionClient, Large512x512MapIsReadPixelForPixel) {
  const Grid grid{512, 512, 20e-6, 20e-6, -10e-6, -10e-6};
  const HeightMap map = test_map(grid, true, 3);
  const auto written = afmkit::scan::write_gsf(dir_.file("large.gsf"), map, "large");
  ASSERT_EQ(written.size(), 2u);
  const auto full = render_ok(written[0], 512, 512, 512);  // MAX-SIZE 512: not scaled
  expect_grey_levels(full.image, 512, 512, expected_file_values(map));
  expect_real_size(full.image, 20e-6, 20e-6);
  expect_mask_levels(render_ok(written[1], 512, 512, 512).image, map);
  const auto small = render_ok(written[0], 512, 512, 128);  // scaled down to fit, the texts still give XRes / YRes
  EXPECT_EQ(small.image.width, 128);
  EXPECT_EQ(small.image.height, 128);
}

TEST_F(GwyddionClient, OddSizesAndOffsetsOpen) {
  struct Case {
    long x_res, y_res;
    double x_size, y_size, x_offset, y_offset;
  };
  const Case cases[] = {
      {1, 1, 1e-6, 1e-6, 0.0, 0.0},           {1, 7, 1e-9, 7e-9, 5e-3, -5e-3},
      {7, 1, 7e-9, 1e-9, -1.25e-7, 3e-7},     {2, 3, 2e-3, 3e-3, 1e-3, 1e-3},
      {37, 23, 370e-9, 230e-9, -1e-6, 2e-6},  {101, 3, 1.01e-4, 3e-6, 0.0, -0.5},
      {3, 101, 3e-10, 1.01e-8, 1e-12, 1e-12}, {255, 17, 2.55e-5, 1.7e-6, -12.5e-6, 0.0},
  };
  unsigned seed = 10;
  for (const Case& c : cases) {
    SCOPED_TRACE(std::to_string(c.x_res) + "x" + std::to_string(c.y_res));
    const HeightMap map = test_map({c.x_res, c.y_res, c.x_size, c.y_size, c.x_offset, c.y_offset}, false, seed++);
    const std::string path = dir_.file("odd_" + std::to_string(c.x_res) + "x" + std::to_string(c.y_res) + ".gsf");
    ASSERT_EQ(afmkit::scan::write_gsf(path, map).size(), 1u);
    const auto t = render_ok(path, c.x_res, c.y_res);
    if (c.x_res * c.y_res > 1) expect_grey_levels(t.image, c.x_res, c.y_res, expected_file_values(map));
    expect_real_size(t.image, c.x_size, c.y_size);
  }
}

TEST_F(GwyddionClient, GsfRoundTripKeepsFloat32ValuesGridAndMask) {
  const Grid grid{33, 21, 3.3e-6, 2.1e-6, -1.7e-6, 0.3e-6};
  const HeightMap map = test_map(grid, true, 4);
  const std::string path = dir_.file("round.gsf");
  const auto written = afmkit::scan::write_gsf(path, map, "round trip");
  ASSERT_EQ(written, (std::vector<std::string>{path, afmkit::scan::gsf_mask_path(path)}));
  const auto back = afmkit::scan::read_gsf_with_mask(written[0], written[1]);
  EXPECT_EQ(back.title, "round trip");
  const Grid& g = back.map.grid();
  EXPECT_EQ(g.x_resolution, 33);
  EXPECT_EQ(g.y_resolution, 21);
  EXPECT_EQ(g.x_size, 3.3e-6);  // shortest round-trip decimal: the same doubles
  EXPECT_EQ(g.y_size, 2.1e-6);
  EXPECT_EQ(g.x_offset, -1.7e-6);
  EXPECT_EQ(g.y_offset, 0.3e-6);
  EXPECT_EQ(back.map.z_unit(), "m");
  ASSERT_TRUE(back.map.has_mask());
  EXPECT_EQ(back.map.mask(), map.mask());
  for (long j = 0; j < 21; ++j) {
    for (long i = 0; i < 33; ++i) {
      if (map.valid(i, j))
        EXPECT_EQ(back.map(i, j), static_cast<double>(static_cast<float>(map(i, j)))) << i << ", " << j;
      else
        EXPECT_TRUE(std::isnan(back.map(i, j))) << i << ", " << j;
    }
  }
}

TEST_F(GwyddionClient, CorruptedGsfIsRejectedByGwyddion) {
  const HeightMap map = test_map({16, 12, 1e-6, 1e-6, 0.0, 0.0}, false, 5);
  const std::string good = afmkit::scan::format_gsf(map);
  const std::string short_path = dir_.file("short.gsf");
  scan_test::spit(short_path, good.substr(0, good.size() - 4));  // one float missing
  const auto t = render(short_path);
  EXPECT_EQ(t.exit_status, 1);
  EXPECT_FALSE(t.png_written);
  EXPECT_NE(t.failure_reason().find("Expected data size"), std::string::npos) << t.error_output;
  EXPECT_FALSE(t.no_previewable_data());

  std::string bad_magic = good;
  bad_magic[9] = 'X';  // "GwyddionXSimple Field 1.0"
  scan_test::spit(dir_.file("magic.gsf"), bad_magic);
  const auto m = render(dir_.file("magic.gsf"));
  EXPECT_EQ(m.exit_status, 1);
  EXPECT_FALSE(m.png_written);
  EXPECT_NE(m.failure_reason(), "") << m.error_output;
  EXPECT_FALSE(m.no_previewable_data());
}

TEST_F(GwyddionClient, GxyzfLoadsAsXyzDataAndCorruptedOnesFail) {
  // A spiral point cloud: two channels (height [m], deflection [V]).
  std::vector<double> x, y, height, deflection;
  for (int k = 0; k < 2000; ++k) {
    const double angle = 0.05 * k, radius = 5e-6 * (1.0 - k / 2000.0);
    x.push_back(radius * std::cos(angle));
    y.push_back(radius * std::sin(angle));
    height.push_back(1e-9 * std::sin(3 * angle));
    deflection.push_back(0.1 * std::cos(angle));
  }
  const afmkit::scan::XyzField field(x, y, {{"Height", "m", height}, {"Deflection", "V", deflection}});
  const std::string path = dir_.file("spiral.gxyzf");
  afmkit::scan::write_gxyzf(path, field);
  const auto t = render(path);
  // Loaded by Gwyddion's GXYZF module (a parse error would name it) into XYZ data, which has no image preview.
  EXPECT_EQ(t.exit_status, 1);
  EXPECT_FALSE(t.png_written);
  EXPECT_TRUE(t.no_previewable_data()) << t.error_output;
  EXPECT_EQ(t.failure_reason(), std::string(gwyddion_client::no_previewable_data) + ".");

  const std::string good = afmkit::scan::format_gxyzf(field);
  scan_test::spit(dir_.file("short.gxyzf"), good.substr(0, good.size() - 8));  // one double of the last point lost
  const auto s = render(dir_.file("short.gxyzf"));
  EXPECT_EQ(s.exit_status, 1);
  EXPECT_FALSE(s.no_previewable_data()) << s.error_output;
  EXPECT_NE(s.failure_reason().find("is not a multiple of point size 32"), std::string::npos) << s.error_output;

  std::string no_channels = good;
  const std::size_t at = no_channels.find("NChannels = 2");
  ASSERT_NE(at, std::string::npos);
  no_channels.replace(at, 13, "NChannels = 0");
  scan_test::spit(dir_.file("nchannels.gxyzf"), no_channels);
  const auto n = render(dir_.file("nchannels.gxyzf"));
  EXPECT_EQ(n.exit_status, 1);
  EXPECT_FALSE(n.no_previewable_data()) << n.error_output;
  EXPECT_NE(n.failure_reason().find("NChannels"), std::string::npos) << n.error_output;
}
