// Asylum .ibw (Igor binary wave v5): the real file's known values (shared data README) and synthetic waves for
// the structure (Indexes split, NaN padding and holes, sizes, checksum, truncation, wrong magic).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "afmkit/core/error.hpp"
#include "afmkit/io/curves/read_curves.hpp"
#include "ibw_builder.hpp"
#include "real_files.hpp"

namespace ac = afmkit::io::curves;

namespace {

std::string error_of(const std::string& bytes, ac::ReadOptions o = {}) {
  try {
    ac::parse_curves(bytes, "w.ibw", ".ibw", o);
  } catch (const afmkit::InputError& e) {
    return e.what();
  }
  return "";
}

// ZSnsr up 0..4 then down: 9 points; Defl = 1e-9 * index.
std::string triangle(const std::string& note, float hole = 0.0f, int hole_at = -1, int pad = 0) {
  std::vector<float> z, d, raw;
  for (int i = 0; i < 9; ++i) {
    z.push_back(static_cast<float>(i <= 4 ? i : 8 - i) * 1e-7f);
    d.push_back(static_cast<float>(i) * 1e-9f);
    raw.push_back(0.5f);
  }
  if (hole_at >= 0) d[static_cast<std::size_t>(hole_at)] = hole;
  for (int i = 0; i < pad; ++i) {
    z.push_back(std::numeric_limits<float>::quiet_NaN());
    d.push_back(std::numeric_limits<float>::quiet_NaN());
    raw.push_back(std::numeric_limits<float>::quiet_NaN());
  }
  return curves_test::make_ibw({"Raw", "Defl", "ZSnsr"}, {raw, d, z}, note);
}

}  // namespace

TEST(CurvesIbw, KnownValuesOfTheRealFile) {
  CURVES_REAL_FILE(path, "asylum_SiN_FD_plot.ibw");
  const auto curves = ac::read_curves(path);
  ASSERT_EQ(curves.size(), 1u);
  const auto& c = curves[0];
  EXPECT_EQ(c.metadata.format, "ibw");
  EXPECT_DOUBLE_EQ(c.metadata.spring_constant, 1.1841);  // README values, from the note
  EXPECT_DOUBLE_EQ(c.metadata.invols, 4.499e-8);
  EXPECT_DOUBLE_EQ(c.metadata.resonance_frequency, 23251.0);
  EXPECT_DOUBLE_EQ(c.metadata.quality_factor, 139.13);
  // Note "Indexes: 0,1008,2015", "Direction: NaN,1,-1": extend = points 0..1008, retract = 1009..2015.
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_EQ(c.segments[0].kind, ac::SegmentKind::approach);
  EXPECT_EQ(c.segments[1].kind, ac::SegmentKind::retract);
  EXPECT_EQ(c.segments[0].size(), 1009u);
  EXPECT_EQ(c.segments[1].size(), 1007u);
  // Heights are -ZSnsr: the extend moves ZSnsr up (towards the sample), so our height goes down.
  EXPECT_LT(c.segments[0].height.back(), c.segments[0].height.front());
  EXPECT_GT(c.segments[1].height.back(), c.segments[1].height.front());
  EXPECT_NEAR(c.segments[0].height[0], -1.1956911976085394e-06, 1e-18);  // -ZSnsr[0] (float32 in the file)
  EXPECT_NEAR(c.segments[0].deflection[0], -3.272485393779334e-09, 1e-20);
  EXPECT_GT(c.segments[0].deflection.back(), 0.0);  // repulsive at the turning point, as ours
  ASSERT_EQ(c.segments[1].time.size(), 1007u);
  EXPECT_NEAR(c.segments[1].time[0], 1009 * 0.0005, 1e-12);  // 2000 points per second
}

TEST(CurvesIbw, SyntheticWaveIndexesAndNoteSplit) {
  const auto c = ac::parse_curves(triangle("SpringConstant: 2\rInvOLS: 5e-08\rIndexes: 0,4,8\rDirection: NaN,1,-1\r"),
                                  "w.ibw", ".ibw")[0];
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_EQ(c.segments[0].size(), 5u);
  EXPECT_EQ(c.segments[1].size(), 4u);
  EXPECT_FLOAT_EQ(static_cast<float>(c.segments[0].height[4]), -4e-7f);
  EXPECT_FLOAT_EQ(static_cast<float>(c.segments[1].deflection[0]), 5e-9f);
  EXPECT_DOUBLE_EQ(c.metadata.spring_constant, 2.0);
  EXPECT_DOUBLE_EQ(c.metadata.invols, 5e-8);
}

TEST(CurvesIbw, WithoutIndexesSplitsAtTheLowestHeight) {
  const auto c = ac::parse_curves(triangle(""), "w.ibw", ".ibw")[0];
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_EQ(c.segments[0].kind, ac::SegmentKind::approach);
  EXPECT_EQ(c.segments[0].size(), 5u);
}

TEST(CurvesIbw, NanPaddingAtTheEndIsDroppedAndNoted) {
  const auto c = ac::parse_curves(triangle("", 0, -1, 3), "w.ibw", ".ibw")[0];
  EXPECT_EQ(c.segments[0].size() + c.segments[1].size(), 9u);
  ASSERT_FALSE(c.notes.empty());
  EXPECT_NE(c.notes[0].find("padding"), std::string::npos);
}

TEST(CurvesIbw, NanInTheMiddleIsRefusedNamingPointAndColumn) {
  const std::string msg = error_of(triangle("", std::numeric_limits<float>::quiet_NaN(), 3));
  EXPECT_NE(msg.find("w.ibw"), std::string::npos) << msg;
  EXPECT_NE(msg.find("point 3, column 'Defl'"), std::string::npos) << msg;
}

TEST(CurvesIbw, HugeDeclaredSizesAreRefusedBeforeAllocation) {
  std::string b = triangle("");
  const std::int32_t huge = 0x7fffffff;
  std::memcpy(&b[64 + 68], &huge, 4);  // rows
  std::memcpy(&b[64 + 12], &huge, 4);  // npnts
  // Fix the checksum so that the size check (not the checksum) refuses it.
  std::memset(&b[2], 0, 2);
  std::uint16_t sum = 0;
  for (std::size_t i = 0; i < 384; i += 2) {
    std::uint16_t v;
    std::memcpy(&v, &b[i], 2);
    sum = static_cast<std::uint16_t>(sum + v);
  }
  const auto check = static_cast<std::uint16_t>(-sum);
  std::memcpy(&b[2], &check, 2);
  const std::string msg = error_of(b);
  EXPECT_NE(msg.find("more than the file"), std::string::npos) << msg;
  std::string note = triangle("");
  const std::int32_t big_note = 0x7ffffff0;
  std::memcpy(&note[12], &big_note, 4);  // note size (in the checksummed header: fix it too)
  std::memset(&note[2], 0, 2);
  sum = 0;
  for (std::size_t i = 0; i < 384; i += 2) {
    std::uint16_t v;
    std::memcpy(&v, &note[i], 2);
    sum = static_cast<std::uint16_t>(sum + v);
  }
  const auto check2 = static_cast<std::uint16_t>(-sum);
  std::memcpy(&note[2], &check2, 2);
  const std::string msg2 = error_of(note);
  EXPECT_NE(msg2.find("truncated: the note"), std::string::npos) << msg2;
}

TEST(CurvesIbw, TruncatedWrongMagicAndChecksumAreRefused) {
  const std::string good = triangle("Indexes: 0,4,8\r");
  for (std::size_t cut : {std::size_t{0}, std::size_t{1}, std::size_t{100}, std::size_t{390}, good.size() - 5}) {
    const std::string msg = error_of(good.substr(0, cut));
    EXPECT_NE(msg.find("w.ibw"), std::string::npos) << cut << ": " << msg;
    EXPECT_FALSE(msg.empty()) << cut;
  }
  std::string magic = good;
  magic[0] = 7;
  EXPECT_NE(error_of(magic).find("not an Igor binary wave"), std::string::npos);
  std::string sum = good;
  sum[64 + 30] ^= 1;  // a byte of the wave name
  EXPECT_NE(error_of(sum).find("checksum"), std::string::npos);
}

TEST(CurvesIbw, NoLabelsOrNoZSnsrIsRefused) {
  const std::vector<float> v(5, 1.0f);
  const std::string wrong = curves_test::make_ibw({"A", "B"}, {v, v}, "");
  EXPECT_NE(error_of(wrong).find("no height column 'ZSnsr' (columns: A, B)"), std::string::npos) << error_of(wrong);
}

TEST(CurvesIbw, NonPositiveCalibrationInTheNoteIsRefused) {
  EXPECT_NE(error_of(triangle("SpringConstant: 0\r")).find("note: 'SpringConstant: 0': must be positive"),
            std::string::npos)
      << error_of(triangle("SpringConstant: 0\r"));
  const auto c = ac::parse_curves(triangle("ThermalQ: 0\r"), "w.ibw", ".ibw")[0];  // no thermal tune: ignored
  EXPECT_TRUE(std::isnan(c.metadata.quality_factor));
}
