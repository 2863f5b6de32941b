#include "study_selector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>

#include "afmkit/core/error.hpp"

namespace afmkit::python::study {

namespace {

using json = nlohmann::json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string trim(std::string s) {
  s.erase(0, s.find_first_not_of(" \t"));
  s.erase(s.find_last_not_of(" \t") + 1);
  return s;
}

[[noreturn]] void bad(const std::string& selector, const std::string& why) {
  throw InvalidParameter("outputs", "outputs: '" + selector + "': " + why);
}

bool is_name(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

bool is_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

/// key[field=value]… or a list index.
Step parse_step(const std::string& text, const std::string& selector) {
  Step step;
  const std::string t = trim(text);
  if (is_digits(t)) {
    if (t.size() > 9) bad(selector, "list index " + t + " is too large");
    step.is_index = true;
    step.index = static_cast<std::size_t>(std::stoul(t));
    return step;
  }
  const auto open = t.find('[');
  step.key = trim(t.substr(0, open));
  if (!is_name(step.key)) bad(selector, "'" + t + "' is not a key, a list index or key[field=value]");
  std::size_t at = open;
  while (at != std::string::npos && at < t.size()) {
    const auto close = t.find(']', at);
    if (t[at] != '[' || close == std::string::npos) bad(selector, "'" + t + "': a filter is written [field=value]");
    const std::string inside = t.substr(at + 1, close - at - 1);
    const auto eq = inside.find('=');
    const std::string field = trim(inside.substr(0, eq)), value = eq == std::string::npos ? "" : trim(inside.substr(eq + 1));
    if (eq == std::string::npos || !is_name(field) || value.empty())
      bad(selector, "'[" + inside + "]' is not a filter: a filter is written [field=value], e.g. [kind=maximum]");
    step.filters.emplace_back(field, value);
    at = close + 1;
    while (at < t.size() && (t[at] == ' ' || t[at] == '\t')) ++at;
  }
  return step;
}

std::vector<Step> parse_path(const std::string& text, const std::string& selector) {
  std::string p = trim(text);
  if (!p.empty() && p.front() == '/') p.erase(0, 1);
  if (p.empty()) bad(selector, "names nothing");
  std::vector<Step> steps;
  std::size_t start = 0;
  for (;;) {
    const auto slash = p.find('/', start);
    steps.push_back(parse_step(p.substr(start, slash == std::string::npos ? std::string::npos : slash - start), selector));
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  if (steps.front().is_index) bad(selector, "a results path starts with a key, not a list index");
  return steps;
}

double number_of(const json& v) {
  if (v.is_number()) return v.get<double>();
  if (v.is_boolean()) return v.get<bool>() ? 1.0 : 0.0;
  if (v.is_string()) {  // the JSON convention for infinities (docs/conventions.md#undefined-values)
    if (v == "inf") return std::numeric_limits<double>::infinity();
    if (v == "-inf") return -std::numeric_limits<double>::infinity();
  }
  return kNaN;  // null (undefined) or not a number
}

/// Whether a value counts: a true boolean, a defined number, a record or a label (not null, false or NaN).
bool holds(const json& v) {
  if (v.is_boolean()) return v.get<bool>();
  if (v.is_number()) return !std::isnan(v.get<double>());
  if (v.is_null()) return false;
  if (v.is_array()) return !v.empty();
  return true;  // records, labels, "inf"
}

/// Whether the record `v` has field == value (text equal, or numerically equal when both are numbers).
bool matches(const json& v, const std::pair<std::string, std::string>& filter) {
  if (!v.is_object() || !v.contains(filter.first)) return false;
  const json& f = v.at(filter.first);
  if (f.is_string()) return f.get<std::string>() == filter.second;
  if (f.is_boolean()) return filter.second == (f.get<bool>() ? "true" : "false") || filter.second == (f.get<bool>() ? "1" : "0");
  if (f.is_number()) {
    char* end = nullptr;
    const double x = std::strtod(filter.second.c_str(), &end);
    return end != filter.second.c_str() && *end == '\0' && x == f.get<double>();
  }
  return false;
}

/// The values a path selects; `several` when a key was applied to a list (one value per record).
struct Walk {
  std::vector<json> values;
  bool several = false;
};

Walk walk(const json& root, const std::vector<Step>& path) {
  Walk w;
  w.values.push_back(root);
  for (const Step& step : path) {
    std::vector<json> next;
    for (const json& v : w.values) {
      if (step.is_index) {
        if (v.is_array() && step.index < v.size()) next.push_back(v[step.index]);
        continue;
      }
      if (v.is_object()) {
        if (v.contains(step.key)) next.push_back(v.at(step.key));
      } else if (v.is_array()) {
        w.several = true;
        for (const json& e : v)
          if (e.is_object() && e.contains(step.key)) next.push_back(e.at(step.key));
      }
    }
    if (!step.filters.empty()) {
      for (json& v : next) {
        const auto keep = [&](const json& e) {
          return std::all_of(step.filters.begin(), step.filters.end(), [&](const auto& f) { return matches(e, f); });
        };
        if (v.is_array()) {
          json kept = json::array();
          for (const json& e : v)
            if (keep(e)) kept.push_back(e);
          v = std::move(kept);
        } else if (!keep(v)) {
          v = nullptr;
        }
      }
      next.erase(std::remove_if(next.begin(), next.end(), [](const json& v) { return v.is_null(); }), next.end());
    }
    w.values = std::move(next);
  }
  return w;
}

/// The unit a "units" document gives the path from `from` on (its keys; list indices and filters skipped; a unit
/// given for a key covers what lies below it), or "".
std::string unit_in(const json& units, const std::vector<Step>& path, std::size_t from) {
  const json* u = &units;
  for (std::size_t k = from; k < path.size(); ++k) {
    const Step& step = path[k];
    if (step.is_index) continue;
    if (u->is_string()) return u->get<std::string>();  // one unit for everything below (e.g. counts per kind)
    if (!u->is_object() || !u->contains(step.key)) return "";
    u = &u->at(step.key);
  }
  return u->is_string() ? u->get<std::string>() : "";
}

/// The unit of a results path: from the command's top-level "units", else from a "units" document of a record
/// on the way (e.g. tau0/units/beta_critical), or "".
std::string unit_of(const json& results, const std::vector<Step>& path) {
  const json* node = &results;
  for (std::size_t k = 0; k < path.size() && node; ++k) {
    if (node->is_object() && node->contains("units") && node->at("units").is_object()) {
      const std::string u = unit_in(node->at("units"), path, k);
      if (!u.empty()) return u;
    }
    const Step& step = path[k];
    while (node && node->is_array()) node = node->empty() ? nullptr : &node->front();  // a record stands for all
    if (!node) break;
    if (step.is_index) continue;
    node = node->is_object() && node->contains(step.key) ? &node->at(step.key) : nullptr;
  }
  return "";
}

std::string joined_columns(const cli::Captured& c) {
  std::string known;
  for (const auto& col : c.columns) known += (known.empty() ? "" : ", ") + col.name;
  return known;
}

std::string joined_results(const cli::Captured& c) {
  std::string known;
  for (const auto& [k, v] : c.results.items())
    if (k != "units" && (v.is_number() || v.is_boolean() || v.is_array() || v.is_object()))
      known += (known.empty() ? "" : ", ") + k;
  return known;
}

long column_index(const cli::Captured& c, const std::string& name) {
  for (std::size_t i = 0; i < c.columns.size(); ++i)
    if (c.columns[i].name == name) return static_cast<long>(i);
  return -1;
}

const char* aggregate_name(Aggregate a) {
  switch (a) {
    case Aggregate::min: return "min";
    case Aggregate::max: return "max";
    case Aggregate::sum: return "sum";
    case Aggregate::count: return "count";
    case Aggregate::first: return "first";
    case Aggregate::last: return "last";
    case Aggregate::none: break;
  }
  return "";
}

/// Aggregates `values` (already filtered).
template <class Values, class Get>
double aggregate(Aggregate a, const Values& values, Get get) {
  double acc = a == Aggregate::min ? std::numeric_limits<double>::infinity()
               : a == Aggregate::max ? -std::numeric_limits<double>::infinity()
                                     : 0.0;
  std::optional<double> first, last;
  long count = 0, defined = 0;
  for (const auto& item : values) {
    const json& v = get(item);
    if (holds(v)) ++count;
    const double x = number_of(v);
    if (!first) first = x;
    last = x;
    if (std::isnan(x)) continue;
    ++defined;
    if (a == Aggregate::min) acc = std::min(acc, x);
    if (a == Aggregate::max) acc = std::max(acc, x);
    if (a == Aggregate::sum) acc += x;
  }
  switch (a) {
    case Aggregate::count: return static_cast<double>(count);
    case Aggregate::first: return first.value_or(kNaN);
    case Aggregate::last: return last.value_or(kNaN);
    default: return defined == 0 ? kNaN : acc;  // min/max/sum of no defined value: undefined
  }
}

}  // namespace

Selector parse_selector(const std::string& text) {
  Selector s;
  s.text = text;
  if (trim(text).empty()) throw InvalidParameter("outputs", "outputs: an output is empty");
  const auto open = text.find('(');
  if (open == std::string::npos) {
    s.path = parse_path(text, text);
    return s;
  }
  const std::string name = trim(text.substr(0, open));
  const auto close = text.rfind(')');
  if (close == std::string::npos || close < open || !trim(text.substr(close + 1)).empty())
    bad(text, "must be a results path or agg(column), agg(column | flag), agg(path)");
  for (Aggregate a : {Aggregate::min, Aggregate::max, Aggregate::sum, Aggregate::count, Aggregate::first,
                      Aggregate::last})
    if (name == aggregate_name(a)) s.aggregate = a;
  if (s.aggregate == Aggregate::none)
    bad(text, "unknown aggregate '" + name + "': must be one of min, max, sum, count, first, last");
  const std::string inside = text.substr(open + 1, close - open - 1);
  const auto bar = inside.find('|');
  const std::string operand = trim(inside.substr(0, bar));
  if (bar != std::string::npos) s.flag = trim(inside.substr(bar + 1));
  if (operand.empty() || (bar != std::string::npos && s.flag.empty())) bad(text, "names no column or path");
  s.path = parse_path(operand, text);
  return s;
}

void bind_selectors(std::vector<Selector>& selectors, const cli::Captured& c) {
  for (Selector& s : selectors) {
    const Step& head = s.path.front();
    const bool bare = s.path.size() == 1 && head.filters.empty();
    s.column_index = s.aggregate != Aggregate::none && bare ? column_index(c, head.key) : -1;
    if (s.column_index >= 0) {  // over the table's rows
      if (!s.flag.empty()) {
        s.flag_index = column_index(c, s.flag);
        if (s.flag_index < 0) bad(s.text, "the table has no column '" + s.flag + "' (columns: " + joined_columns(c) + ")");
      }
      const std::string& unit = c.columns[static_cast<std::size_t>(s.column_index)].unit;
      const bool boolean = unit.rfind("boolean", 0) == 0;
      s.unit = s.aggregate == Aggregate::count || (s.aggregate == Aggregate::sum && boolean) ? "count" : unit;
      continue;
    }
    if (!c.results.contains(head.key) || head.key == "units") {
      if (s.aggregate != Aggregate::none && bare)
        bad(s.text, "the table has no column '" + head.key + "' (columns: " + joined_columns(c) +
                        ") and the command reports no '" + head.key + "' (results: " + joined_results(c) + ")");
      bad(s.text, "the command reports no '" + head.key + "' (results: " + joined_results(c) +
                      "; or agg(column) over its table)");
    }
    if (!s.flag.empty())
      bad(s.text, "'| " + s.flag + "' filters the rows of the table; filter the records of a results list with "
                  "[field=value], e.g. count(folds[kind=maximum])");
    const Walk w = walk(c.results, s.path);
    if (s.aggregate == Aggregate::none) {
      if (w.several)
        bad(s.text, "selects one value per record of a list: pick one by index (e.g. folds/0/separation) or "
                    "aggregate (e.g. min(folds/separation))");
      if (!w.values.empty() && w.values.front().is_array())
        bad(s.text, "is a list: pick an element by index (e.g. approach_jumps/0) or aggregate (e.g. "
                    "count(approach_jumps), min(approach_jumps))");
      if (!w.values.empty() && w.values.front().is_object())
        bad(s.text, "is a record: name one of its fields (e.g. " + s.text + "/" +
                        (w.values.front().empty() ? std::string("field") : w.values.front().begin().key()) + ")");
    }
    if (s.aggregate == Aggregate::count) {
      s.unit = "count";
    } else {
      s.unit = unit_of(c.results, s.path);
      if (s.unit.empty() && !w.values.empty() && w.values.front().is_boolean())
        s.unit = s.aggregate == Aggregate::sum ? "count" : "boolean (0/1)";
    }
  }
}

double extract(const Selector& s, const cli::Captured& c) {
  if (s.column_index >= 0) {
    std::vector<const json*> cells;
    for (const auto& row : c.rows) {
      if (s.flag_index >= 0 && !(number_of(row[static_cast<std::size_t>(s.flag_index)]) != 0.0)) continue;
      cells.push_back(&row[static_cast<std::size_t>(s.column_index)]);
    }
    return aggregate(s.aggregate, cells, [](const json* v) -> const json& { return *v; });
  }
  const Walk w = walk(c.results, s.path);
  if (s.aggregate == Aggregate::none) return w.values.size() == 1 ? number_of(w.values.front()) : kNaN;
  std::vector<json> flat;  // the elements of lists, the other values as they are
  for (const json& v : w.values) {
    if (v.is_array())
      flat.insert(flat.end(), v.begin(), v.end());
    else
      flat.push_back(v);
  }
  return aggregate(s.aggregate, flat, [](const json& v) -> const json& { return v; });
}

}  // namespace afmkit::python::study
