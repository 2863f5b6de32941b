// The command line answers --help and --version for every command (bad input: test_bad_input.cpp, which runs
// every row of docs/bad-input.md).
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
