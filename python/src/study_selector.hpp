#pragma once
// The output selectors of a parameter study (docs/study.md#outputs): what a study records at each point, taken
// from what the command computed (its results document and its table).
//
//   path                       one number of the results:  free_amplitude, folds/0/separation
//   agg(column)                over the table's rows:      max(amplitude), count(jumped)
//   agg(column | flag)         … over the rows whose `flag` column is true
//   agg(path)                  over the values of a path:  count(folds), min(folds/separation)
// A path is steps separated by '/': a key, a list index, or a key followed by filters [field=value] that keep
// the records of a list whose field equals value (jumps[direction=approach]/0/separation). A key applied to a
// list takes that field of every record (folds/separation: one value per fold; a plain path must name one value).
// agg is min, max, sum, count, first or last; count counts the values that hold: true booleans, defined numbers
// (not NaN), records and labels; min, max and sum skip undefined values; no value gives NaN (count: 0).
#include <string>
#include <vector>

#include "command.hpp"

namespace afmkit::python::study {

enum class Aggregate { none, min, max, sum, count, first, last };

/// One step of a results path: a key (with its filters) or a list index.
struct Step {
  bool is_index = false;
  std::string key;
  std::size_t index = 0;
  std::vector<std::pair<std::string, std::string>> filters;  // [field=value], all must hold
};

struct Selector {
  std::string text;
  Aggregate aggregate = Aggregate::none;
  std::vector<Step> path;    // the results path (or the bare operand of an aggregate, resolved by bind)
  std::string flag;          // agg(column | flag): the row filter
  long column_index = -1;    // the table column (bind: when the operand names one)
  long flag_index = -1;
  std::string unit;          // bind: the unit of the output
};

/// Parses one selector; InvalidParameter("outputs", …) naming it when it is malformed.
Selector parse_selector(const std::string& text);

/// Resolves the selectors against one point's results: table column or results path, and the unit of each output
/// (count: "count"; a column: its unit; a path: the command's "units" entry for it). Throws InvalidParameter
/// ("outputs") for an operand the command does not report, a plain path that selects a list, a record or several
/// values, and a row filter (| flag) on a results path.
void bind_selectors(std::vector<Selector>& selectors, const cli::Captured& c);

/// The value of a bound selector at one point (NaN: undefined there).
double extract(const Selector& s, const cli::Captured& c);

}  // namespace afmkit::python::study
