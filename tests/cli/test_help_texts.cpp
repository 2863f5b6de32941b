// Every command's --help as a new user reads it: every option typed (numbers as FLOAT/INT, choices as NAME,
// files as FILE or TEXT), flags without a value type, one default each, and no reference to a file outside the
// project (the theory is in docs/theory-*.md).
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "help_walk.hpp"

using namespace afmkit_test;

namespace {
// options whose value is free text: file paths and folders
const std::set<std::string> kTextOptions = {"output", "boundaries-output", "output-dir", "force-curve"};
}  // namespace

class HelpText : public ::testing::TestWithParam<std::string> {};

TEST_P(HelpText, EveryOptionIsTypedHasOneDefaultAndCitesOnlyTheProject) {
  const std::string command = GetParam();
  std::string help = help_of(command);
  help.erase(0, help.find('\n', help.find("Usage:")));  // the usage line names the program's own path
  for (const char* outside : {"MATH.md", "/work/", "shared/spec", "seeds/"})
    EXPECT_EQ(help.find(outside), std::string::npos) << "afmkit " << command << " --help cites " << outside;
  const auto options = options_in(help);
  ASSERT_GT(options.size(), 3u) << command;
  for (const HelpOption& o : options) {
    if (o.name == "help" || o.name == "version") continue;
    if (o.type == "TEXT") EXPECT_TRUE(kTextOptions.count(o.name)) << command << " --" << o.name << " is untyped (TEXT)";
    if (o.flag) EXPECT_EQ(o.description.find("TEXT=true"), std::string::npos) << command << " --" << o.name;
    // one default: the [default …] the parameter set prints, no second "(default: …)" in the help text
    std::size_t defaults = 0;
    for (std::size_t at = o.description.find("default"); at != std::string::npos;
         at = o.description.find("default", at + 1))
      if (at > 0 && (o.description[at - 1] == '[' || o.description[at - 1] == '(')) ++defaults;
    EXPECT_LE(defaults, 1u) << command << " --" << o.name << ": " << o.description;
  }
}

INSTANTIATE_TEST_SUITE_P(Commands, HelpText, ::testing::ValuesIn(kCommands),
command_test_name);
