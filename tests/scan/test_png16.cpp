#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <png.h>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/png16.hpp"
#include "scan_test_dir.hpp"

using afmkit::InputError;
using afmkit::scan::Grey16;
using afmkit::scan::HeightMap;

namespace {

// A PNG of another kind, made with libpng's simplified API (independent of the code under test).
std::string other_png(png_uint_32 format, int width = 3, int height = 2) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = format;
  std::vector<unsigned char> pixels(PNG_IMAGE_SIZE(image), 0x5A);
  png_alloc_size_t size = 0;
  EXPECT_TRUE(png_image_write_to_memory(&image, nullptr, &size, 0, pixels.data(), 0, nullptr));
  std::string out(size, '\0');
  EXPECT_TRUE(png_image_write_to_memory(&image, out.data(), &size, 0, pixels.data(), 0, nullptr));
  out.resize(size);
  return out;
}

std::string png_error_of(const std::string& bytes) {
  try {
    afmkit::scan::parse_png16(bytes, "dir/x.png");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

unsigned be32(const std::string& s, std::size_t at) {
  unsigned v = 0;
  for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(s[at + k]);
  return v;
}

}  // namespace

TEST(Png16, IntegerDataZeroTo65535RoundTripsExactly) {
  scan_test::TempDir dir("afmkit_png16_round");
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> u(0, 65535);
  const long w = 41, h = 17;
  std::vector<double> data(w * h);
  for (double& v : data) v = u(rng);
  data[3] = 0;       // the range is exactly 0 … 65535: the scaling is the identity
  data[10] = 65535;
  afmkit::scan::write_png16(dir.file("m.png"), HeightMap({w, h, 1e-6, 1e-6}, data));
  const std::string bytes = scan_test::slurp(dir.file("m.png"));
  // IHDR by hand: signature (8), chunk length (4), "IHDR" (4), width, height (big-endian), bit depth, colour type
  ASSERT_GT(bytes.size(), 26u);
  EXPECT_EQ(bytes.substr(12, 4), "IHDR");
  EXPECT_EQ(be32(bytes, 16), 41u);
  EXPECT_EQ(be32(bytes, 20), 17u);
  EXPECT_EQ(static_cast<int>(bytes[24]), 16);  // bit depth
  EXPECT_EQ(static_cast<int>(bytes[25]), 0);   // colour type 0: greyscale
  const Grey16 back = afmkit::scan::read_png16(dir.file("m.png"));
  ASSERT_EQ(back.width, w);
  ASSERT_EQ(back.height, h);
  for (std::size_t k = 0; k < data.size(); ++k) EXPECT_EQ(back.pixels[k], data[k]) << k;

  // and an image read back by libpng's simplified API (linear 16-bit grey) agrees
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_memory(&image, bytes.data(), bytes.size()));
  image.format = PNG_FORMAT_LINEAR_Y;
  std::vector<png_uint_16> ref(PNG_IMAGE_SIZE(image) / 2);
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, ref.data(), 0, nullptr));
  ASSERT_EQ(ref.size(), back.pixels.size());
  for (std::size_t k = 0; k < ref.size(); ++k) EXPECT_EQ(ref[k], back.pixels[k]) << k;
}

TEST(Png16, ScalingOfTheFiniteRangeAndInvalidPixels) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const HeightMap m({4, 1, 1, 1}, {-1e-9, 0.0, nan, 1e-9}, "m", {1, 1, 0, 1});
  const Grey16 g = afmkit::scan::to_grey16(m);
  EXPECT_EQ(g.pixels, (std::vector<std::uint16_t>{0, 32768, 0, 65535}));  // round(65535 / 2) = 32768
  EXPECT_EQ(afmkit::scan::to_grey16(HeightMap({2, 1, 1, 1}, {5, 5})).pixels, (std::vector<std::uint16_t>{0, 0}));
  // the widest range a double allows: no overflow of max - min
  const double big = std::numeric_limits<double>::max();
  EXPECT_EQ(afmkit::scan::to_grey16(HeightMap({3, 1, 1, 1}, {-big, 0.0, big})).pixels,
            (std::vector<std::uint16_t>{0, 32768, 65535}));
  // a Grey16 image round-trips through the encoder exactly
  Grey16 img{5, 3, {}};
  for (int k = 0; k < 15; ++k) img.pixels.push_back(static_cast<std::uint16_t>(k * 4681));
  const Grey16 back = afmkit::scan::parse_png16(afmkit::scan::format_png16(img), "t");
  EXPECT_EQ(back.pixels, img.pixels);
  EXPECT_THROW(afmkit::scan::format_png16(Grey16{2, 2, {1, 2, 3}}), afmkit::InvalidParameter);
}

TEST(Png16, OtherPngsAndNonPngsAreRefusedWithWhatWasFound) {
  std::string m = png_error_of(other_png(PNG_FORMAT_RGB));
  EXPECT_NE(m.find("dir/x.png: not a 16-bit greyscale PNG: bit depth 8, colour type 2 (RGB)"), std::string::npos) << m;
  m = png_error_of(other_png(PNG_FORMAT_GRAY));
  EXPECT_NE(m.find("bit depth 8, colour type 0 (greyscale)"), std::string::npos) << m;
  m = png_error_of(other_png(PNG_FORMAT_LINEAR_Y_ALPHA));
  EXPECT_NE(m.find("bit depth 16, colour type 4 (greyscale with alpha)"), std::string::npos) << m;
  m = png_error_of("Gwyddion Simple Field 1.0\n");
  EXPECT_NE(m.find("dir/x.png: not a PNG file"), std::string::npos) << m;
  EXPECT_NE(png_error_of("").find("not a PNG"), std::string::npos);

  Grey16 img{64, 64, std::vector<std::uint16_t>(64 * 64)};
  for (std::size_t k = 0; k < img.pixels.size(); ++k) img.pixels[k] = static_cast<std::uint16_t>(k * 2654435761u);
  const std::string good = afmkit::scan::format_png16(img);
  m = png_error_of(good.substr(0, good.size() / 2));  // truncated
  EXPECT_NE(m.find("dir/x.png: bad PNG"), std::string::npos) << m;
  std::string corrupt = good;
  corrupt[good.size() / 2] = static_cast<char>(corrupt[good.size() / 2] ^ 0x55);  // inside IDAT: CRC mismatch
  m = png_error_of(corrupt);
  EXPECT_NE(m.find("dir/x.png: bad PNG"), std::string::npos) << m;
}

TEST(Png16, FilesThatCannotBeReadAreNamed) {
  scan_test::TempDir dir("afmkit_png16_files");
  try {
    afmkit::scan::read_png16(dir.file("none.png"));
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("none.png"), std::string::npos) << e.what();
  }
}
