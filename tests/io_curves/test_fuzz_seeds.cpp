// The fuzz seed corpora (fuzz/corpus/fuzz_io_curves_*) are valid inputs: each parses, so the fuzzers start from
// inside the formats. The synthetic JPK archives also test the shared-data layout (lcd-info channel definitions)
// that the real file does not have: expected values computed by hand from the seed's headers.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "afmkit/io/curves/read_curves.hpp"

namespace ac = afmkit::io::curves;

namespace {

std::string seed(const std::string& target, const std::string& name) {
  std::ifstream in(std::string(AFMKIT_SOURCE_DIR) + "/fuzz/corpus/" + target + "/" + name, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(CurvesFuzzSeeds, JpkArchivesOldAndSharedLayouts) {
  for (const char* name : {"old_layout_stored", "shared_layout_deflated"}) {
    const std::string bytes = seed("fuzz_io_curves_jpk", name);
    ASSERT_FALSE(bytes.empty()) << name;
    const auto c = ac::parse_curves(bytes, name, ".jpk-force")[0];
    ASSERT_EQ(c.segments.size(), 2u) << name;
    const auto& a = c.segments[0];
    // height raw 0 -> 0 V -> nominal 0 * (-1e-6) + 1e-4 = 1e-4 m; raw 500 -> 0.5 V -> 1e-4 - 5e-7 m.
    EXPECT_DOUBLE_EQ(a.height[0], 1e-4) << name;
    EXPECT_DOUBLE_EQ(a.height[5], 1e-4 - 0.5e-6) << name;
    // vDeflection raw 400 -> 0.4 V -> 2e-8 m -> 1e-9 N; k = 0.05 N/m, InvOLS = 5e-8 m/V.
    EXPECT_DOUBLE_EQ(a.deflection_volts[5], 0.4) << name;
    EXPECT_DOUBLE_EQ(a.deflection[5], 0.4 * 5e-8) << name;
    EXPECT_DOUBLE_EQ(a.force[5], 0.4 * 5e-8 * 0.05) << name;
    EXPECT_DOUBLE_EQ(c.metadata.spring_constant, 0.05) << name;
    EXPECT_DOUBLE_EQ(c.metadata.invols, 5e-8) << name;
    EXPECT_EQ(c.metadata.instrument, "JPK seed") << name;
    EXPECT_EQ(c.segments[1].kind, ac::SegmentKind::retract) << name;
    EXPECT_DOUBLE_EQ(c.segments[1].time[0], 0.5) << name;
  }
}

TEST(CurvesFuzzSeeds, EveryTextAndIbwSeedParses) {
  static const char* const formats[] = {"text", "jpk-txt", "asylum-txt", "nanoscope-txt", "ntmdt-txt",
                                        "afmworkshop-csv", "auto"};
  for (const char* target : {"fuzz_io_curves_text", "fuzz_io_curves_ibw"}) {
    const std::string dir = std::string(AFMKIT_SOURCE_DIR) + "/fuzz/corpus/" + target;
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      const std::string name = entry.path().filename().string();
      const std::string bytes = seed(target, name);
      ASSERT_FALSE(bytes.empty());
      ac::ReadOptions o;
      const bool text = std::string(target) == "fuzz_io_curves_text";
      const auto control = static_cast<unsigned char>(bytes[0]);
      o.format = text ? formats[control % 7] : "ibw";
      if (text && (control & 0x80)) o.decimal = "comma";
      EXPECT_NO_THROW(ac::parse_curves(bytes.substr(1), name, text ? ".txt" : ".ibw", o)) << target << "/" << name;
      ++count;
    }
    EXPECT_GE(count, 3) << target;
  }
}

TEST(CurvesFuzzSeeds, JpkForceMapGivesOneCurvePerIndex) {
  const std::string bytes = seed("fuzz_io_curves_jpk", "force_map_two_indices");
  ASSERT_FALSE(bytes.empty());
  const auto curves = ac::parse_curves(bytes, "map.jpk-force-map", ".jpk-force-map");
  ASSERT_EQ(curves.size(), 2u);
  EXPECT_EQ(curves[0].origin, "map.jpk-force-map (index/0)");
  EXPECT_EQ(curves[1].origin, "map.jpk-force-map (index/1)");
  // Index i's last extend deflection is raw 200 (i + 1) -> 0.2 (i + 1) V -> x 5e-8 m/V -> x 0.05 N/m.
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(curves[static_cast<std::size_t>(i)].segments.size(), 2u);
    EXPECT_DOUBLE_EQ(curves[static_cast<std::size_t>(i)].segments[0].force[3], 0.2 * (i + 1) * 5e-8 * 0.05);
  }
}

TEST(CurvesFuzzSeeds, BigEndianIbwSeedValues) {
  const std::string bytes = seed("fuzz_io_curves_ibw", "v5_be_noindexes");
  ASSERT_FALSE(bytes.empty());
  const auto c = ac::parse_curves(bytes.substr(1), "be.ibw", ".ibw")[0];
  // ZSnsr = 0, 1, ..., 4, 3, ..., 0 (x 1e-7 m), Defl = index x 1e-9 m, big-endian float32: split after point 4.
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_FLOAT_EQ(static_cast<float>(c.segments[0].height[4]), -4e-7f);
  EXPECT_FLOAT_EQ(static_cast<float>(c.segments[0].deflection[4]), 4e-9f);
  EXPECT_EQ(c.segments[1].size(), 4u);
}
