// Bad input through the command line: exit status 2, a message naming the parameter or file and the allowed
// range, and no output file.
#include <gtest/gtest.h>

#include "cli_run.hpp"

using afmkit_test::run_cli;
using afmkit_test::TempDir;

TEST(Cli, HelpAndVersionSucceed) {
  TempDir d;
  EXPECT_EQ(run_cli("--help", d).status, 0);
  EXPECT_EQ(run_cli("--version", d).status, 0);
  for (const char* sub : {"impact", "tapping orbit", "tapping hb", "tapping sweep", "demo", "control tf",
                          "control roots", "control margin", "control chart", "control tune", "control simulate"}) {
    auto r = run_cli(std::string(sub) + " --help", d);
    EXPECT_EQ(r.status, 0) << sub << ": " << r.err;
    EXPECT_NE(r.out.find("--"), std::string::npos) << sub;
  }
}

TEST(Cli, MissingOrUnknownSubcommandIsStatus2) {
  TempDir d;
  EXPECT_EQ(run_cli("", d).status, 2);
  EXPECT_EQ(run_cli("frobnicate", d).status, 2);
  EXPECT_EQ(run_cli("tapping", d).status, 2);
}

struct BadCase {
  const char* args;
  const char* must_mention;
};

class CliBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(CliBadInput, ExitsWith2NamesTheProblemAndWritesNothing) {
  TempDir d;
  d.write("malformed.toml", "quality_factor = = 3\n");
  d.write("unknown.toml", "quality_factr = 3\n");
  d.write("wrongtype.toml", "quality_factor = 'high'\n");
  const std::size_t before = d.count_files();
  auto r = run_cli(std::string("tapping hb --output res.csv ") + GetParam().args, d);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(GetParam().must_mention), std::string::npos) << r.err;
  EXPECT_EQ(d.count_files(), before) << "an output file was written";
}

INSTANTIATE_TEST_SUITE_P(
    TappingHb, CliBadInput,
    ::testing::Values(BadCase{"--quality-factor -1", "quality_factor"}, BadCase{"--quality-factor nan", "quality_factor"},
                      BadCase{"--quality-factor inf", "quality_factor"},
                      BadCase{"--approach-stiffness -3", "approach_stiffness"},
                      BadCase{"--law attractive --approach-adhesion 1 --departure-adhesion 0.5", "departure_adhesion"},
                      BadCase{"--law magnetic", "law"}, BadCase{"--config missing.toml", "missing.toml"},
                      BadCase{"--config malformed.toml", "malformed.toml"},
                      BadCase{"--config unknown.toml", "quality_factr"},
                      BadCase{"--config wrongtype.toml", "quality_factor"},
                      BadCase{"--units physical --drive-amplitude 3", "drive_amplitude"},
                      BadCase{"--law dmt", "dmt"}, BadCase{"--spring-constant 0 --units physical", "spring_constant"}));
