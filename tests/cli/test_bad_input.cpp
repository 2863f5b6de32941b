// docs/bad-input.md, row by row: each documented bad input gives its exit status and message, and a rejected
// command (exit 2) writes nothing. The page is the test's data, so documentation and behaviour cannot drift.
#include <gtest/gtest.h>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.hpp"
#include "help_walk.hpp"

using afmkit_test::run_shell;
using afmkit_test::source_file;
using afmkit_test::TempDir;

namespace {

struct Row {
  std::string command;
  int status;
  std::string message;
  bool needs_python = false;  // under a heading "… (checked by the study runner …)": the Python package answers
  std::size_t number = 0;     // its place among the page's rows (1, 2, …): the test's name
};
// gtest prints parameters of failing tests.
[[maybe_unused]] void PrintTo(const Row& row, std::ostream* os) { *os << row.command; }

struct Page {
  std::vector<std::pair<std::string, std::string>> files;  // name, content
  std::vector<Row> rows;
};

// Backquoted cells may contain '|' only inside backquotes; split on " | " between cells.
Page read_page() {
  Page page;
  std::istringstream in(source_file("docs/bad-input.md"));
  const std::regex file_line(R"(^- `([^`]+)`: `(.*)`$)");
  const std::regex row_line(R"(^\| `(.+)` \| (\d+) \| `(.+)` \|$)");
  bool python_section = false;
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (line.rfind("## ", 0) == 0) python_section = line.find("checked by the study runner") != std::string::npos;
    if (std::regex_match(line, m, file_line)) {
      std::string content = m[2];  // "\n" in a fixture stands for a line break (multi-line files on one line)
      for (std::size_t at; (at = content.find("\\n")) != std::string::npos;) content.replace(at, 2, "\n");
      page.files.emplace_back(m[1], content);
    }
    else if (std::regex_match(line, m, row_line))
      page.rows.push_back({m[1], std::stoi(m[2]), m[3], python_section, page.rows.size() + 1});
  }
  return page;
}

// The rows run as tests: all of them in Release, every other one under the sanitizers (each row is a process of
// the program, ~10x slower there; the campaign's sampling, cli_run.hpp).
std::vector<Row> bad_input_rows_run() {
  std::vector<Row> out;
  for (const Row& row : read_page().rows)
    if (!afmkit_test::left_out_under_sanitizers(row.number - 1, 2)) out.push_back(row);
  return out;
}

}  // namespace

TEST(BadInputPage, HasRowsForEveryCommand) {
  const Page page = read_page();
  ASSERT_GE(page.rows.size(), 20u);
  for (const char* command : {"afmkit tapping hb", "afmkit tapping sweep", "afmkit tapping orbit", "afmkit demo",
                              "afmkit impact", "afmkit control tf", "afmkit control roots", "afmkit control margin",
                              "afmkit control chart", "afmkit control tune", "afmkit control simulate"}) {
    bool found = false;
    for (const Row& r : page.rows) found = found || r.command.find(command) != std::string::npos;
    EXPECT_TRUE(found) << "docs/bad-input.md has no row for " << command;
  }
}

class BadInputRow : public ::testing::TestWithParam<Row> {};

TEST_P(BadInputRow, GivesItsStatusAndMessageAndWritesNothingWhenRejected) {
  const Row& row = GetParam();
  if (row.needs_python && !afmkit_test::kHasPython)
    GTEST_SKIP() << "the study runner is the Python package, which this build (sanitizers) does not have";
  TempDir dir;
  for (const auto& [name, content] : read_page().files) dir.write(name, content + "\n");
  const std::size_t before = dir.count_files();
  const auto r = run_shell(row.command, dir);
  EXPECT_EQ(r.status, row.status) << row.command << "\n" << r.err;
  EXPECT_NE(r.err.find(row.message), std::string::npos)
      << row.command << "\nexpected in the message: " << row.message << "\ngot: " << r.err;
  if (row.status == 2) {
    EXPECT_EQ(dir.count_files(), before) << row.command << ": a file was written";
  }
}

// One test per row of the page (named by its row number), so ctest runs and reports them one by one.
INSTANTIATE_TEST_SUITE_P(Docs, BadInputRow, ::testing::ValuesIn(bad_input_rows_run()),
                         [](const ::testing::TestParamInfo<Row>& info) {
                           return "row" + std::to_string(info.param.number);
                         });
