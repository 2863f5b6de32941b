// Every command's --help as a new user reads it: every option typed (numbers as FLOAT/INT, choices as NAME,
// files as FILE), every number with its unit ("[unit: …", docs/units.md), flags without a value type, one default
// each, and no reference to a file outside the project (the theory is in docs/theory-*.md).
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "help_walk.hpp"

using namespace afmkit_test;

namespace {
// options whose value is free text (paths are FILE, choices NAME): report's comma-separated list of figure ids
const std::set<std::string> kTextOptions = {"figures",     // a list of figure ids
                                            "scheduler",   // serial, local or any Dask scheduler address
                                            // spectroscopy prepare: a column of a text export, by name or position
                                            "height-column", "deflection-column", "force-column", "segment-column",
                                            "retract-height-column", "retract-deflection-column",
                                            "retract-force-column",
                                            "parameters",      // spectroscopy fit: a list of parameter names
                                            "signal-column"};  // control simulate: a column of signal_file
}  // namespace

class HelpText : public ::testing::TestWithParam<std::string> {};

TEST_P(HelpText, EveryOptionIsTypedHasOneDefaultAndCitesOnlyTheProject) {
  const std::string command = GetParam();
  for (std::string help : helps_of(command)) {
    help.erase(0, help.find('\n', help.find("Usage:")));  // the usage line names the program's own path
    for (const char* outside : {"MATH.md", "/work/", "shared/spec", "seeds/"})
      EXPECT_EQ(help.find(outside), std::string::npos) << "afmkit " << command << " --help cites " << outside;
  }
  const auto options = options_of(command);
  ASSERT_GT(options.size(), 3u) << command;
  for (const HelpOption& o : options) {
    if (o.name == "help" || o.name == "version") continue;
    if (o.type == "TEXT") {
      EXPECT_TRUE(kTextOptions.count(o.name)) << command << " --" << o.name << " is untyped (TEXT)";
    }
    if (o.flag) {
      EXPECT_EQ(o.description.find("TEXT=true"), std::string::npos) << command << " --" << o.name;
    }
    // every number carries its unit, named and not empty
    if (o.type == "FLOAT" || o.type == "INT" || o.type == "FLOAT,...") {
      const std::size_t at = o.description.find("[unit: ");
      EXPECT_NE(at, std::string::npos) << command << " --" << o.name << " has no unit: " << o.description;
      if (at != std::string::npos) {
        EXPECT_NE(o.description[at + 7], ';') << command << " --" << o.name << " has an empty unit";
      }
    }
    // one default: the [default …] the parameter set prints, no second "(default: …)" in the help text
    std::size_t defaults = 0;
    for (std::size_t at = o.description.find("default"); at != std::string::npos;
         at = o.description.find("default", at + 1))
      if (at > 0 && (o.description[at - 1] == '[' || o.description[at - 1] == '(')) ++defaults;
    EXPECT_LE(defaults, 1u) << command << " --" << o.name << ": " << o.description;
  }
}

// The physical-unit keys are listed only where they apply: with --units physical, not in the normalised help.
TEST(HelpText, UnitSystemGroupsAreListedOnlyWhereTheyApply) {
  const std::string normalised = help_of("tapping hb");
  const std::string physical = help_of("tapping hb --units physical");
  EXPECT_NE(normalised.find("--drive-amplitude"), std::string::npos);
  EXPECT_EQ(normalised.find("--spring-constant"), std::string::npos);
  EXPECT_NE(physical.find("--spring-constant"), std::string::npos);
  EXPECT_EQ(physical.find("--drive-amplitude"), std::string::npos);
  EXPECT_NE(normalised.find("--units physical --help"), std::string::npos);  // says where the others are
}

INSTANTIATE_TEST_SUITE_P(Commands, HelpText, ::testing::ValuesIn(kCommands),
command_test_name);
