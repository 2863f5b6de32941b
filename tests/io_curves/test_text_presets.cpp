// The text presets on synthetic exports laid out as the vendors write them (docs/curve-files.md#presets), and on
// files of another instrument given the wrong preset.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "afmkit/core/error.hpp"
#include "afmkit/io/curves/read_curves.hpp"
#include "real_files.hpp"

namespace ac = afmkit::io::curves;

namespace {

ac::RawCurve parse(const std::string& text, const std::string& format) {
  ac::ReadOptions o;
  o.format = format;
  const auto curves = ac::parse_curves(text, "export.txt", ".txt", o);
  EXPECT_EQ(curves.size(), 1u);
  return curves.at(0);
}

std::string preset_error_of(const std::string& text, const std::string& format) {
  try {
    parse(text, format);
  } catch (const afmkit::InputError& e) {
    return e.what();
  }
  return "";
}

std::string error_of_file(const std::string& path, const std::string& format) {
  ac::ReadOptions o;
  o.format = format;
  try {
    ac::read_curves(path, o);
  } catch (const afmkit::InputError& e) {
    return e.what();
  }
  return "";
}

// JPK Data Processing text export: header comments, then per segment "# segment:", "# columns:", "# units:".
const std::string kJpk =
    "# xPosition: 1.0E-5\n"
    "# springConstant: 0.0434\n"
    "# sensitivity: 7.0E-8\n"
    "#\n"
    "# segmentIndex: 0\n"
    "# segment: extend\n"
    "# columns: height vDeflection strainGaugeHeight seriesTime\n"
    "# fancyNames: \"Height\" \"Vertical Deflection\" \"Height (measured)\" \"Series Time\"\n"
    "# units: m N m s\n"
    "#\n"
    "3.0E-6 -1.0E-11 2.9E-6 0.0\n"
    "2.0E-6 2.0E-10 1.9E-6 0.5\n"
    "\n"
    "# segmentIndex: 1\n"
    "# segment: retract\n"
    "# columns: height vDeflection strainGaugeHeight seriesTime\n"
    "# units: m N m s\n"
    "#\n"
    "2.0E-6 1.5E-10 1.95E-6 1.0\n"
    "3.0E-6 -2.0E-11 2.95E-6 1.5\n";

}  // namespace

TEST(CurvesPresets, JpkTxt) {
  const auto c = parse(kJpk, "jpk-txt");
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_EQ(c.segments[0].kind, ac::SegmentKind::approach);
  EXPECT_EQ(c.segments[1].kind, ac::SegmentKind::retract);
  EXPECT_DOUBLE_EQ(c.segments[0].height[0], 2.9e-6);  // the measured height is preferred
  EXPECT_DOUBLE_EQ(c.segments[0].force[1], 2.0e-10);  // vDeflection in N: a force
  EXPECT_DOUBLE_EQ(c.segments[1].time[1], 1.5);
  EXPECT_DOUBLE_EQ(c.metadata.spring_constant, 0.0434);
  EXPECT_DOUBLE_EQ(c.metadata.invols, 7.0e-8);
  // The piezo height by name.
  ac::ReadOptions o;
  o.format = "jpk-txt";
  o.height.name = "height";
  EXPECT_DOUBLE_EQ(ac::parse_curves(kJpk, "e.txt", ".txt", o)[0].segments[0].height[0], 3.0e-6);
}

TEST(CurvesPresets, JpkTxtWithoutRetractIsRefused) {
  const std::string extend_only = kJpk.substr(0, kJpk.find("\n# segmentIndex: 1"));
  const std::string msg = preset_error_of(extend_only, "jpk-txt");
  EXPECT_NE(msg.find("export.txt: no retract part (the jpk-txt preset"), std::string::npos) << msg;
}

TEST(CurvesPresets, JpkTxtColumnsThatDisagreeAreRefused) {
  std::string bad = kJpk;
  bad.replace(bad.rfind("# units: m N m s"), 16, "# units: m N m");
  EXPECT_NE(preset_error_of(bad, "jpk-txt").find("line 17: '# units:' gives 3 units for 4 columns"), std::string::npos)
      << preset_error_of(bad, "jpk-txt");
}

TEST(CurvesPresets, NanoscopeTxtSideBySideWithUnitsInNames) {
  // Ramp (extension towards the sample) in nm, deflection in nm; the retract rows written in recording order.
  const std::string text =
      "Calc_Ramp_Ex_nm\tCalc_Ramp_Rt_nm\tDefl_nm_Ex\tDefl_nm_Rt\n"
      "0\t100\t0\t5\n"
      "50\t50\t0.5\t0.5\n"
      "100\t0\t5\t-1\n";
  const auto c = parse(text, "nanoscope-txt");
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_DOUBLE_EQ(c.segments[0].height[2], -100e-9);  // height = -ramp
  EXPECT_DOUBLE_EQ(c.segments[0].deflection[2], 5e-9);
  EXPECT_DOUBLE_EQ(c.segments[1].height[0], -100e-9);
  EXPECT_DOUBLE_EQ(c.segments[1].deflection[2], -1e-9);
  EXPECT_TRUE(c.notes.empty());
  // pN deflection goes to the force channel.
  const auto f = parse("Calc_Ramp_Ex_nm\tCalc_Ramp_Rt_nm\tDefl_pN_Ex\tDefl_pN_Rt\n0\t100\t1\t2\n100\t0\t3\t4\n",
                       "nanoscope-txt");
  EXPECT_DOUBLE_EQ(f.segments[0].force[1], 3e-12);
}

TEST(CurvesPresets, NanoscopeTxtRetractSortedLikeTheExtendIsReversed) {
  const std::string text =
      "Calc_Ramp_Ex_nm\tCalc_Ramp_Rt_nm\tDefl_V_Ex\tDefl_V_Rt\n"
      "0\t0\t0\t-0.1\n"
      "100\t100\t1\t0.9\n";
  const auto c = parse(text, "nanoscope-txt");
  EXPECT_DOUBLE_EQ(c.segments[1].height[0], -100e-9);  // recording order: from the sample away
  EXPECT_DOUBLE_EQ(c.segments[1].deflection_volts[0], 0.9);
  ASSERT_EQ(c.notes.size(), 1u);
  EXPECT_NE(c.notes[0].find("reversed"), std::string::npos);
}

TEST(CurvesPresets, NanoscopeTxtWithoutRetractColumnsIsRefused) {
  const std::string msg = preset_error_of("Calc_Ramp_Ex_nm\tDefl_nm_Ex\n0\t0\n100\t5\n", "nanoscope-txt");
  EXPECT_NE(msg.find("line 1: not the layout of the nanoscope-txt preset"), std::string::npos) << msg;
  const std::string empty_rt =
      preset_error_of("Calc_Ramp_Ex_nm\tCalc_Ramp_Rt_nm\tDefl_nm_Ex\tDefl_nm_Rt\n0\t\t0\t\n100\t\t5\t\n", "nanoscope-txt");
  EXPECT_NE(empty_rt.find("no retract part"), std::string::npos) << empty_rt;
}

TEST(CurvesPresets, AsylumTxt) {
  const std::string text =
      "# SpringConstant: 1.2\n# InvOLS: 4.5e-08\n"
      "SiN0000Raw\tSiN0000Defl\tSiN0000ZSnsr\n"
      "1e-6\t-1e-9\t1.0e-6\n"
      "1e-6\t2e-9\t1.2e-6\n"
      "1e-6\t5e-9\t1.4e-6\n"
      "1e-6\t1e-9\t1.2e-6\n";
  const auto c = parse(text, "asylum-txt");
  ASSERT_EQ(c.segments.size(), 2u);
  EXPECT_DOUBLE_EQ(c.segments[0].height[0], -1.0e-6);  // -ZSnsr
  EXPECT_EQ(c.segments[0].kind, ac::SegmentKind::approach);
  EXPECT_EQ(c.segments[0].size(), 3u);
  EXPECT_DOUBLE_EQ(c.segments[0].deflection[2], 5e-9);
  EXPECT_DOUBLE_EQ(c.metadata.spring_constant, 1.2);
  EXPECT_DOUBLE_EQ(c.metadata.invols, 4.5e-8);
}

TEST(CurvesPresets, AsylumTxtWithoutRetractIsRefused) {
  const std::string msg = preset_error_of("SiN0000Defl\tSiN0000ZSnsr\n0\t1e-6\n1e-9\t2e-6\n", "asylum-txt");
  EXPECT_NE(msg.find("no retract part"), std::string::npos) << msg;
}

TEST(CurvesPresets, FilesOfAnotherInstrumentAreRefused) {
  CURVES_REAL_FILE(ws, "afmworkshop_single_2020-02-14.csv");
  CURVES_REAL_FILE(nt, "ntmdt_gel4_curve51.txt");
  CURVES_REAL_FILE(jpk, "jpk_spot3-0192.jpk-force");
  CURVES_REAL_FILE(ibw, "asylum_SiN_FD_plot.ibw");
  struct Case {
    std::string path, format, expect;
  };
  const Case cases[] = {
      {ws, "ntmdt-txt", "line 11: not the layout of the ntmdt-txt preset"},
      {ws, "jpk-txt", "not the layout of the jpk-txt preset"},
      {ws, "nanoscope-txt", "line 11: not the layout of the nanoscope-txt preset"},
      {ws, "asylum-txt", "line 11: not the layout of the asylum-txt preset"},
      {nt, "afmworkshop-csv", "no rows of numbers found (a text export needs lines of numbers separated by tabs, ';', ',' or blanks) (the afmworkshop-csv preset expects a first line 'Force-Distance Curve'"},
      {nt, "jpk-txt", "not the layout of the jpk-txt preset"},
      {nt, "nanoscope-txt", "not the layout of the nanoscope-txt preset"},
      {nt, "ibw", "not an Igor binary wave"},
      {nt, "jpk-force", "not a readable JPK .jpk-force file"},
      {jpk, "ibw", "not an Igor binary wave"},
      {jpk, "afmworkshop-csv", "a NUL byte"},
      {ibw, "jpk-force", "not a readable JPK .jpk-force file"},
      {ibw, "ntmdt-txt", "a NUL byte"},
  };
  for (const Case& c : cases) {
    const std::string msg = error_of_file(c.path, c.format);
    EXPECT_NE(msg.find(c.path), std::string::npos) << c.format << ": " << msg;
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.format << ": " << msg;
  }
}

TEST(CurvesPresets, AutoFormatReadsEachRealFile) {
  CURVES_REAL_FILE(jpk, "jpk_spot3-0192.jpk-force");
  CURVES_REAL_FILE(ibw, "asylum_SiN_FD_plot.ibw");
  EXPECT_EQ(ac::read_curves(jpk)[0].metadata.format, "jpk-force");
  EXPECT_EQ(ac::read_curves(ibw)[0].metadata.format, "ibw");
}

TEST(CurvesPresets, AfmWorkshopWithoutRetractColumnsIsRefused) {
  const std::string text =
      "Force-Distance Curve\nFile Format:\t3\n\nExtend Z-Sense(nm),Extend Force(nN)\n100,1\n200,2\n300,3\n";
  const std::string msg = preset_error_of(text, "afmworkshop-csv");
  EXPECT_NE(msg.find("export.txt: no retract height column in the header (line 4: 1 'Extend Z-Sense(nm)', 2 "
                     "'Extend Force(nN)'): the afmworkshop-csv preset expects 'Retract Z-Sense(nm)'"),
            std::string::npos)
      << msg;
  // The placeholders of an uncalibrated instrument (1 nN/nm, 1 mV/nm) are not taken for a calibration.
  const auto c = parse("Force-Distance Curve\nForce Constant, nN/nm:\t1\nLight Lever Gain, mV/nm:\t20\n\n"
                       "Extend Z-Sense(nm),Extend T-B(V),Retract Z-Sense(nm),Retract T-B(V)\n100,0.1,300,1.2\n"
                       "200,0.1,200,0.2\n300,1.3,100,0.1\n",
                       "afmworkshop-csv");
  EXPECT_TRUE(std::isnan(c.metadata.spring_constant));
  EXPECT_DOUBLE_EQ(c.metadata.invols, 1.0 / 20e6);  // 20 mV/nm = 2e7 V/m
  EXPECT_DOUBLE_EQ(c.segments[0].deflection_volts[2], 1.3);
  EXPECT_DOUBLE_EQ(c.segments[1].height[0], -300e-9);
}
