// The text reader of force curves (docs/curve-files.md#text-exports): separators, decimal comma, header units,
// column choices, segment splits, unit conversion, and its refusals (file, line, column in every message).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/curves/read_curves.hpp"

namespace ac = afmkit::io::curves;

namespace {

std::vector<ac::RawCurve> parse(const std::string& text, ac::ReadOptions options = {}) {
  return ac::parse_curves(text, "curve.txt", ".txt", options);
}

// The InputError message of parsing `text`, or "" when it parses.
std::string text_error_of(const std::string& text, ac::ReadOptions options = {}) {
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

TEST(CurvesText, SeparatorsDecimalCommaAndUnitsConvertAtTheEdge) {
  struct Case {
    std::string text;
    double h0, d0;  // first height [m], first deflection [m]
  };
  const Case cases[] = {
      {"Height (um);Defl [nm]\n3;1,5\n1;2\n2;0\n", 3e-6, 1.5e-9},     // ';' with decimal comma
      {"Height_nm,Deflection_pm\n30,100\n10,200\n20,0\n", 30e-9, 100e-12},  // ',' and '_unit' suffixes
      {"Height (nm)  Defl (nm)\n 30  1.5e0\n 10  2\n 20  0\n", 30e-9, 1.5e-9},  // blanks, "(unit)" joined
      {"Height/nm\tDefl/nm\n30\t1,5\n10\t2\n20\t0\n", 30e-9, 1.5e-9},           // tab, decimal comma, '/unit'
      {"Height (\xC2\xB5m)\tDefl (m)\n3\t1e-9\n1\t2e-9\n2\t0\n", 3e-6, 1e-9},   // micro sign
  };
  for (const Case& c : cases) {
    const auto curves = parse(c.text);
    ASSERT_EQ(curves.size(), 1u) << c.text;
    ASSERT_FALSE(curves[0].segments.empty()) << c.text;
    EXPECT_DOUBLE_EQ(curves[0].segments[0].height[0], c.h0) << c.text;
    EXPECT_DOUBLE_EQ(curves[0].segments[0].deflection[0], c.d0) << c.text;
  }
}

TEST(CurvesText, DeflectionUnitChoosesTheChannel) {
  const auto v = parse("Height (nm)\tDefl (mV)\n30\t5\n10\t7\n20\t1\n")[0];
  EXPECT_DOUBLE_EQ(v.segments[0].deflection_volts[0], 5e-3);
  EXPECT_TRUE(v.segments[0].deflection.empty());
  const auto f = parse("Height (nm)\tForce (pN)\n30\t5\n10\t7\n20\t1\n")[0];
  EXPECT_DOUBLE_EQ(f.segments[0].force[0], 5e-12);
  const auto t = parse("Time (ms)\tHeight (nm)\tDefl (nm)\n0\t30\t0\n1\t10\t1\n2\t20\t0\n")[0];
  EXPECT_DOUBLE_EQ(t.segments[0].time[1], 1e-3);
  EXPECT_DOUBLE_EQ(t.segments[0].height[1], 10e-9);
}

TEST(CurvesText, ColumnsByPositionAndNameWithUnitOptions) {
  ac::ReadOptions o;
  o.height.position = 3;
  o.height.unit = "um";
  o.deflection.position = 1;
  o.deflection.unit = "nm";
  const auto c = parse("# no header\n5\t0\t3\n6\t0\t1\n7\t0\t2\n", o)[0];
  EXPECT_DOUBLE_EQ(c.segments[0].height[0], 3e-6);
  EXPECT_DOUBLE_EQ(c.segments[0].deflection[0], 5e-9);
  ac::ReadOptions n;
  n.height.name = "piezo z";
  n.deflection.name = "signal";
  n.deflection.unit = "V";  // the header gives none for it
  const auto d = parse("Signal\tPiezo Z (nm)\n0.5\t30\n0.6\t10\n0.7\t20\n", n)[0];
  EXPECT_DOUBLE_EQ(d.segments[0].deflection_volts[0], 0.5);
  EXPECT_DOUBLE_EQ(d.segments[0].height[0], 30e-9);
}

TEST(CurvesText, HeightDirectionTowardsNegates) {
  ac::ReadOptions o;
  o.height_direction = "towards";
  const auto c = parse("Z (nm)\tDefl (nm)\n10\t0\n30\t2\n20\t0\n", o)[0];
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_DOUBLE_EQ(c.segments[0].height[0], -10e-9);
  EXPECT_EQ(c.segments[0].kind, ac::SegmentKind::approach);
  EXPECT_EQ(c.segments[0].size(), 2u);
}

TEST(CurvesText, SegmentColumnSplitsAndKindsFollowTheHeight) {
  const auto c = parse("Height (nm)\tDefl (nm)\tSegment\n30\t0\t0\n20\t1\t0\n20\t1\t1\n20\t1\t1\n20\t1\t2\n30\t0\t2\n")[0];
  ASSERT_EQ(c.segments.size(), 3u);
  EXPECT_EQ(c.segments[0].kind, ac::SegmentKind::approach);
  EXPECT_EQ(c.segments[1].kind, ac::SegmentKind::pause);
  EXPECT_EQ(c.segments[2].kind, ac::SegmentKind::retract);
  EXPECT_EQ(c.segments[1].size(), 2u);
}

TEST(CurvesText, NanPaddingAtTheEndIsDroppedAndNoted) {
  const auto c = parse("Height (nm),Defl (nm)\n30,0\n10,2\n20,0\n,\nNaN,NaN\n")[0];
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_EQ(c.segments[1].size(), 1u);
  ASSERT_EQ(c.notes.size(), 1u);
  EXPECT_NE(c.notes[0].find("lines 5-6"), std::string::npos) << c.notes[0];
}

// Refusals: every message names the file and the line / column.
TEST(CurvesText, NanInTheMiddleIsRefused) {
  const std::string msg = text_error_of("Height (nm)\tDefl (nm)\n30\t0\n20\tNaN\n10\t2\n20\t0\n");
  EXPECT_NE(msg.find("curve.txt: line 3, column 2: missing value"), std::string::npos) << msg;
}

TEST(CurvesText, ANonNumberCellIsRefusedWithLineAndColumn) {
  const std::string msg = text_error_of("Height (nm)\tDefl (nm)\n30\t0\n20\t1\n10\tabc\n");
  EXPECT_NE(msg.find("curve.txt: line 4, column 2: 'abc' is not a number"), std::string::npos) << msg;
  const std::string inf = text_error_of("Height (nm)\tDefl (nm)\n30\t0\n20\t1\n10\tinf\n");
  EXPECT_NE(inf.find("line 4, column 2: 'inf' is not a finite number"), std::string::npos) << inf;
  const std::string wide = text_error_of("Height (nm)\tDefl (nm)\n30\t0\n20\t1\t7\n");
  EXPECT_NE(wide.find("line 3: 3 columns"), std::string::npos) << wide;
}

TEST(CurvesText, AHeaderWithoutUnitsAndNoUnitOptionIsRefused) {
  const std::string msg = text_error_of("Height\tDeflection\n30\t0\n10\t1\n20\t0\n");
  EXPECT_NE(msg.find("curve.txt: the height column 1 ('Height', line 1) has no unit in its header"),
            std::string::npos)
      << msg;
  const std::string bare = text_error_of("30\t0\n10\t1\n20\t0\n");
  EXPECT_NE(bare.find("has no unit (no header row)"), std::string::npos) << bare;
  const std::string unknown = text_error_of("Height (furlong)\tDefl (nm)\n30\t0\n10\t1\n");
  EXPECT_NE(unknown.find("unknown unit 'furlong'"), std::string::npos) << unknown;
  const std::string wrong = text_error_of("Height (V)\tDefl (nm)\n30\t0\n10\t1\n");
  EXPECT_NE(wrong.find("the unit 'V' is a voltage, the height must be a length"), std::string::npos) << wrong;
}

TEST(CurvesText, ChoicesThatDoNotExistAreRefused) {
  ac::ReadOptions o;
  o.height.name = "Zpiezo";
  const std::string msg = text_error_of("Height (nm)\tDefl (nm)\n30\t0\n10\t1\n", o);
  EXPECT_NE(msg.find("no column named 'Zpiezo' for the height (header, line 1: 1 'Height (nm)', 2 'Defl (nm)')"),
            std::string::npos)
      << msg;
  ac::ReadOptions p;
  p.deflection.position = 5;
  EXPECT_NE(text_error_of("Height (nm)\tDefl (nm)\n30\t0\n10\t1\n", p).find("the deflection column is 5, but the file has 2"),
            std::string::npos);
  const std::string none = text_error_of("Height (nm)\tAmplitude (nm)\n30\t0\n10\t1\n");
  EXPECT_NE(none.find("no deflection or force column"), std::string::npos) << none;
}

TEST(CurvesText, NoDataAndBinaryInputAreRefused) {
  EXPECT_NE(text_error_of("").find("no rows of numbers"), std::string::npos);
  EXPECT_NE(text_error_of("just words\nand more\n").find("no rows of numbers"), std::string::npos);
  EXPECT_NE(text_error_of(std::string("PK\x03\x04\0\0", 6)).find("not a readable JPK"), std::string::npos);
  EXPECT_NE(text_error_of(std::string("ab\0cd", 5)).find("byte 2: a NUL byte"), std::string::npos);
}

TEST(CurvesText, BadOptionsAreRefusedNamingTheOption) {
  ac::ReadOptions o;
  o.format = "bruker";
  EXPECT_NE(text_error_of("1\t2\n", o).find("format 'bruker' is not one of"), std::string::npos);
  ac::ReadOptions s;
  s.separator = "pipe";
  EXPECT_NE(text_error_of("1\t2\n", s).find("separator 'pipe'"), std::string::npos);
  ac::ReadOptions k;
  k.spring_constant = -1;
  EXPECT_NE(text_error_of("1\t2\n", k).find("spring constant = -1 N/m: must be a positive"), std::string::npos);
  ac::ReadOptions d;
  d.height_direction = "up";
  EXPECT_NE(text_error_of("H (nm)\tD (nm)\n1\t2\n2\t3\n", d).find("height direction 'up'"), std::string::npos);
}

TEST(CurvesText, CalibrationOptionsOverrideTheFile) {
  ac::ReadOptions o;
  o.spring_constant = 0.5;
  o.invols = 3e-8;
  const auto c = parse("# springConstant: 0.1\n# sensitivity: 1e-8\nH (nm)\tDefl (V)\n30\t0\n10\t1\n20\t0\n", o)[0];
  EXPECT_DOUBLE_EQ(c.metadata.spring_constant, 0.5);
  EXPECT_DOUBLE_EQ(c.metadata.invols, 3e-8);
  const auto f = parse("# springConstant: 0.1\n# sensitivity: 1e-8\nH (nm)\tDefl (V)\n30\t0\n10\t1\n20\t0\n")[0];
  EXPECT_DOUBLE_EQ(f.metadata.spring_constant, 0.1);
  EXPECT_DOUBLE_EQ(f.metadata.invols, 1e-8);
}

TEST(CurvesText, NonRegularFilesAreRefusedWithoutBlocking) {
  const std::string dir = ::testing::TempDir();
  try {
    ac::read_curves(dir);
    FAIL() << "a directory was read";
  } catch (const afmkit::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos) << e.what();
  }
  const std::string fifo = dir + "/curves_fifo_" + std::to_string(::getpid());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    ac::read_curves(fifo);
    ADD_FAILURE() << "a FIFO was read";
  } catch (const afmkit::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fifo), std::string::npos) << e.what();
  }
  ::unlink(fifo.c_str());
  EXPECT_THROW(ac::read_curves(dir + "/does_not_exist.txt"), afmkit::InputError);
}

TEST(CurvesText, NonPositiveCalibrationInTheFileIsRefusedWithItsLine) {
  const std::string msg = text_error_of("# springConstant: -0.1\nHeight (nm)\tDefl (V)\n30\t0\n10\t1\n20\t0\n");
  EXPECT_NE(msg.find("curve.txt: line 1: 'springConstant: -0.1': the spring constant must be positive"),
            std::string::npos)
      << msg;
  const std::string zero = text_error_of("# InvOLS: 0\nHeight (nm)\tDefl (V)\n30\t0\n10\t1\n20\t0\n");
  EXPECT_NE(zero.find("line 1: 'InvOLS: 0': the InvOLS must be positive"), std::string::npos) << zero;
}

TEST(CurvesText, TrailingSeparatorsAndAUnitsRowUnderTheNames) {
  // Rows ending with a tab (an empty last column) under a header without it, and the reverse.
  const auto a = parse("Height (nm)\tDefl (nm)\n30\t0\t\n10\t2\t\n20\t0\t\n")[0];
  EXPECT_DOUBLE_EQ(a.segments[0].deflection[1], 2e-9);
  const auto b = parse("Height (nm)\tDefl (nm)\t\n30\t0\n10\t2\n20\t0\n")[0];
  EXPECT_DOUBLE_EQ(b.segments[0].deflection[1], 2e-9);
  // Names, then units on their own row.
  const auto c = parse("Height;Deflection\nnm;(pm)\n30;5\n10;7\n20;1\n")[0];
  EXPECT_DOUBLE_EQ(c.segments[0].height[0], 30e-9);
  EXPECT_DOUBLE_EQ(c.segments[0].deflection[0], 5e-12);
  // A last column with values is data, not a separator: the two-cell line is then no header.
  const std::string msg = text_error_of("Height (nm)\tDefl (nm)\n30\t0\t1\n10\t2\t1\n20\t0\t1\n");
  EXPECT_NE(msg.find("has no unit (no header row)"), std::string::npos) << msg;
}

TEST(CurvesText, SegmentColumnWithPaddingRows) {
  const auto c = parse("Height (nm),Defl (nm),Segment\n30,0,0\n10,2,0\n10,2,1\n30,0,1\n,,\n")[0];
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_EQ(c.segments[1].size(), 2u);
  EXPECT_NE(text_error_of("Height (nm),Defl (nm),Segment\n30,0,0\n10,2,\n10,2,1\n").find("line 3, column 3: the segment "
                                                                                     "column has no value"),
            std::string::npos);
}
