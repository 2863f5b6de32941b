#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <random>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/ascii_matrix.hpp"
#include "scan_test_dir.hpp"

using afmkit::InputError;
using afmkit::scan::parse_ascii_matrix;

namespace {
std::string error_of(const std::string& text) {
  try {
    parse_ascii_matrix(text, "m.txt");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(AsciiMatrix, SeparatorsCommentsAndLineEndsAgreeWithStrtod) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1e-6, 1e-6);
  const char* seps[] = {" ", "\t", ",", ", ", " ,\t", "  "};
  std::string text = "\xEF\xBB\xBF# Gwyddion ASCII export\n# Width: 1 um\n\n";
  std::vector<double> reference;
  for (int j = 0; j < 7; ++j) {
    for (int i = 0; i < 9; ++i) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.17g", u(rng));
      text += buf;
      if (i < 8) text += seps[(i + j) % 6];
      reference.push_back(std::strtod(buf, nullptr));
    }
    text += j % 2 ? "  # row comment\r\n" : "\n";
    if (j == 3) text += "   \n# between rows\n";
  }
  const auto m = parse_ascii_matrix(text, "t");
  EXPECT_EQ(m.rows, 7);
  EXPECT_EQ(m.columns, 9);
  EXPECT_EQ(m.values, reference);
}

TEST(AsciiMatrix, RaggedRowsNameFileLineAndBothLengths) {
  EXPECT_EQ(error_of("# h\n1 2 3\n4 5 6\n\n7 8\n"),
            "m.txt:5: ragged rows: this row has 2 values, the first row (line 2) has 3");
  EXPECT_EQ(error_of("1 2\n3 4 5\n"), "m.txt:2: ragged rows: this row has 3 values, the first row (line 1) has 2");
  EXPECT_EQ(error_of("1 2\n3 x4\n"), "m.txt:2: 'x4' is not a finite number");
  EXPECT_NE(error_of("1 nan\n").find("m.txt:1:"), std::string::npos);
  EXPECT_NE(error_of("1,,2\n").find("m.txt:1: empty cell"), std::string::npos);
  EXPECT_NE(error_of(",1,2\n").find("m.txt:1: empty cell"), std::string::npos);
  EXPECT_NE(error_of("1,2\n3,4,\n").find("m.txt:2: empty cell"), std::string::npos);
  EXPECT_EQ(error_of("# nothing\n\n"), "m.txt: no numbers: an ASCII matrix needs at least one value");
  EXPECT_EQ(error_of(""), "m.txt: no numbers: an ASCII matrix needs at least one value");
}

TEST(AsciiMatrix, FilesAreReadAndBadPathsNamed) {
  scan_test::TempDir dir("afmkit_ascii_matrix");
  scan_test::spit(dir.file("a.txt"), "1 2\r\n3 4\r\n");
  const auto m = afmkit::scan::read_ascii_matrix(dir.file("a.txt"));
  EXPECT_EQ(m.values, (std::vector<double>{1, 2, 3, 4}));
  scan_test::spit(dir.file("r.txt"), "1 2\n3\n");
  try {
    afmkit::scan::read_ascii_matrix(dir.file("r.txt"));
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), dir.file("r.txt") + ":2: ragged rows: this row has 1 value, the first row "
                                                           "(line 1) has 2");
  }
  EXPECT_THROW(afmkit::scan::read_ascii_matrix(dir.file("none.txt")), InputError);
}
