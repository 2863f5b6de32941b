// The measured-curve reader of the reconstructions (units in the header, separators, errors naming file, line and
// column) and the table-law file the reconstructions write (read back by the table law's own parser).
#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/spectroscopy/reconstruct_input.hpp"
#include "afmkit/spectroscopy/reconstruct_law.hpp"

namespace sp = afmkit::spectroscopy;

TEST(ReconstructInput, UnitsAndSeparatorsOfTheHeader) {
  const auto am = sp::parse_measured_curve(
      "# AM curve\nseparation [Å]; amplitude (pm); phase (deg)\n50; 4000; 120\n60; 5000; 110\n70; 6000; 100\n"
      "80; 7000; 95\n90; 8000; 91\n",
      "am.csv");
  EXPECT_FALSE(am.frequency_modulation);
  ASSERT_EQ(am.distance.size(), 5u);
  EXPECT_DOUBLE_EQ(am.distance[0], 5e-9);
  EXPECT_DOUBLE_EQ(am.amplitude[1], 5e-9);
  EXPECT_DOUBLE_EQ(am.phase[0], 120.0 * std::numbers::pi / 180.0);
  EXPECT_EQ(am.lines[0], 3);
  const auto fm = sp::parse_measured_curve("z_nm\tdf_kHz\n5\t-0.003\n4\t-0.004\n3\t-0.005\n2\t-0.006\n1\t-0.008\n",
                                           "fm.tsv");
  EXPECT_TRUE(fm.frequency_modulation);
  EXPECT_DOUBLE_EQ(fm.frequency_shift[4], -8.0);
  EXPECT_DOUBLE_EQ(fm.distance[4], 1e-9);
}

TEST(ReconstructInput, ErrorsNameFileLineAndColumn) {
  const auto message = [](const std::string& text) {
    try {
      sp::parse_measured_curve(text, "c.csv");
    } catch (const afmkit::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("distance (nm), frequency shift (Hz)\n1, -3\n2, x\n").find("c.csv:3: column 2"), std::string::npos);
  EXPECT_NE(message("distance (nm), frequency shift (Hz)\n1, -3\n2, -2\n3, inf\n").find("not a finite number"),
            std::string::npos);
  EXPECT_NE(message("distance (furlong), frequency shift (Hz)\n").find("is not a length"), std::string::npos);
  EXPECT_NE(message("distance (nm), amplitude (nm)\n1, 2\n").find("neither FM"), std::string::npos);
  EXPECT_NE(message("distance (nm), frequency shift (Hz)\n1, -3\n2, -2\n").find("at least 5"), std::string::npos);
  EXPECT_NE(message("distance (nm), frequency shift (Hz)\n1, -3\n2, -2\n3\n").find("1 cells for 2 columns"),
            std::string::npos);
}

TEST(ReconstructLaw, TheWrittenFileReadsBackAsTheSameLaw) {
  const std::vector<double> d = {0.1e-9, 0.2e-9, 0.4e-9, 0.8e-9, 1.6e-9};
  const std::vector<double> fa = {-2e-9, -1.5e-9, -0.7e-9, -0.2e-9, -0.01e-9};
  const std::vector<double> fr = {-2.5e-9, -1.8e-9, -0.7e-9, -0.2e-9, -0.01e-9};
  const auto curve = sp::force_curve_from_si(d, fa, fr, "x");
  const auto back = afmkit::impact::parse_force_curve(sp::table_law_text(curve, "a comment"), "law.csv");
  EXPECT_EQ(back.approach_gap, curve.approach_gap);
  EXPECT_EQ(back.approach_force, curve.approach_force);
  EXPECT_EQ(back.retract_force, curve.retract_force);
}
