#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/gsf.hpp"
#include "scan_test_dir.hpp"

using afmkit::InputError;
using afmkit::InvalidParameter;
using afmkit::scan::Grid;
using afmkit::scan::HeightMap;

namespace {

// float32 little-endian, built independently of the library: bits by memcpy, bytes by shifting.
std::string le32(float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, 4);
  std::string out;
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>(bits >> (8 * k)));
  return out;
}

// A GSF file by hand: magic, the given header text, NULs to the next multiple of 4 (1 to 4), the floats.
std::string gsf(const std::string& header, const std::vector<float>& values) {
  std::string out = "Gwyddion Simple Field 1.0\n" + header;
  out.append(4 - out.size() % 4, '\0');
  for (float v : values) out += le32(v);
  return out;
}

// The message of the InputError raised by parsing `bytes` as file `name` ("" when none is raised).
std::string gsf_error_of(const std::string& bytes, const std::string& name = "bad.gsf") {
  try {
    afmkit::scan::parse_gsf(bytes, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_error(const std::string& bytes, std::initializer_list<const char*> parts) {
  const std::string message = gsf_error_of(bytes, "dir/bad.gsf");
  ASSERT_FALSE(message.empty()) << "accepted";
  EXPECT_NE(message.find("dir/bad.gsf"), std::string::npos) << message;
  for (const char* p : parts) EXPECT_NE(message.find(p), std::string::npos) << "'" << p << "' not in: " << message;
}

}  // namespace

TEST(Gsf, WrittenBytesAreTheFormatBuiltByHand) {
  scan_test::TempDir dir("afmkit_gsf_bytes");
  const std::vector<double> data{1.0, -2.25, 0.0, 1e-9, 3.5e-7, -65504.0};
  const HeightMap map({3, 2, 2e-6, 1e-6, 0.0, -5e-7}, data, "m");
  const auto written = afmkit::scan::write_gsf(dir.file("a.gsf"), map, "spiral");
  ASSERT_EQ(written, std::vector<std::string>{dir.file("a.gsf")});  // no mask: one file

  const std::string header =
      "Gwyddion Simple Field 1.0\n"
      "XRes = 3\n"
      "YRes = 2\n"
      "XReal = 2e-06\n"
      "YReal = 1e-06\n"
      "XOffset = 0\n"
      "YOffset = -5e-07\n"
      "XYUnits = m\n"
      "ZUnits = m\n"
      "Title = spiral\n";
  ASSERT_EQ(header.size(), 139u);         // counted by hand: 26+9+9+14+14+12+17+12+11+15
  std::string expected = header + '\0';   // 139 + 1 = 140, a multiple of 4
  for (double v : data) expected += le32(static_cast<float>(v));
  EXPECT_EQ(expected.substr(140, 4), std::string("\x00\x00\x80\x3F", 4));  // 1.0f = 0x3F800000, little-endian
  EXPECT_EQ(scan_test::slurp(dir.file("a.gsf")), expected);
}

TEST(Gsf, RoundTripIsExactForFloat32Data) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1e-6f, 1e-6f);
  std::vector<double> data(37 * 23);
  for (double& v : data) v = u(rng);  // float values: representable exactly
  data[5] = std::numeric_limits<float>::max();
  data[6] = std::numeric_limits<float>::denorm_min();
  const HeightMap map({37, 23, 1.2345678901234567e-5, 9.87654321e-6, -3.3e-6, 1.0 / 3.0}, data, "m");
  const std::string bytes = afmkit::scan::format_gsf(map, "Höhe / µm");
  const auto back = afmkit::scan::parse_gsf(bytes, "t");
  EXPECT_EQ(back.map.data(), data);
  EXPECT_EQ(back.map.x_size(), map.x_size());  // shortest round-trip decimal text
  EXPECT_EQ(back.map.y_size(), map.y_size());
  EXPECT_EQ(back.map.x_offset(), map.x_offset());
  EXPECT_EQ(back.map.y_offset(), map.y_offset());
  EXPECT_EQ(back.map.z_unit(), "m");
  EXPECT_EQ(back.title, "Höhe / µm");
  EXPECT_TRUE(back.extra.empty());
  EXPECT_FALSE(back.map.has_mask());
  // a double is rounded to the nearest float
  const HeightMap fine({1, 1, 1, 1}, {0.1});
  EXPECT_EQ(afmkit::scan::parse_gsf(afmkit::scan::format_gsf(fine), "t").map.data()[0], static_cast<double>(0.1f));
}

TEST(Gsf, InvalidPixelsBecomeTheMeanPlusAMaskFile) {
  scan_test::TempDir dir("afmkit_gsf_mask");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const HeightMap map({3, 2, 1e-6, 1e-6}, {1, nan, 2, nan, 6, 3}, "m", {1, 0, 1, 0, 1, 1});
  const std::string path = dir.file("disc.gsf");
  const auto written = afmkit::scan::write_gsf(path, map, "disc");
  ASSERT_EQ(written.size(), 2u);
  EXPECT_EQ(written[1], dir.file("disc_mask.gsf"));
  EXPECT_EQ(afmkit::scan::gsf_mask_path("/a/b/x.gsf"), "/a/b/x_mask.gsf");
  EXPECT_EQ(afmkit::scan::gsf_mask_path("x"), "x_mask.gsf");

  // the data file alone: every pixel finite, invalid ones = mean of the valid ones (1+2+6+3)/4 = 3
  const auto plain = afmkit::scan::read_gsf(path);
  EXPECT_EQ(plain.map.data(), (std::vector<double>{1, 3, 2, 3, 6, 3}));
  EXPECT_FALSE(plain.map.has_mask());
  // the mask file: 1 valid / 0 invalid, dimensionless
  const auto mask = afmkit::scan::read_gsf(written[1]);
  EXPECT_EQ(mask.map.data(), (std::vector<double>{1, 0, 1, 0, 1, 1}));
  EXPECT_EQ(mask.map.z_unit(), "");
  EXPECT_EQ(mask.title, "disc validity mask");
  // both: the original map back
  const auto both = afmkit::scan::read_gsf_with_mask(path, written[1]);
  EXPECT_EQ(both.map.mask(), map.mask());
  for (long j = 0; j < 2; ++j)
    for (long i = 0; i < 3; ++i)
      if (map.valid(i, j)) {
        EXPECT_EQ(both.map(i, j), map(i, j));
      }

  // a NaN written by another tool makes the pixel invalid
  const auto nan_file = afmkit::scan::parse_gsf(gsf("XRes = 2\nYRes = 1\n", {1.0f, NAN}), "t");
  EXPECT_EQ(nan_file.map.mask(), (std::vector<std::uint8_t>{1, 0}));
  // a mask of another size, or with a value other than 0 / 1, is refused naming the mask file
  const std::string data2 = gsf("XRes = 2\nYRes = 1\n", {1, 2});
  try {
    afmkit::scan::parse_gsf_with_mask(data2, "d.gsf", gsf("XRes = 1\nYRes = 2\n", {1, 1}), "d_mask.gsf");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("d_mask.gsf"), std::string::npos) << e.what();
  }
  try {
    afmkit::scan::parse_gsf_with_mask(data2, "d.gsf", gsf("XRes = 2\nYRes = 1\n", {1, 0.5f}), "d_mask.gsf");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("d_mask.gsf: mask value 0.5 at column 1, row 0"), std::string::npos)
        << e.what();
  }
}

TEST(Gsf, HandMadeFileWithUnknownKeysCrLfAndDefaults) {
  // CR-LF header lines, blanks around keys and '=', a blank line, an unknown key; no XReal: Gwyddion's default 1
  const std::string bytes = gsf("XRes = 2\r\n  YRes=1 \r\n\r\nInstrument = virtual RS-AFM\r\nZUnits = V\r\n", {0.5f, -1});
  const auto f = afmkit::scan::parse_gsf(bytes, "hand.gsf");
  EXPECT_EQ(f.map.x_resolution(), 2);
  EXPECT_EQ(f.map.y_resolution(), 1);
  EXPECT_EQ(f.map.x_size(), 1.0);
  EXPECT_EQ(f.map.x_offset(), 0.0);
  EXPECT_EQ(f.map.z_unit(), "V");
  EXPECT_EQ(f.map.data(), (std::vector<double>{0.5, -1}));
  ASSERT_EQ(f.extra.size(), 1u);
  EXPECT_EQ(f.extra[0].first, "Instrument");
  EXPECT_EQ(f.extra[0].second, "virtual RS-AFM");
  // a header whose length is already a multiple of 4 takes 4 NULs
  const std::string aligned = std::string("Gwyddion Simple Field 1.0\nXRes=1\nYRes=1\n\0\0\0\0", 44) + le32(7);
  EXPECT_EQ(afmkit::scan::parse_gsf(aligned, "t").map.data(), std::vector<double>{7});
  // the data may start with zero bytes (0.0f) right after the padding
  EXPECT_EQ(afmkit::scan::parse_gsf(gsf("XRes = 2\nYRes = 1\n", {0, 0}), "t").map.data(), (std::vector<double>{0, 0}));
}

TEST(Gsf, EveryBadInputNamesTheFileAndTheField) {
  const std::vector<float> two{1, 2};
  expect_error("Gwyddion Simple Field 1.1\nXRes = 2\nYRes = 1\n", {"Gwyddion Simple Field 1.0"});  // magic
  expect_error(std::string("Gwyddion Simple Field 1.0\r\nXRes = 2\nYRes = 1\n\0\0", 47), {"Gwyddion Simple Field"});
  expect_error(gsf("YRes = 1\n", two), {"missing", "XRes"});
  expect_error(gsf("XRes = 2\n", two), {"missing", "YRes"});
  expect_error(gsf("XRes = 2.5\nYRes = 1\n", two), {":2:", "XRes", "'2.5'", "positive integer"});
  expect_error(gsf("XRes = abc\nYRes = 1\n", two), {"XRes", "'abc'"});
  expect_error(gsf("XRes = 0\nYRes = 1\n", two), {"XRes", "'0'"});
  expect_error(gsf("XRes = 2\nYRes = -1\n", two), {":3:", "YRes", "'-1'"});
  expect_error(gsf("XRes = 2\nYRes = 99999999999999999999\n", two), {"YRes"});
  expect_error(gsf("XRes = 2\nYRes = 1\nXReal = inf\n", two), {":4:", "XReal", "not finite"});
  expect_error(gsf("XRes = 2\nYRes = 1\nYReal = nan\n", two), {"YReal", "not finite"});
  expect_error(gsf("XRes = 2\nYRes = 1\nXReal = 0\n", two), {"XReal", "> 0"});
  expect_error(gsf("XRes = 2\nYRes = 1\nXReal = 1 um\n", two), {"XReal", "not a number"});
  expect_error(gsf("XRes = 2\nYRes = 1\nYOffset = -inf\n", two), {"YOffset", "not finite"});
  expect_error(gsf("XRes = 2\nYRes = 1\nXYUnits = nm\n", two), {"XYUnits", "'nm'"});
  expect_error(gsf("XRes = 2\nYRes = 1\nTitle = a\x01z\n", two), {"Title", "control character"});
  expect_error(gsf("XRes = 2\nYRes = 1\nXRes = 2\n", two), {":4:", "duplicate", "XRes", "line 2"});
  expect_error(gsf("XRes = 2\nYRes 1\n", two), {":3:", "'YRes 1'", "Key = Value"});
  expect_error(gsf("XRes = 2\n = 1\n", two), {":3:", "no key"});
  // padding: none at all; a non-NUL inside it (too few NULs: data not aligned); more than 4 NULs
  expect_error("Gwyddion Simple Field 1.0\nXRes = 2\nYRes = 1\n", {"bad padding", "no NUL"});
  std::string unaligned = "Gwyddion Simple Field 1.0\nXRes = 2\nYRes = 1\n";  // 44 bytes: 4 NULs needed
  unaligned += std::string(2, '\0') + le32(0.1f) + le32(0.2f);  // 0.1f = 0x3DCCCCCD: no zero byte
  expect_error(unaligned, {"bad padding", "byte 46", "multiple of 4"});
  std::string long_padding = "Gwyddion Simple Field 1.0\nXRes = 2\nYRes = 1\n";
  long_padding += std::string(8, '\0') + le32(0.1f) + le32(0.2f);
  expect_error(long_padding, {"bad padding", "8 NUL bytes"});
  // size mismatch: one float missing, one extra, one byte extra
  expect_error(gsf("XRes = 2\nYRes = 2\n", {1, 2, 3}), {"size mismatch", "XRes · YRes = 2 · 2", "16 bytes", "truncated"});
  expect_error(gsf("XRes = 2\nYRes = 1\n", {1, 2, 3}), {"size mismatch", "too long"});
  expect_error(gsf("XRes = 2\nYRes = 1\n", two) + "x", {"size mismatch", "9"});
  expect_error(gsf("XRes = 16777216\nYRes = 16777216\n", two), {"size mismatch"});
}

TEST(Gsf, FilesThatCannotBeReadAndBadArgumentsAreNamed) {
  scan_test::TempDir dir("afmkit_gsf_files");
  try {
    afmkit::scan::read_gsf(dir.file("missing.gsf"));
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.gsf"), std::string::npos) << e.what();
  }
  EXPECT_THROW(afmkit::scan::read_gsf(dir.path.string()), InputError);  // a directory
  scan_test::spit(dir.file("bad.gsf"), gsf("XRes = 3\nYRes = 1\n", {1, 2}));
  try {
    afmkit::scan::read_gsf(dir.file("bad.gsf"));
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file("bad.gsf") + ": size mismatch"), std::string::npos) << e.what();
  }
  const HeightMap map({1, 1, 1, 1}, {1});
  try {
    afmkit::scan::format_gsf(map, "two\nlines");
    ADD_FAILURE();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "title");
  }
  try {
    afmkit::scan::format_gsf(HeightMap({1, 1, 1, 1}, {1e39}));
    ADD_FAILURE();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "data");
  }
}
