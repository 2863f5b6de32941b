#pragma once
// Walking the command line as a user does: the commands and the options each --help lists.
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_run.hpp"

namespace afmkit_test {

/// Every leaf command of afmkit (kept explicit so that a new command is a deliberate addition to the tests).
inline const std::vector<std::string> kCommands = {
    "demo",          "impact",         "tapping orbit", "tapping hb",    "tapping sweep", "tapping grid",
    "control tf",    "control roots",  "control margin", "control chart", "control tune",  "control simulate",
    "control export", "scan",          "report",         "study run",     "tapping fm",
    "spectroscopy prepare", "spectroscopy reconstruct", "spectroscopy fit", "tapping image", "tapping modes"};

/// Whether this build has the Python module (`afmkit report` and `afmkit study run` need it; the sanitizer build has
/// none).
#ifdef AFMKIT_TEST_HAS_PYTHON
inline constexpr bool kHasPython = true;
#else
inline constexpr bool kHasPython = false;
#endif

/// A gtest parameter name for a command: "tapping orbit" -> "tapping_orbit".
inline std::string command_test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  for (char& c : name)
    if (c == ' ') c = '_';
  return name;
}

/// One option line of --help: `--name TYPE  description` (type empty for a flag). A long name whose description
/// starts on the next line gets that line as its description.
struct HelpOption {
  std::string name;
  bool flag;
  std::string type;
  std::string description;
};

inline std::string help_of(const std::string& command) {
  TempDir dir;
  return run_cli(command + " --help", dir).out;
}

/// The options listed in a --help text.
inline std::vector<HelpOption> options_in(const std::string& help) {
  std::vector<HelpOption> out;
  const std::regex line(R"(^\s+(?:-\w,)?--([a-z0-9-]+)(?:\s+(FLOAT,\.\.\.|FLOAT|INT|NAME|TEXT|FILE)(?=\s|$))?\s*(.*)$)");
  std::istringstream in(help);
  std::string text;
  while (std::getline(in, text)) {
    std::smatch m;
    if (std::regex_search(text, m, line)) {
      out.push_back({m[1].str(), !m[2].matched, m[2].str(), m[3].str()});
    } else if (!out.empty() && out.back().description.empty() && text.rfind("      ", 0) == 0) {
      out.back().description = text;  // wrapped: the description on its own line
    }
  }
  return out;
}

/// The --help texts of a command: its plain help, and for a command whose groups depend on the unit system
/// (the plain help points at `--units physical --help`) the physical one too.
inline std::vector<std::string> helps_of(const std::string& command) {
  std::vector<std::string> helps{help_of(command)};
  if (helps[0].find("--units physical --help") != std::string::npos) helps.push_back(help_of(command + " --units physical"));
  return helps;
}

/// Every option of a command (the union over helps_of).
inline std::vector<HelpOption> options_of(const std::string& command) {
  std::vector<HelpOption> out;
  for (const std::string& help : helps_of(command))
    for (const HelpOption& o : options_in(help)) {
      bool known = false;
      for (const HelpOption& k : out) known = known || k.name == o.name;
      if (!known) out.push_back(o);
    }
  return out;
}

/// Subcommand names listed by `afmkit <prefix> --help`.
inline std::vector<std::string> subcommands_of(const std::string& prefix) {
  std::vector<std::string> out;
  std::istringstream in(help_of(prefix));
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

/// The leaf commands found by walking --help from the top.
inline std::vector<std::string> leaf_commands() {
  std::vector<std::string> leaves;
  for (const std::string& top : subcommands_of("")) {
    const auto subs = subcommands_of(top);
    if (subs.empty()) leaves.push_back(top);
    for (const std::string& s : subs) leaves.push_back(top + " " + s);
  }
  return leaves;
}

}  // namespace afmkit_test
