// Every command example of the README and docs/ runs as written and succeeds (under the sanitizer build too,
// where this is how the documented command lines are checked for memory errors and undefined behaviour), and
// every CSV table it writes is self-describing: its JSON sidecar lists every header column, in order, with a unit
// and a description (docs/commands.md#outputs).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"
#include "help_walk.hpp"

using afmkit_test::run_shell;
using afmkit_test::source_file;
using afmkit_test::TempDir;

namespace {

struct Example {
  std::string origin;   // file:line
  std::string command;  // with `afmkit` for build/bin/afmkit
};
[[maybe_unused]] void PrintTo(const Example& e, std::ostream* os) { *os << e.origin << ": " << e.command; }

std::string trim(std::string s) {
  s.erase(0, s.find_first_not_of(' '));
  s.erase(s.find_last_not_of(' ') + 1);
  return s;
}

// Indented code lines starting with build/bin/afmkit; '\' continues a line; a trailing '# …' is a comment;
// a word "a|b|c" stands for one example per alternative.
std::vector<Example> examples() {
  std::vector<std::string> pages{"README.md"};
  for (const auto& f : std::filesystem::directory_iterator(std::filesystem::path(AFMKIT_SOURCE_DIR) / "docs"))
    if (f.path().extension() == ".md") pages.push_back("docs/" + f.path().filename().string());
  std::vector<Example> out;
  const std::string prefix = "    build/bin/afmkit";
  for (const std::string& page : pages) {
    std::istringstream in(source_file(page));
    int number = 0;
    for (std::string line; std::getline(in, line);) {
      ++number;
      if (line.rfind(prefix, 0) != 0) continue;
      const int first = number;
      std::string command = line;
      while (!command.empty() && command.back() == '\\' && std::getline(in, line)) {
        ++number;
        command.pop_back();
        command += " " + trim(line);
      }
      if (const auto hash = command.find(" #"); hash != std::string::npos) command.erase(hash);
      command = "afmkit" + trim(command).substr(std::string("build/bin/afmkit").size());
      std::vector<std::string> variants{command};
      if (const auto bar = command.find('|'); bar != std::string::npos) {
        variants.clear();
        const auto start = command.rfind(' ', bar) + 1, end = command.find(' ', bar);
        std::istringstream alternatives(command.substr(start, end - start));
        for (std::string alt; std::getline(alternatives, alt, '|');)
          variants.push_back(command.substr(0, start) + alt + command.substr(end));
      }
      for (const auto& v : variants) out.push_back({page + ":" + std::to_string(first), v});
    }
  }
  return out;
}

class DocumentedExample : public ::testing::TestWithParam<Example> {};

/// Every CSV below `dir` (not following links) has a sidecar whose "columns" match its header, each with a unit
/// and a description.
void expect_self_describing_tables(const std::filesystem::path& dir, const std::string& origin) {
  namespace fs = std::filesystem;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
    if (it->is_symlink()) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->path().extension() != ".csv") continue;
    std::ifstream csv(it->path());
    std::string header;
    std::getline(csv, header);
    std::vector<std::string> names;
    std::istringstream cells(header);
    for (std::string name; std::getline(cells, name, ',');) names.push_back(name);
    std::ifstream sidecar(it->path().string() + ".json");
    ASSERT_TRUE(sidecar) << origin << ": " << it->path() << " has no sidecar";
    const auto meta = nlohmann::json::parse(sidecar);
    ASSERT_TRUE(meta.contains("columns")) << origin << ": " << it->path() << ".json has no column list";
    const auto& columns = meta["columns"];
    ASSERT_EQ(columns.size(), names.size()) << origin << ": " << it->path();
    for (std::size_t i = 0; i < names.size(); ++i) {
      EXPECT_EQ(columns[i].value("name", ""), names[i]) << origin << ": " << it->path();
      EXPECT_FALSE(columns[i].value("unit", "").empty()) << origin << ": column " << names[i] << " has no unit";
      EXPECT_FALSE(columns[i].value("description", "").empty())
          << origin << ": column " << names[i] << " has no description";
    }
    EXPECT_TRUE(meta.contains("parameter_units")) << origin << ": " << it->path();
  }
}

}  // namespace

TEST(DocumentedExamples, AreFound) { EXPECT_GE(examples().size(), 20u); }

TEST_P(DocumentedExample, RunsAndSucceeds) {
  const std::string& command = GetParam().command;
  const bool python = command.rfind("afmkit report", 0) == 0 || command.rfind("afmkit study run", 0) == 0;
  if (python && command.find("--help") == std::string::npos && !afmkit_test::kHasPython)
    GTEST_SKIP() << "afmkit report and study run need the Python module, which this build (sanitizers) does not have";
  TempDir dir;
  // documented commands run from the source tree: its example inputs (examples/force_curves/…) are reachable
  std::filesystem::create_directory_symlink(std::filesystem::path(AFMKIT_SOURCE_DIR) / "examples",
                                            dir.path / "examples");
  const auto r = run_shell(GetParam().command, dir);
  EXPECT_EQ(r.status, 0) << GetParam().origin << ": " << GetParam().command << "\n" << r.err;
  expect_self_describing_tables(dir.path, GetParam().origin);
}

INSTANTIATE_TEST_SUITE_P(Docs, DocumentedExample, ::testing::ValuesIn(examples()),
                         [](const ::testing::TestParamInfo<Example>& info) {
                           std::string name = info.param.origin;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name + "_" + std::to_string(info.index);
                         });
