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

using namespace afmkit_test;

namespace {

const std::vector<std::string> kCommands = {"demo",          "impact",        "tapping orbit", "tapping hb",
                                            "tapping sweep", "control tf",    "control roots", "control margin",
                                            "control chart", "control tune",  "control simulate"};

// values of the classes found by the campaign: not a number, the double range's ends, beyond it, negative
const std::vector<std::string> kValues = {"nan", "1e308", "-1e308", "1e400", "-1", "abc"};

// options not probed with numbers: help, the config file and the output path (probed by their own tests)
const std::set<std::string> kSkipped = {"help", "config", "output"};

struct Option {
  std::string name;
  bool flag;
};

std::vector<Option> options_of(const std::string& command) {
  TempDir dir;
  const RunResult r = run_cli(command + " --help", dir);
  std::vector<Option> out;
  // `--name TYPE` for options with a value, `--name` alone for flags
  const std::regex line(R"(^\s+(?:-\w,)?--([a-z0-9-]+)(\s+(?:FLOAT,\.\.\.|FLOAT|INT|NAME|TEXT|FILE)\b)?)");
  std::istringstream in(r.out);
  std::string text;
  while (std::getline(in, text)) {
    std::smatch m;
    if (std::regex_search(text, m, line) && !kSkipped.count(m[1].str())) out.push_back({m[1].str(), !m[2].matched});
  }
  return out;
}

/// Subcommand names listed by `afmkit <prefix> --help`.
std::vector<std::string> subcommands_of(const std::string& prefix) {
  TempDir dir;
  const RunResult r = run_cli(prefix + " --help", dir);
  std::vector<std::string> out;
  std::istringstream in(r.out);
  std::string text;
  bool listing = false;
  while (std::getline(in, text)) {
    if (text.rfind("Subcommands:", 0) == 0) {
      listing = true;
      continue;
    }
    std::smatch m;
    if (listing && std::regex_search(text, m, std::regex(R"(^  ([a-z]+)\s)"))) out.push_back(m[1].str());
  }
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
  std::vector<std::string> leaves;
  for (const std::string& top : subcommands_of("")) {
    const auto subs = subcommands_of(top);
    if (subs.empty()) leaves.push_back(top);
    for (const std::string& s : subs) leaves.push_back(top + " " + s);
  }
  EXPECT_EQ(std::set<std::string>(leaves.begin(), leaves.end()),
            std::set<std::string>(kCommands.begin(), kCommands.end()));
}

class HostileCampaign : public ::testing::TestWithParam<std::string> {};

TEST_P(HostileCampaign, EveryOptionWithEveryHostileValueEndsWithAStatusAndLeavesNoTemporary) {
  const std::string command = GetParam();
  const auto options = options_of(command);
  ASSERT_FALSE(options.empty()) << command;
  bool has_output = false, has_quiet = false;
  for (const Option& o : options) has_quiet |= o.name == "quiet";
  {
    TempDir d;
    has_output = run_cli(command + " --help", d).out.find("--output") != std::string::npos;
  }
  int runs = 0;
  for (const Option& o : options) {
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
