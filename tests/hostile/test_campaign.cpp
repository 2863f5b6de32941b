// A hostile-user campaign, generated: every option of every command (read from its --help) is given values of
// the classes that once crashed or misled afmkit — not a number, ±1e308, out of double range, negative — and
// every command must answer with exit 0, 1 or 2 (never a signal, an escaped exception, a sanitizer report or an
// unbounded run), and leave no temporary file behind. One test per command, so ctest runs them in parallel.
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../cli/cli_run.hpp"
#include "../cli/help_walk.hpp"

using namespace afmkit_test;

namespace {


// values of the classes found by the campaign: not a number, the double range's ends, beyond it, negative
const std::vector<std::string> kValues = {"nan", "1e308", "-1e308", "1e400", "-1", "abc"};

// options not probed with numbers: help, the config file and the output path (probed by their own tests)
const std::set<std::string> kSkipped = {"help", "config", "output"};

// Under the sanitizers (a build ~10x slower per process) the campaign takes a sample: every other option (k even)
// with one case, number (k/2) mod its number of cases, so that every hostile value is still tried on every command
// with enough options. Release runs the full product (kSanitized, left_out_under_sanitizers: cli_run.hpp).
bool sampled_out(std::size_t option_index, std::size_t case_index, std::size_t cases) {
  return left_out_under_sanitizers(option_index, 2) || (kSanitized && case_index != (option_index / 2) % cases);
}

// Commands whose default run is long (`scan`: 8e6 samples, ~1.5 s CPU, far more under the sanitizers) are probed
// from a lighter configuration (a --config file; the probed option, given on the command line, overrides it): the
// campaign is about how each value is answered, not about the default instrument.
std::string light_config(const std::string& command) {
  if (command == "scan")
    return "sample_rate = 20000.0\nradial_speed = 1e-3\nimage_resolution = 128\nsample_resolution = 512\n";
  return {};
}

std::vector<HelpOption> probed(const std::vector<HelpOption>& options) {
  std::vector<HelpOption> out;
  for (const HelpOption& o : options)
    if (!kSkipped.count(o.name)) out.push_back(o);
  return out;
}
std::vector<HelpOption> probed_options(const std::string& command) { return probed(options_of(command)); }

RunResult run_bounded(const std::string& args, const TempDir& dir) {
  // 60 s: far above any default run (< 1 s; several under the sanitizers); KILL so that a hang cannot hide
  const std::string line = "timeout -s KILL 60 '" + std::string(AFMKIT_CLI) + "' " + args;
  const std::string out = dir.file(".stdout"), err = dir.file(".stderr");
  const int raw = std::system(("cd '" + dir.path.string() + "' && " + line + " >'" + out + "' 2>'" + err + "'").c_str());
  RunResult r{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

}  // namespace

TEST(HostileCampaign, TheCommandListIsEveryLeafCommand) {
  const auto leaves = leaf_commands();
  EXPECT_EQ(std::set<std::string>(leaves.begin(), leaves.end()),
            std::set<std::string>(kCommands.begin(), kCommands.end()));
}

class HostileCampaign : public ::testing::TestWithParam<std::string> {};

TEST_P(HostileCampaign, EveryOptionWithEveryHostileValueEndsWithAStatusAndLeavesNoTemporary) {
  const std::string command = GetParam();
  const auto all = options_of(command);
  const auto options = probed(all);
  ASSERT_FALSE(options.empty()) << command;
  bool has_output = false, has_quiet = false;
  for (const HelpOption& o : all) {
    has_quiet |= o.name == "quiet";
    has_output |= o.name == "output";
  }
  int runs = 0;
  std::size_t option_index = 0;
  for (const HelpOption& o : options) {
    if (o.flag) continue;
    if (command == "report" && o.name == "output-dir") continue;  // any folder name is valid: a whole report each
    ++option_index;
    for (std::size_t value_index = 0; value_index < kValues.size(); ++value_index) {
      if (sampled_out(option_index, value_index, kValues.size())) continue;
      const std::string& v = kValues[value_index];
      TempDir dir;
      const std::string light = light_config(command);
      if (!light.empty()) dir.write("light.toml", light);
      const std::string args = command + " --" + o.name + " '" + v + "'" + (has_output ? " --output out.csv" : "") +
                               (has_quiet ? " --quiet" : "") + (light.empty() ? "" : " --config light.toml");
      const RunResult r = run_bounded(args, dir);
      ++runs;
      EXPECT_TRUE(r.status == 0 || r.status == 1 || r.status == 2)
          << "afmkit " << args << "\nexit " << r.status << (r.status == 137 ? " (killed: ran unbounded)" : "") << "\n"
          << r.err;
      for (const char* bad : {"terminate called", "Sanitizer", "runtime error:", "Aborted"})
        EXPECT_EQ(r.err.find(bad), std::string::npos) << "afmkit " << args << "\n" << r.err;
      for (const auto& e : std::filesystem::recursive_directory_iterator(dir.path))
        EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos)
            << "afmkit " << args << " left " << e.path();
      if (r.status == 2) {
        EXPECT_FALSE(std::filesystem::exists(dir.path / "out.csv")) << "afmkit " << args;
      }
    }
  }
  RecordProperty("runs", runs);
}

// Crossed ranges: every pair --X-min / --X-max given the wrong way round is bad input (exit 2), naming one of them.
TEST_P(HostileCampaign, EveryCrossedRangeIsBadInput) {
  const std::string command = GetParam();
  const auto options = probed_options(command);
  std::set<std::string> names;
  for (const HelpOption& o : options) names.insert(o.name);
  for (const std::string& lo : names) {
    if (lo.size() < 4 || lo.compare(lo.size() - 4, 4, "-min") != 0) continue;
    const std::string stem = lo.substr(0, lo.size() - 4), hi = stem + "-max";
    if (!names.count(hi)) continue;
    TempDir dir;
    const std::string args = command + " --" + lo + " 5 --" + hi + " 1" + (names.count("quiet") ? " --quiet" : "");
    const RunResult r = run_bounded(args, dir);
    EXPECT_EQ(r.status, 2) << "afmkit " << args << "\n" << r.err;
    std::string underscored = stem;
    for (char& c : underscored)
      if (c == '-') c = '_';
    EXPECT_NE(r.err.find(underscored), std::string::npos) << "afmkit " << args << "\n" << r.err;
  }
}

// Hostile TOML: every key of the command given a value of the wrong kind (array, table, text, a number too large
// for TOML) is bad input naming the key or the file; nothing is written.
TEST_P(HostileCampaign, EveryKeyWithAHostileTomlValueIsBadInput) {
  const std::string command = GetParam();
  std::size_t option_index = 0;
  for (const HelpOption& o : probed_options(command)) {
    std::string key = o.name;
    for (char& c : key)
      if (c == '-') c = '_';
    ++option_index;
    const std::vector<std::string> values = {std::string("[1, 2]"), std::string("{ a = 1 }"),
                                             std::string("99999999999999999999"), std::string("1979-05-27"),
                                             std::string("'") + std::string(5000, 'x') + "'"};
    for (std::size_t value_index = 0; value_index < values.size(); ++value_index) {
      if (sampled_out(option_index, value_index, values.size())) continue;
      const std::string& value = values[value_index];
      if (o.type == "TEXT" && value[0] == '\'') continue;      // long text is a valid (missing) file name
      if (o.type == "FLOAT,..." && value[0] == '[') continue;  // an array is what a list key takes
      TempDir dir;
      dir.write("hostile.toml", key + " = " + value + "\n");
      const RunResult r = run_bounded(command + " --config hostile.toml --output out.csv", dir);
      if ((command == "demo" || command == "report" || command == "study run" ||
           command == "tapping grid") &&
          r.err.find("--output") != std::string::npos)
        continue;  // these write to a folder or a store
      EXPECT_TRUE(r.status == 1 || r.status == 2) << "afmkit " << command << " with " << key << " = " << value.substr(0, 40)
                                                  << "\nexit " << r.status << "\n" << r.err;
      EXPECT_FALSE(std::filesystem::exists(dir.path / "out.csv")) << command << " " << key;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Commands, HostileCampaign, ::testing::ValuesIn(kCommands),
command_test_name);

// Output paths and kills, for a command that writes a table: refused paths exit 2 and leave nothing; a run killed
// while it computes or writes leaves no temporary.
TEST(HostileOutputs, RefusedPathsAndKilledRunsLeaveNothingBehind) {
  TempDir dir;
  std::filesystem::create_directories(dir.path / "folder");
  dir.write("file.txt", "x");
  ASSERT_EQ(std::system(("mkfifo '" + dir.file("fifo.csv") + "'").c_str()), 0);
  for (const std::string& out : {std::string("folder"), std::string("fifo.csv"), std::string("file.txt/out.csv"),
                                 std::string(300, 'n') + ".csv"}) {
    const RunResult r = run_bounded("tapping hb --points 50 --output '" + out + "'", dir);
    EXPECT_EQ(r.status, 2) << out.substr(0, 40) << "\n" << r.err;
  }
  // killed at several moments of a run that computes and then streams 2e5 rows
  for (const char* after : {"0.05", "0.2", "0.5", "1"}) {
    const std::string line = "timeout -s TERM " + std::string(after) + " '" + std::string(AFMKIT_CLI) +
                             "' control tf --points 200000 --output killed.csv >/dev/null 2>&1";
    std::system(("cd '" + dir.path.string() + "' && " + line).c_str());
    for (const auto& e : std::filesystem::recursive_directory_iterator(dir.path))
      EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << "killed after " << after << " s left "
                                                                               << e.path();
  }
}
