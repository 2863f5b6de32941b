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

#include "cli_run.hpp"
#include "help_walk.hpp"

using namespace afmkit_test;

namespace {


// values of the classes found by the campaign: not a number, the double range's ends, beyond it, negative
const std::vector<std::string> kValues = {"nan", "1e308", "-1e308", "1e400", "-1", "abc"};

// options not probed with numbers: help, the config file and the output path (probed by their own tests)
const std::set<std::string> kSkipped = {"help", "config", "output"};

std::vector<HelpOption> probed_options(const std::string& command) {
  std::vector<HelpOption> out;
  for (const HelpOption& o : options_of(command))
    if (!kSkipped.count(o.name)) out.push_back(o);
  return out;
}

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
  const auto options = probed_options(command);
  ASSERT_FALSE(options.empty()) << command;
  bool has_output = false, has_quiet = false;
  for (const HelpOption& o : options) has_quiet |= o.name == "quiet";
  {
    TempDir d;
    has_output = run_cli(command + " --help", d).out.find("--output") != std::string::npos;
  }
  int runs = 0;
  for (const HelpOption& o : options) {
    if (o.flag) continue;
    for (const std::string& v : kValues) {
      TempDir dir;
      const std::string args = command + " --" + o.name + " '" + v + "'" + (has_output ? " --output out.csv" : "") +
                               (has_quiet ? " --quiet" : "");
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
      if (r.status == 2) EXPECT_FALSE(std::filesystem::exists(dir.path / "out.csv")) << "afmkit " << args;
    }
  }
  RecordProperty("runs", runs);
}

INSTANTIATE_TEST_SUITE_P(Commands, HostileCampaign, ::testing::ValuesIn(kCommands),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (c == ' ') c = '_';
                           return name;
                         });
