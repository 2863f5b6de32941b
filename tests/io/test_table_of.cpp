// Tables declared once (io::TableOf): each column carries its value; the header, the sidecar's columns and the
// rows come from the one list; grids are recorded with their coordinates and checked against the rows.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include "afmkit/io/table.hpp"

namespace fs = std::filesystem;
using afmkit::io::Cell;
using afmkit::io::GridRecord;
using afmkit::io::TableOf;
using afmkit::io::TableWriter;

namespace {

struct TableOfSample {
  double x;
  int count;
  std::size_t size;
  bool flag;
  const char* label;
};

TableOf<TableOfSample> table_of_sample_table(double scale) {
  using S = TableOfSample;
  return {{"x", "nm", "x scaled", [scale](const S& s) { return s.x * scale; }},
          {"count", "count", "an int", &S::count},
          {"size", "count", "a size_t", &S::size},
          {"flag", "boolean (0/1)", "a flag", &S::flag},
          {"label", "label", "a text", [](const S& s) { return std::string(s.label) + ",!"; }}};
}

std::string table_of_read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fs::path table_of_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("afmkit_test_table_of_" + name + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

}  // namespace

TEST(TableOf, CellsKeepTheirKind) {
  EXPECT_TRUE(std::holds_alternative<long>(afmkit::io::to_cell(3)));
  EXPECT_TRUE(std::holds_alternative<long>(afmkit::io::to_cell(std::size_t{3})));
  EXPECT_TRUE(std::holds_alternative<bool>(afmkit::io::to_cell(true)));
  EXPECT_TRUE(std::holds_alternative<double>(afmkit::io::to_cell(0.5f)));
  EXPECT_EQ(std::get<std::string>(afmkit::io::to_cell("abc")), "abc");
  EXPECT_EQ(afmkit::io::cell_json(afmkit::io::to_cell(true)).dump(), "true");
  EXPECT_EQ(afmkit::io::cell_json(afmkit::io::to_cell(7)).dump(), "7");
}

TEST(TableOf, WritesTheSameFileAsTheColumnsAndValuesListedByHand) {
  const fs::path dir = table_of_dir("same");
  const std::vector<TableOfSample> rows = {{0.1, -2, 7, true, "a"}, {std::nan(""), 0, 0, false, "b\"c"}};
  const TableOf<TableOfSample> table = table_of_sample_table(3.0);
  {
    TableWriter declared((dir / "declared.csv").string(), table.columns());
    for (const TableOfSample& s : rows) afmkit::io::write_row(declared, table, s);
    declared.commit(afmkit::io::make_sidecar("test", {{"k", 1}}));
    // independently: the columns and each row's values written in order by hand
    TableWriter by_hand((dir / "by_hand.csv").string(), {{"x", "nm", "x scaled"},
                                                         {"count", "count", "an int"},
                                                         {"size", "count", "a size_t"},
                                                         {"flag", "boolean (0/1)", "a flag"},
                                                         {"label", "label", "a text"}});
    by_hand.row(0.1 * 3.0, -2L, 7L, true, "a,!");
    by_hand.row(std::nan(""), 0L, 0L, false, "b\"c,!");
    by_hand.commit(afmkit::io::make_sidecar("test", {{"k", 1}}));
  }
  EXPECT_EQ(table_of_read(dir / "declared.csv"), table_of_read(dir / "by_hand.csv"));
  EXPECT_EQ(table_of_read(dir / "declared.csv.json"), table_of_read(dir / "by_hand.csv.json"));
  EXPECT_NE(table_of_read(dir / "declared.csv").find("\"b\"\"c,!\""), std::string::npos);  // quoted as RFC 4180
  fs::remove_all(dir);
}

TEST(TableOf, PrependAndDescribeChangeTheOneList) {
  TableOf<TableOfSample> table = table_of_sample_table(1.0);
  table.prepend({"first", "s", "put first", [](const TableOfSample& s) { return s.count * 2; }})
      .describe("x", "another meaning");
  const auto columns = table.columns();
  ASSERT_EQ(columns.size(), 6u);
  EXPECT_EQ(columns[0].name, "first");
  EXPECT_EQ(columns[1].description, "another meaning");
  EXPECT_EQ(std::get<long>(table.entries()[0].value({0.0, 21, 0, false, ""})), 42);
  EXPECT_THROW(table.describe("nothing", "x"), std::logic_error);
  EXPECT_THROW(table.grid({{"nothing", "n", 2}}), std::logic_error);
}

TEST(TableOf, GridRecordHasTheCoordinatesOfTheRowMajorRows) {
  GridRecord g({{"y", "beta", 2}, {"x", "alpha", 3}});
  const double ys[] = {-1.0, 4.0}, xs[] = {0.5, 1.5, std::numeric_limits<double>::infinity()};
  for (double y : ys)
    for (double x : xs) {
      g.value(0, y);
      g.value(1, x);
      g.end_row();
    }
  const nlohmann::json j = g.json();
  EXPECT_EQ(j["dims"], nlohmann::json({"beta", "alpha"}));
  EXPECT_EQ(j["columns"], nlohmann::json({"y", "x"}));
  EXPECT_EQ(j["shape"], nlohmann::json({2, 3}));
  EXPECT_EQ(j["coords"]["beta"], nlohmann::json({-1.0, 4.0}));
  EXPECT_EQ(j["coords"]["alpha"], nlohmann::json({0.5, 1.5, "inf"}));  // afmkit's JSON convention for infinity
}

TEST(TableOf, GridRecordRefusesRowsOffTheGrid) {
  GridRecord swapped({{"y", "y", 2}, {"x", "x", 2}});
  swapped.value(0, 0.0);
  swapped.value(1, 0.0);
  swapped.end_row();
  // the second row must still be at y[0] (x varies fastest)
  EXPECT_THROW(swapped.value(0, 1.0), std::logic_error);

  GridRecord short_of_rows({{"x", "x", 3}});
  short_of_rows.value(0, 1.0);
  short_of_rows.end_row();
  EXPECT_THROW(short_of_rows.json(), std::logic_error);
}
