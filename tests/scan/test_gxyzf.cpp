#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/gxyzf.hpp"
#include "scan_test_dir.hpp"

using afmkit::InputError;
using afmkit::InvalidParameter;
using afmkit::scan::XyzChannel;
using afmkit::scan::XyzField;

namespace {

std::string le64(double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, 8);
  std::string out;
  for (int k = 0; k < 8; ++k) out.push_back(static_cast<char>(bits >> (8 * k)));
  return out;
}

// A GXYZF file by hand: magic, header text, NULs to the next multiple of 8 (1 to 8), the doubles.
std::string gxyzf(const std::string& header, const std::vector<double>& values) {
  std::string out = "Gwyddion XYZ Field 1.0\n" + header;
  out.append(8 - out.size() % 8, '\0');
  for (double v : values) out += le64(v);
  return out;
}

void expect_gxyzf_error(const std::string& bytes, std::initializer_list<const char*> parts) {
  try {
    afmkit::scan::parse_gxyzf(bytes, "dir/bad.gxyzf");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("dir/bad.gxyzf"), std::string::npos) << m;
    for (const char* p : parts) EXPECT_NE(m.find(p), std::string::npos) << "'" << p << "' not in: " << m;
  }
}

}  // namespace

TEST(Gxyzf, WrittenBytesAreTheFormatBuiltByHand) {
  scan_test::TempDir dir("afmkit_gxyzf_bytes");
  const XyzField field({0.0, 1e-6, -2.5e-7}, {0.0, 3e-7, 1e-6},
                       {{"Height", "m", {1e-9, -2e-9, 0.0}}, {"Amplitude", "V", {0.5, 0.25, 1.0}}});
  afmkit::scan::write_gxyzf(dir.file("p.gxyzf"), field);
  const std::string header =
      "Gwyddion XYZ Field 1.0\n"
      "NChannels = 2\n"
      "NPoints = 3\n"
      "XYUnits = m\n"
      "ZUnits1 = m\n"
      "Title1 = Height\n"
      "ZUnits2 = V\n"
      "Title2 = Amplitude\n";
  ASSERT_EQ(header.size(), 120u);                   // counted by hand: 23+14+12+12+12+16+12+19
  std::string expected = header + std::string(8, '\0');  // already a multiple of 8: a full block of 8 NULs
  const double points[3][4] = {{0.0, 0.0, 1e-9, 0.5}, {1e-6, 3e-7, -2e-9, 0.25}, {-2.5e-7, 1e-6, 0.0, 1.0}};
  for (const auto& p : points)
    for (double v : p) expected += le64(v);
  EXPECT_EQ(expected.substr(128 + 8 * 3, 8), std::string("\x00\x00\x00\x00\x00\x00\xE0\x3F", 8));  // 0.5
  EXPECT_EQ(scan_test::slurp(dir.file("p.gxyzf")), expected);
}

TEST(Gxyzf, RoundTripIsExact) {
  scan_test::TempDir dir("afmkit_gxyzf_round");
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1e-6);
  const std::size_t count = 1001;
  std::vector<double> x(count), y(count), z(count), phase(count), amp(count);
  for (std::size_t k = 0; k < count; ++k) x[k] = n(rng), y[k] = n(rng), z[k] = n(rng), phase[k] = n(rng) * 1e6,
                                          amp[k] = n(rng);
  const XyzField field(x, y, {{"Height", "m", z}, {"Phase", "deg", phase}, {"", "", amp}});
  afmkit::scan::write_gxyzf(dir.file("r.gxyzf"), field);
  const XyzField back = afmkit::scan::read_gxyzf(dir.file("r.gxyzf"));
  EXPECT_EQ(back.x(), x);
  EXPECT_EQ(back.y(), y);
  ASSERT_EQ(back.channels().size(), 3u);
  EXPECT_EQ(back.channels()[0].values, z);
  EXPECT_EQ(back.channels()[1].values, phase);
  EXPECT_EQ(back.channels()[2].values, amp);
  EXPECT_EQ(back.channels()[1].title, "Phase");
  EXPECT_EQ(back.channels()[1].unit, "deg");
  EXPECT_EQ(back.channels()[2].title, "");
  EXPECT_EQ(back.xy_unit(), "m");
}

TEST(Gxyzf, HandMadeFileWithACommonZUnitsAndGridHints) {
  // ZUnits without a number applies to every channel (as in Gwyddion); XRes / YRes hints are ignored
  const auto f = afmkit::scan::parse_gxyzf(
      gxyzf("NChannels = 2\r\nNPoints = 1\r\nZUnits = A\r\nXRes = 10\r\n", {1, 2, 3, 4}), "t");
  EXPECT_EQ(f.channels()[0].unit, "A");
  EXPECT_EQ(f.channels()[1].unit, "A");
  EXPECT_EQ(f.xy_unit(), "");
  EXPECT_EQ(f.channels()[1].values, std::vector<double>{4});
}

TEST(Gxyzf, EveryBadInputNamesTheFileAndTheField) {
  const std::vector<double> one{0, 0, 1};
  expect_gxyzf_error("Gwyddion XYZ Field 2.0\nNChannels = 1\n", {"Gwyddion XYZ Field 1.0"});
  expect_gxyzf_error(gxyzf("NPoints = 1\n", one), {"missing", "NChannels"});
  expect_gxyzf_error(gxyzf("NChannels = 1\n", one), {"missing", "NPoints"});
  expect_gxyzf_error(gxyzf("NChannels = 0\nNPoints = 1\n", one), {":2:", "NChannels", "'0'"});
  expect_gxyzf_error(gxyzf("NChannels = 1025\nNPoints = 1\n", one), {"NChannels", "1024"});
  expect_gxyzf_error(gxyzf("NChannels = 1\nNPoints = 1e3\n", one), {":3:", "NPoints", "'1e3'"});
  expect_gxyzf_error(gxyzf("NChannels = 1\nNPoints = 2\n", one), {"size mismatch", "NPoints · (NChannels + 2) = 2 · 3", "truncated"});
  expect_gxyzf_error(gxyzf("NChannels = 1\nNPoints = 1\n", {0, 0, 1, 2}), {"size mismatch", "too long"});
  expect_gxyzf_error(gxyzf("NChannels = 1\nNPoints = 1\n", {0, NAN, 1}), {"point 0", "y", "not finite"});
  expect_gxyzf_error(gxyzf("NChannels = 2\nNPoints = 1\n", {0, 0, 1, INFINITY}), {"point 0", "z2", "not finite"});
  expect_gxyzf_error(gxyzf("NChannels = 1\nNPoints = 1\nTitle1 = a\tb\n", one), {"Title1", "control character"});
  expect_gxyzf_error(gxyzf("NChannels = 1\nNPoints = 1\nNPoints = 1\n", one), {"duplicate", "NPoints"});
  expect_gxyzf_error("Gwyddion XYZ Field 1.0\nNChannels = 1\nNPoints = 1\n", {"bad padding", "no NUL"});
  std::string header = "Gwyddion XYZ Field 1.0\nNChannels = 1\nNPoints = 1\n";  // 23+14+12 = 49: 7 NULs needed
  expect_gxyzf_error(header + std::string(3, '\0') + le64(0.1) + le64(0.2) + le64(0.3), {"bad padding", "byte 52"});
  expect_gxyzf_error(header + std::string(15, '\0') + le64(0.1) + le64(0.2) + le64(0.3), {"bad padding", "15 NUL bytes"});
}

TEST(Gxyzf, ConstructorNamesTheBadField) {
  auto field_of = [](auto make) {
    try {
      make();
    } catch (const InvalidParameter& e) {
      return e.parameter();
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(field_of([] { XyzField({}, {}, {{"", "", {}}}); }), "x");
  EXPECT_EQ(field_of([] { XyzField({1}, {1, 2}, {{"", "", {1}}}); }), "y");
  EXPECT_EQ(field_of([] { XyzField({1}, {1}, {}); }), "channels");
  EXPECT_EQ(field_of([] { XyzField({1}, {1}, {{"", "", {1, 2}}}); }), "channels[0].values");
  EXPECT_EQ(field_of([] { XyzField({NAN}, {1}, {{"", "", {1}}}); }), "x");
  EXPECT_EQ(field_of([] { XyzField({1}, {1}, {{"", "", {1}}, {"", "", {INFINITY}}}); }), "channels[1].values");
  EXPECT_EQ(field_of([] { XyzField({1}, {1}, {{"a\nb", "", {1}}}); }), "channels[0].title");
  EXPECT_EQ(field_of([] { XyzField({1}, {1}, {{"", "m ", {1}}}); }), "channels[0].unit");
  EXPECT_EQ(field_of([] { XyzField({1}, {1}, {{"", "", {1}}}, "\t"); }), "xy_unit");
}
