// The number parser of flag values against the C library's strtod (independent reference) and its edge cases;
// text parameters must be UTF-8 (found by fuzz/fuzz_io_params: invalid UTF-8 broke the JSON sidecar).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/number.hpp"
#include "afmkit/io/params.hpp"

using afmkit::io::parse_integer;
using afmkit::io::parse_real;

TEST(Number, RealsAgreeWithStrtodBitForBit) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 20000; ++i) {
    const double v = std::ldexp(std::uniform_real_distribution<double>(-1, 1)(rng),
                                std::uniform_int_distribution<int>(-1000, 1000)(rng));
    for (const std::string& text : {fmt::format("{}", v), fmt::format("{:.17e}", v), fmt::format("{:.5g}", v)}) {
      const auto parsed = parse_real(text);
      ASSERT_TRUE(parsed) << text;
      const double reference = std::strtod(text.c_str(), nullptr);
      EXPECT_EQ(std::memcmp(&reference, &*parsed, sizeof reference), 0) << text;
    }
  }
}

TEST(Number, WholeTextMustBeOneNumber) {
  for (const char* bad : {"", " 1", "1 ", "1,2", "0x10", "1e", "--1", "+-1", "abc", "1.2.3", "1e400"})
    EXPECT_FALSE(parse_real(bad)) << bad;
  EXPECT_EQ(*parse_real("+2"), 2.0);
  EXPECT_TRUE(std::isnan(*parse_real("nan")));  // accepted here, rejected by the range check with its range
  EXPECT_TRUE(std::isinf(*parse_real("-inf")));
}

TEST(Number, IntegersExactlyAndFromIntegralReals) {
  EXPECT_EQ(*parse_integer("9223372036854775807"), 9223372036854775807L);
  EXPECT_EQ(*parse_integer("-9223372036854775808"), std::numeric_limits<long>::min());
  EXPECT_EQ(*parse_integer("9007199254740993"), 9007199254740993L);  // not representable as a double
  EXPECT_EQ(*parse_integer("1e7"), 10000000L);
  EXPECT_EQ(*parse_integer("2.0"), 2L);
  for (const char* bad : {"9223372036854775808", "9.3e18", "1e30", "2.5", "nan", "inf", "", "1e"})
    EXPECT_FALSE(parse_integer(bad)) << bad;
}

TEST(Number, FlagsUseTheParserAndNameTheRange) {
  afmkit::io::ParamSet p;
  p.integer("points", 10, "n", 2, 1000000).text("output", "x.csv", "path");
  p.set_from_string("points", "1e3");
  EXPECT_EQ(p.integer("points"), 1000);
  try {
    p.set_from_string("points", "1e30");
    FAIL();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "points");
    EXPECT_NE(std::string(e.what()).find("[2, 1000000]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(p.set_from_string("output", "\xcc" "1"), afmkit::InvalidParameter);
  EXPECT_THROW(p.set_from_string("output", "\xed\xa0\x80"), afmkit::InvalidParameter);  // a surrogate
  p.set_from_string("output", "r\xc3\xa9sultat/\xe2\x88\x86.csv");                     // "résultat/∆.csv"
  EXPECT_EQ(p.text("output"), "r\xc3\xa9sultat/\xe2\x88\x86.csv");
}
