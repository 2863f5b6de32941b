// _afmkit.evaluate_points: one chunk of a parameter study (python/afmkit/study/) computed in C++ — the points'
// parameters set, the command run and the outputs extracted without the interpreter (no Python per point).
//
// An output is a selector on what the command computed (docs/study.md):
//   key[/key…]                    a number of the command's results ("critical_delay", "folds/0/separation")
//   agg(column)                   over the command's table: min, max, sum, count, first, last of a column
//   agg(column | flag)            … over the rows whose column `flag` is true (non-zero)
// A point whose computation fails numerically (no convergence) gets NaN in every output and is counted.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/params.hpp"
#include "bindings.hpp"
#include "interrupts.hpp"
#include "command.hpp"
#include "params_from_python.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

enum class Aggregate { none, min, max, sum, count, first, last };

struct Selector {
  std::string text;
  Aggregate aggregate = Aggregate::none;
  nlohmann::json::json_pointer pointer;  // results path (aggregate none)
  std::string first_key;                 // its first key (must be reported by the command)
  std::string column, flag;              // table column and optional row filter
  long column_index = -1, flag_index = -1;
};

std::string trim(std::string s) {
  s.erase(0, s.find_first_not_of(" \t"));
  s.erase(s.find_last_not_of(" \t") + 1);
  return s;
}

Selector parse_selector(const std::string& text) {
  Selector s;
  s.text = text;
  const auto open = text.find('(');
  if (open == std::string::npos) {
    if (trim(text).empty()) throw InvalidParameter("outputs", "outputs: an output is empty");
    std::string path = trim(text);
    if (path.front() != '/') path = "/" + path;
    s.first_key = path.substr(1, path.find('/', 1) - 1);
    try {
      s.pointer = nlohmann::json::json_pointer(path);
    } catch (const nlohmann::json::exception&) {
      throw InvalidParameter("outputs", "outputs: '" + text + "' is not a results path (key/key/…)");
    }
    return s;
  }
  const std::string name = trim(text.substr(0, open));
  const auto close = text.rfind(')');
  if (close == std::string::npos || close < open || !trim(text.substr(close + 1)).empty())
    throw InvalidParameter("outputs", "outputs: '" + text + "' must be agg(column) or agg(column | flag)");
  const std::vector<std::pair<std::string, Aggregate>> names = {{"min", Aggregate::min},     {"max", Aggregate::max},
                                                                {"sum", Aggregate::sum},     {"count", Aggregate::count},
                                                                {"first", Aggregate::first}, {"last", Aggregate::last}};
  for (const auto& [n, a] : names)
    if (n == name) s.aggregate = a;
  if (s.aggregate == Aggregate::none)
    throw InvalidParameter("outputs", "outputs: '" + text + "': unknown aggregate '" + name +
                                          "': must be one of min, max, sum, count, first, last");
  const std::string inside = text.substr(open + 1, close - open - 1);
  const auto bar = inside.find('|');
  s.column = trim(inside.substr(0, bar));
  if (bar != std::string::npos) s.flag = trim(inside.substr(bar + 1));
  if (s.column.empty() || (bar != std::string::npos && s.flag.empty()))
    throw InvalidParameter("outputs", "outputs: '" + text + "' names no column");
  return s;
}

double number_of(const nlohmann::json& v) {
  if (v.is_number()) return v.get<double>();
  if (v.is_boolean()) return v.get<bool>() ? 1.0 : 0.0;
  if (v.is_string()) {  // the JSON convention for infinities (docs/conventions.md#undefined-values)
    if (v == "inf") return std::numeric_limits<double>::infinity();
    if (v == "-inf") return -std::numeric_limits<double>::infinity();
  }
  return kNaN;  // null (undefined) or not a number
}

long column_index(const std::vector<io::Column>& columns, const std::string& name, const std::string& selector) {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i].name == name) return static_cast<long>(i);
  std::string known;
  for (const auto& c : columns) known += (known.empty() ? "" : ", ") + c.name;
  throw InvalidParameter("outputs", "outputs: '" + selector + "': the table has no column '" + name +
                                        "' (columns: " + known + ")");
}

/// Resolves column names against the first point's table and checks that results paths start with a key the
/// command reports (a path further down may be absent at some points: NaN there).
void bind_selectors(std::vector<Selector>& selectors, const cli::Captured& c) {
  for (Selector& s : selectors) {
    if (s.aggregate == Aggregate::none) {
      const std::string& first = s.first_key;
      if (!c.results.contains(first)) {
        std::string known;
        for (const auto& [k, v] : c.results.items())
          if (v.is_number() || v.is_boolean() || v.is_array() || v.is_object()) known += (known.empty() ? "" : ", ") + k;
        throw InvalidParameter("outputs", "outputs: '" + s.text + "': the command reports no '" + first +
                                              "' (results: " + known + "; or agg(column) over its table)");
      }
    } else {
      s.column_index = column_index(c.columns, s.column, s.text);
      if (!s.flag.empty()) s.flag_index = column_index(c.columns, s.flag, s.text);
    }
  }
}

double extract(const Selector& s, const cli::Captured& c) {
  if (s.aggregate == Aggregate::none) return c.results.contains(s.pointer) ? number_of(c.results.at(s.pointer)) : kNaN;
  double acc = s.aggregate == Aggregate::min ? std::numeric_limits<double>::infinity()
               : s.aggregate == Aggregate::max ? -std::numeric_limits<double>::infinity()
                                               : 0.0;
  std::optional<double> first, last;
  long count = 0;
  for (const auto& row : c.rows) {
    if (s.flag_index >= 0 && !(number_of(row[static_cast<std::size_t>(s.flag_index)]) != 0.0)) continue;
    const double v = number_of(row[static_cast<std::size_t>(s.column_index)]);
    if (!first) first = v;
    last = v;
    ++count;
    if (s.aggregate == Aggregate::min) acc = std::min(acc, v);
    if (s.aggregate == Aggregate::max) acc = std::max(acc, v);
    if (s.aggregate == Aggregate::sum) acc += v;
  }
  switch (s.aggregate) {
    case Aggregate::count: return static_cast<double>(count);
    case Aggregate::first: return first.value_or(kNaN);
    case Aggregate::last: return last.value_or(kNaN);
    default: return count == 0 ? kNaN : acc;  // min/max/sum of no row: undefined
  }
}

/// The result of one chunk: outputs[point, output] and the number of points that failed numerically.
struct ChunkResult {
  py::array_t<double> outputs;
  long failed = 0;
};

ChunkResult evaluate_points(const std::string& path, const py::dict& base, const std::vector<std::string>& names,
                            const py::array_t<double, py::array::c_style | py::array::forcecast>& values,
                            const std::vector<std::string>& outputs) {
  std::string fn = "afmkit.study(" + path + ")";
  const cli::CommandSpec& spec = command_spec(path);
  const io::ParamSet prepared = params_from_python(path, fn, base);
  if (values.ndim() != 2 || values.shape(1) != static_cast<py::ssize_t>(names.size()))
    throw py::value_error("evaluate_points: values must be an array of shape (points, axes)");
  std::vector<bool> integer;  // per axis: an integer parameter (else real)
  const auto described = prepared.describe();
  for (const std::string& n : names) {
    const auto it = std::find_if(described.begin(), described.end(), [&](const auto& d) { return d.key == n; });
    if (it == described.end() || (it->kind != "real" && it->kind != "integer"))
      throw InvalidParameter("axes", "axes: '" + n + "' is not a numeric parameter of afmkit " + path);
    integer.push_back(it->kind == "integer");
  }
  std::vector<Selector> selectors;
  for (const std::string& o : outputs) selectors.push_back(parse_selector(o));
  if (selectors.empty()) throw InvalidParameter("outputs", "outputs: at least one output is needed");
  const bool rows = std::any_of(selectors.begin(), selectors.end(), [](const Selector& s) {
    return s.aggregate != Aggregate::none;
  });

  const auto n = static_cast<std::size_t>(values.shape(0));
  ChunkResult out;
  out.outputs = py::array_t<double>({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(selectors.size())});
  double* o = out.outputs.mutable_data();
  const double* v = values.data();
  SignalPoll interrupts;  // Ctrl-C stops the chunk at the next point (or inside a long point) with KeyboardInterrupt
  interrupts.run([&] {
    bool bound = false;
    for (std::size_t i = 0; i < n; ++i) {
      interrupts.cancellation().check();
      io::ParamSet p = prepared;
      for (std::size_t j = 0; j < names.size(); ++j) {
        const double x = v[i * names.size() + j];
        if (integer[j]) {
          if (!(std::isfinite(x) && x == std::floor(x) && std::abs(x) < 9.0e15))
            throw InvalidParameter(names[j], "axes: " + names[j] + " = " + std::to_string(x) + " is not an integer");
          p.set_value(names[j], static_cast<long>(x));
        } else {
          p.set_value(names[j], x);
        }
      }
      cli::Captured captured;
      captured.want_rows = rows;
      captured.cancellation = interrupts.cancellation();
      try {
        spec.run(p, &captured);
      } catch (const NumericalFailure&) {
        ++out.failed;
        for (std::size_t k = 0; k < selectors.size(); ++k) o[i * selectors.size() + k] = kNaN;
        continue;
      }
      if (!bound) {
        bind_selectors(selectors, captured);
        bound = true;
      }
      for (std::size_t k = 0; k < selectors.size(); ++k) o[i * selectors.size() + k] = extract(selectors[k], captured);
    }
  });
  return out;
}

}  // namespace

void bind_study(py::module_& m) {
  m.def(
      "evaluate_points",
      [](const std::string& path, const py::dict& base, const std::vector<std::string>& names,
         const py::array_t<double, py::array::c_style | py::array::forcecast>& values,
         const std::vector<std::string>& outputs) {
        ChunkResult r = evaluate_points(path, base, names, values, outputs);
        return py::make_tuple(r.outputs, r.failed);
      },
      py::arg("path"), py::arg("base"), py::arg("names"), py::arg("values"), py::arg("outputs"),
      "One chunk of a study: command `path` with parameters `base` (TOML keys), at each row of `values` (columns: "
      "the parameters `names`), returning (outputs[point, output] as float64, points that failed numerically).");
}

}  // namespace afmkit::python
