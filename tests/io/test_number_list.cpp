#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <unistd.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/number_list.hpp"

using afmkit::InputError;
using afmkit::io::parse_number_list;

TEST(NumberList, SeparatorsCommentsAndBlankLinesAgreeWithStrtod) {
  // random values written with mixed separators; the reference reads each token with strtod
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  const char* seps[] = {",", " ", "\t", "\n", ", ", " ,\t"};
  std::string text = "# header comment\n\n";
  std::vector<double> reference;
  for (int i = 0; i < 500; ++i) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", u(rng));
    text += buf;
    text += seps[i % 6];
    if (i % 50 == 0) text += "  # a comment, with 1,2,3 in it\n";
    reference.push_back(std::strtod(buf, nullptr));
  }
  const std::vector<double> got = parse_number_list(text, "t");
  ASSERT_EQ(got.size(), reference.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], reference[i]) << i;
  EXPECT_TRUE(parse_number_list("", "t").empty());
  EXPECT_TRUE(parse_number_list("# only a comment\n\n", "t").empty());
}

TEST(NumberList, AWordThatIsNotANumberNamesOriginAndLine) {
  try {
    parse_number_list("1, 2\n3 4\n5 x6 7\n", "seps.txt");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "seps.txt:3: 'x6' is not a finite number");
  }
  EXPECT_THROW(parse_number_list("1 nan", "t"), InputError);   // not finite
  EXPECT_THROW(parse_number_list("1 inf", "t"), InputError);
  EXPECT_THROW(parse_number_list("1;2", "t"), InputError);     // ';' is not a separator
  EXPECT_THROW(parse_number_list("0x10", "t"), InputError);    // no hexadecimal
}

TEST(NumberList, FilesAreReadAndBadPathsNamed) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("afmkit_number_list_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  { std::ofstream(dir / "l.txt") << "# nm\n10\n9.5, 9\n"; }
  EXPECT_EQ(afmkit::io::read_number_list((dir / "l.txt").string(), "separations_file"),
            (std::vector<double>{10, 9.5, 9}));
  try {
    afmkit::io::read_number_list((dir / "missing.txt").string(), "separations_file");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("separations_file"), std::string::npos) << e.what();
  }
  EXPECT_THROW(afmkit::io::read_number_list(dir.string(), "separations_file"), InputError);  // a directory
  fs::remove_all(dir);
}
