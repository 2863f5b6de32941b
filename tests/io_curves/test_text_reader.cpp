// The text reader of force curves (docs/curve-files.md#text-exports): separators, decimal comma, header units,
// column choices, segment splits, unit conversion, and its refusals (file, line, column in every message).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "afmkit/core/error.hpp"
#include "afmkit/io/curves/read_curves.hpp"

namespace ac = afmkit::io::curves;

namespace {

std::vector<ac::RawCurve> parse(const std::string& text, ac::ReadOptions options = {}) {
  return ac::parse_curves(text, "curve.txt", ".txt", options);
}

// The InputError message of parsing `text`, or "" when it parses.
std::string error_of(const std::string& text, ac::ReadOptions options = {}) {
  try {
    parse(text, options);
  } catch (const afmkit::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(CurvesText, TabSeparatedHeaderWithUnitsSplitsAtTheTurningPoint) {
  // Height (nm) down to 0 then back up; deflection in nm: approach rows 1-3 (3 is the turning point), retract 4-5.
  const std::string text = "# a comment\nHeight (nm)\tDefl (nm)\n30\t0\n20\t0.5\n10\t2\n20\t0.25\n30\t0\n";
  const auto curves = parse(text);
  ASSERT_EQ(curves.size(), 1u);
  const auto& c = curves[0];
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_EQ(c.segments[0].kind, ac::SegmentKind::approach);
  EXPECT_EQ(c.segments[1].kind, ac::SegmentKind::retract);
  ASSERT_EQ(c.segments[0].height.size(), 3u);
  EXPECT_DOUBLE_EQ(c.segments[0].height[0], 30e-9);
  EXPECT_DOUBLE_EQ(c.segments[0].height[2], 10e-9);
  EXPECT_DOUBLE_EQ(c.segments[0].deflection[2], 2e-9);
  ASSERT_EQ(c.segments[1].height.size(), 2u);
  EXPECT_DOUBLE_EQ(c.segments[1].deflection[0], 0.25e-9);
  EXPECT_TRUE(c.segments[0].force.empty());
}
