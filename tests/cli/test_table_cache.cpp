// What `tapping orbit` does per run besides its search is kept small (issue 26: "the command layer adds <= 5 % to a
// 1 ms command", bench/command_layer.py): its table is declared once per set of units and shared (TableCache,
// io::SharedTable, io::ColumnList), the law keys given are read once (LawChoice) and a cost model's text is made
// only for a refused request (require_work_with). These tests check that the sharing happens and changes nothing.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "command.hpp"
#include "law_params.hpp"
#include "orbit_as_python.hpp"
#include "table_cache.hpp"
#include "work_budget.hpp"

namespace {

afmkit::cli::Captured table_cache_run(const afmkit::io::ParamSet& p) {
  afmkit::cli::Captured c;
  afmkit_test::orbit_command_spec().run(p, &c);
  return c;
}

TEST(TableCache, RunsInTheSameUnitsShareOneColumnListAndOtherUnitsGetTheirOwn) {
  const afmkit::io::ParamSet normalised = afmkit_test::orbit_params_as_python("", "normalised");
  const afmkit::io::ParamSet physical = afmkit_test::orbit_params_as_python("", "physical");
  const afmkit::cli::Captured a = table_cache_run(normalised);
  const afmkit::cli::Captured b = table_cache_run(normalised);
  const afmkit::cli::Captured c = table_cache_run(physical);
  const afmkit::cli::Captured d = table_cache_run(normalised);
  // the table as declared: one column per orbit observable, lengths in the run's unit
  ASSERT_EQ(a.columns.size(), 21u);
  EXPECT_EQ(a.columns[0].name, "source");
  std::vector<std::string> names;
  for (const afmkit::io::Column& col : a.columns) names.push_back(col.name);
  EXPECT_EQ(names[3], "amplitude");
  EXPECT_EQ(names.back(), "trapped");
  EXPECT_EQ(a.columns[3].unit, "L");
  EXPECT_EQ(c.columns[3].unit, "nm");
  EXPECT_EQ(c.columns[3].description, a.columns[3].description);
  // the same list handed to every run in the same units (not a copy), another one in other units
  EXPECT_EQ(&a.columns.vector(), &b.columns.vector());
  EXPECT_EQ(&a.columns.vector(), &d.columns.vector());
  EXPECT_NE(&a.columns.vector(), &c.columns.vector());
  // and the rows as before: one orbit, its cells in the columns' order
  ASSERT_EQ(a.rows.size(), 1u);
  EXPECT_EQ(a.rows[0].size(), a.columns.size());
  EXPECT_EQ(a.rows, b.rows);
}

int table_cache_made = 0;  // tables made by table_cache_make (the cache's make is a plain function)
afmkit::io::TableOf<double> table_cache_make(const int& scale) {
  ++table_cache_made;
  return {{"x", "count", "x times " + std::to_string(scale), [scale](double x) { return x * scale; }}};
}

TEST(TableCache, MakesATableOncePerUnitsAndKeepsTheLastFew) {
  table_cache_made = 0;
  afmkit::cli::TableCache<double, int> cache(table_cache_make);
  const afmkit::io::SharedTable<double> one = cache.get(1);
  EXPECT_EQ(&cache.get(1).table(), &one.table());
  EXPECT_EQ(table_cache_made, 1);
  EXPECT_EQ(cache.get(2).columns()[0].description, "x times 2");
  EXPECT_EQ(std::get<double>(cache.get(2).table().entries()[0].value(3.0)), 6.0);
  EXPECT_EQ(table_cache_made, 2);
  for (int u = 3; u <= 5; ++u) cache.get(u);  // five sets of units: the first one is dropped
  EXPECT_EQ(table_cache_made, 5);
  EXPECT_EQ(cache.get(5).columns()[0].description, "x times 5");
  EXPECT_EQ(table_cache_made, 5);
  EXPECT_EQ(cache.get(1).columns()[0].description, "x times 1");
  EXPECT_EQ(table_cache_made, 6);  // made again
  // a table handed out stays valid when the cache drops it
  EXPECT_EQ(one.columns()[0].description, "x times 1");
}

TEST(TableCache, AnEmptyColumnListIsAnEmptyRange) {
  const afmkit::io::ColumnList none;
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(none.size(), 0u);
  EXPECT_EQ(none.begin(), none.end());
}

TEST(TableCache, LawChoiceReadsTheLawAndTheKeysGivenOnce) {
  afmkit::io::ParamSet p = afmkit_test::orbit_params_as_python("", "normalised");
  p.set_value("restitution", 0.5);
  const afmkit::impact::LawRegistry registry = afmkit::impact::LawRegistry::builtin();
  const afmkit::cli::LawChoice choice(p, registry);
  EXPECT_EQ(choice.spec.name, "hysteresis");
  ASSERT_EQ(choice.given.size(), registry.keys().size());
  for (std::size_t i = 0; i < registry.keys().size(); ++i)
    EXPECT_EQ(choice.given[i] != 0, registry.keys()[i].key == "restitution") << registry.keys()[i].key;
  // the law built from the choice is the one built from the parameters (K_b = e^2 K_a)
  const afmkit::impact::ForceLaw from_choice = afmkit::cli::law_from_params(p, registry, choice);
  const afmkit::impact::ForceLaw from_params = afmkit::cli::law_from_params(p, registry);
  for (double gap : {-0.5, -0.1, 0.2}) {
    EXPECT_EQ(from_choice.approach(gap), from_params.approach(gap));
    EXPECT_EQ(from_choice.departure(gap), from_params.departure(gap));
  }
  EXPECT_GT(from_choice.approach(-0.5), 0.0);
  EXPECT_DOUBLE_EQ(from_choice.departure(-0.5), 0.25 * from_choice.approach(-0.5));  // K_b = e^2 K_a, e = 0.5
}

TEST(TableCache, ACostModelIsWordedOnlyForARefusedRequest) {
  int worded = 0;
  const auto model = [&] {
    ++worded;
    return std::string("n steps of 1 s");
  };
  // within the limit (1 hour unless AFMKIT_WORK_LIMIT says otherwise): the estimate, nothing worded
  EXPECT_EQ(afmkit::cli::require_work_with("n", 10.0, 1e-9, model), 1e-8);
  EXPECT_EQ(worded, 0);
  // beyond it: the message of require_work, with the model's words
  std::string message;
  try {
    afmkit::cli::require_work_with("n", 1e30, 1.0, model);
  } catch (const afmkit::InvalidParameter& e) {
    message = e.what();
  }
  EXPECT_EQ(worded, 1);
  EXPECT_NE(message.find("n = 1e+30 would take about"), std::string::npos) << message;
  EXPECT_NE(message.find("(n steps of 1 s)"), std::string::npos) << message;
}

}  // namespace
