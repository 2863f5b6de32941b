// io::quantity: the SI prefix of a summary's number chosen by magnitude (docs/units.md#summaries).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "afmkit/io/quantity.hpp"

using afmkit::io::quantity;

TEST(Quantity, ChoosesThePrefixByMagnitude) {
  EXPECT_EQ(quantity(0.000245, "mm"), "245 nm");  // the case of the issue: a 245 nm scan radius
  EXPECT_EQ(quantity(245e-9, "m"), "245 nm");
  EXPECT_EQ(quantity(4e-3, "m"), "4 mm");
  EXPECT_EQ(quantity(0.0125, "m"), "12.5 mm");
  EXPECT_EQ(quantity(1.5, "m"), "1.5 m");
  EXPECT_EQ(quantity(20.0, "nm"), "20 nm");
  EXPECT_EQ(quantity(0.02, "nm"), "20 pm");
  EXPECT_EQ(quantity(2.5e4, "nm"), "25 \xC2\xB5m");
  EXPECT_EQ(quantity(23.251, "kHz"), "23.25 kHz");
  EXPECT_EQ(quantity(50e3, "Hz"), "50 kHz");
  EXPECT_EQ(quantity(50.0, "Hz"), "50 Hz");
  EXPECT_EQ(quantity(3e-4, "s"), "300 \xC2\xB5s");
  EXPECT_EQ(quantity(3e-4, "us"), "300 ps");
  EXPECT_EQ(quantity(1.2e-3, "nN"), "1.2 pN");
  EXPECT_EQ(quantity(-7.5e3, "nN"), "-7.5 \xC2\xB5N");
  EXPECT_EQ(quantity(0.5, "aJ"), "0.5 aJ");  // below atto the mantissa leaves [1, 1000)
  EXPECT_EQ(quantity(2000.0, "aJ"), "2 fJ");
  EXPECT_EQ(quantity(1e6, "nm/s"), "1 mm/s");
}

TEST(Quantity, RoundingThatCarriesTakesTheNextPrefix) {
  EXPECT_EQ(quantity(999.96e-9, "m"), "1 \xC2\xB5m");
  EXPECT_EQ(quantity(999.94e-9, "m"), "999.9 nm");
  EXPECT_EQ(quantity(999.96e-9, "m", 6), "999.96 nm");
  EXPECT_EQ(quantity(1e-9, "m"), "1 nm");  // log10 rounding at an exact power of 1000
  EXPECT_EQ(quantity(1e-6, "m"), "1 \xC2\xB5m");
  EXPECT_EQ(quantity(1e3, "m"), "1 km");
}

TEST(Quantity, BeyondThePrefixesAndUndefinedValues) {
  EXPECT_EQ(quantity(1e-20, "m"), "0.01 am");
  EXPECT_EQ(quantity(5e15, "Hz"), "5000 THz");
  EXPECT_EQ(quantity(0.0, "mm"), "0 mm");
  EXPECT_EQ(quantity(std::numeric_limits<double>::quiet_NaN(), "m"), "nan m");
  EXPECT_EQ(quantity(-std::numeric_limits<double>::quiet_NaN(), "m"), "nan m");  // never "-nan"
  EXPECT_EQ(quantity(std::numeric_limits<double>::infinity(), "s"), "inf s");
  EXPECT_EQ(quantity(-std::numeric_limits<double>::infinity(), "s"), "-inf s");
  EXPECT_EQ(quantity(0.25, "rad"), "0.25 rad");  // not a prefixable unit: as given
  EXPECT_EQ(quantity(1234567.0, "count"), "1.235e+06 count");
}

TEST(Quantity, TheValueSurvivesTheRoundTrip) {
  // independent: the printed mantissa times its prefix's power of ten gives back the value to the digits asked
  const char* prefixes[] = {"a", "f", "p", "n", "\xC2\xB5", "m", "", "k", "M", "G", "T"};
  for (double v = 1.7e-14; v < 1e14; v *= 3.7) {
    const std::string s = quantity(v, "m", 10);
    const auto space = s.find(' ');
    const double mantissa = std::stod(s.substr(0, space));
    const std::string unit = s.substr(space + 1);
    int e = -99;
    for (int k = 0; k < 11; ++k)
      if (unit == std::string(prefixes[k]) + "m") e = 3 * (k - 6);
    ASSERT_NE(e, -99) << s;
    EXPECT_GE(mantissa, 1.0) << s;
    EXPECT_LT(mantissa, 1000.0) << s;
    EXPECT_NEAR(mantissa * std::pow(10.0, e), v, 1e-9 * v) << s;
  }
}

// issue 24: every physical number of a summary by magnitude, and a normalised number said to be one (the tapping
// model's L, t; the control commands' Omega, T) instead of printed as if it had a physical unit.
TEST(Quantity, SummaryValuesArePrefixedOrSaidToBeNormalised) {
  using afmkit::io::summary_value;
  using afmkit::io::summary_values;
  EXPECT_TRUE(afmkit::io::si_unit("nm"));
  EXPECT_TRUE(afmkit::io::si_unit("aJ"));
  EXPECT_FALSE(afmkit::io::si_unit("L"));
  EXPECT_FALSE(afmkit::io::si_unit("Omega"));
  EXPECT_FALSE(afmkit::io::si_unit("L/t^2"));
  EXPECT_EQ(summary_value(0.35, "nm"), "350 pm");
  EXPECT_EQ(summary_value(1500.0, "nm"), "1.5 \xC2\xB5m");
  EXPECT_EQ(summary_value(0.35, "L"), "0.35 (normalised, units of L)");
  EXPECT_EQ(summary_value(-0.0123456, "Omega", 3), "-0.0123 (normalised, units of Omega)");
  EXPECT_EQ(summary_value(std::nan(""), "T"), "nan (normalised, units of T)");
  EXPECT_EQ(summary_values({0.2, 0.45}, "nm"), "200 pm, 450 pm");
  EXPECT_EQ(summary_values({0.2, 0.45}, "L"), "0.2, 0.45 (normalised, units of L)");
  EXPECT_EQ(summary_values({}, "nm"), "none");
  EXPECT_EQ(afmkit::io::normalised(0.31, "T", 4, "3.1 ms"), "0.31 (normalised, units of T; 3.1 ms)");
}
