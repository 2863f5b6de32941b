// The text presets on real exports: AFM Workshop CSV and NT-MDT text (shared data). Expected values are read from
// the file's text here (first and last rows) and converted by hand, independently of the reader.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "afmkit/core/error.hpp"
#include "afmkit/io/curves/read_curves.hpp"
#include "real_files.hpp"

namespace ac = afmkit::io::curves;

TEST(CurvesRealText, AfmWorkshopCsv) {
  CURVES_REAL_FILE(path, "afmworkshop_single_2020-02-14.csv");
  ac::ReadOptions o;
  o.format = "afmworkshop-csv";
  const auto curves = ac::read_curves(path, o);
  ASSERT_EQ(curves.size(), 1u);
  const auto& c = curves[0];
  ASSERT_EQ(c.segments.size(), 2u);
  const auto& a = c.segments[0];
  const auto& r = c.segments[1];
  EXPECT_EQ(a.kind, ac::SegmentKind::approach);
  EXPECT_EQ(r.kind, ac::SegmentKind::retract);
  // Line 13: "15072.4571,1276.4373,18452.4571,3809.6950": Z-Sense grows towards the sample, so height = -Z-Sense;
  // the force column is in nN, positive repulsive as ours.
  ASSERT_GT(a.size(), 100u);
  EXPECT_DOUBLE_EQ(a.height[0], -15072.4571e-9);
  EXPECT_DOUBLE_EQ(a.force[0], 1276.4373e-9);
  EXPECT_DOUBLE_EQ(r.height[0], -18452.4571e-9);
  EXPECT_DOUBLE_EQ(r.force[0], 3809.6950e-9);
  EXPECT_EQ(a.size(), r.size());
  EXPECT_TRUE(a.deflection.empty());
  EXPECT_LT(a.height.back(), a.height.front());  // approach: towards the sample
  EXPECT_GT(r.height.back(), r.height.front());
  EXPECT_EQ(c.metadata.instrument, "AFM Workshop");
}

TEST(CurvesRealText, NtmdtText) {
  CURVES_REAL_FILE(path, "ntmdt_gel4_curve51.txt");
  ac::ReadOptions o;
  o.format = "ntmdt-txt";
  const auto curves = ac::read_curves(path, o);
  ASSERT_EQ(curves.size(), 1u);
  const auto& c = curves[0];
  ASSERT_EQ(c.segments.size(), 2u);
  const auto& a = c.segments[0];
  const auto& r = c.segments[1];
  // 1000 rows sorted by height from -7999,9482 nm (line 1, in contact) to -0,0006 nm (line 1000, free): the
  // approach ran from the free end, so its samples come in reverse row order; the retract in row order.
  ASSERT_EQ(a.size(), 1000u);
  ASSERT_EQ(r.size(), 1000u);
  EXPECT_DOUBLE_EQ(a.height.front(), -0.0006e-9);
  EXPECT_DOUBLE_EQ(a.height.back(), -7999.9482e-9);
  EXPECT_DOUBLE_EQ(a.deflection_volts.back(), 1.4726e-9);  // DFL in nA, kept in deflection_volts as A
  EXPECT_DOUBLE_EQ(a.deflection_volts.front(), -1.1033e-9);
  EXPECT_DOUBLE_EQ(r.height.front(), -7999.9482e-9);
  EXPECT_DOUBLE_EQ(r.deflection_volts.front(), 1.4711e-9);
  EXPECT_DOUBLE_EQ(r.deflection_volts.back(), -1.0926e-9);
  EXPECT_TRUE(std::isnan(c.metadata.spring_constant));
  // Lines 1-179 repeat 1,4726 (column 2) and 1,4711 (column 3): kept, and said.
  ASSERT_GE(c.notes.size(), 2u);
  EXPECT_NE(c.notes[0].find("lines 1-179: column 2 repeats one value (1.4726) 179 times"), std::string::npos)
      << c.notes[0];
  EXPECT_NE(c.notes[1].find("lines 1-179: column 3"), std::string::npos) << c.notes[1];
}
