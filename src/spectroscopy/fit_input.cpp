// Reader of the measured curve file of `spectroscopy fit`: AM-AFM amplitude/phase or FM-AFM frequency shift
// (/dissipation) versus distance (format: fit_input.hpp, docs/fitting.md#input).
#include "afmkit/spectroscopy/fit_input.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::spectroscopy {

namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void fail(const std::string& origin, long line, long column, const std::string& message) {
  throw InputError(fmt::format("{}:{}:{}: {}", origin, line, column, message));
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '"')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '"'))
    s.remove_suffix(1);
  return s;
}

/// A cell and where it starts in its line (1-based column).
struct Cell {
  std::string_view text;
  long column;
};

std::vector<Cell> split(std::string_view line, char sep) {
  std::vector<Cell> cells;
  std::size_t i = 0;
  if (sep == ' ') {
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      if (i > start) cells.push_back({trim(line.substr(start, i - start)), static_cast<long>(start) + 1});
    }
    return cells;
  }
  while (true) {
    const std::size_t end = line.find(sep, i);
    std::string_view raw = line.substr(i, end == std::string_view::npos ? std::string_view::npos : end - i);
    std::size_t lead = 0;
    while (lead < raw.size() && (raw[lead] == ' ' || raw[lead] == '\t')) ++lead;
    cells.push_back({trim(raw), static_cast<long>(i + lead) + 1});
    if (end == std::string_view::npos) break;
    i = end + 1;
  }
  return cells;
}

enum class Role { distance, amplitude, phase, frequency_shift, dissipation };
constexpr int kRoles = 5;

struct Column {
  Role role;
  double factor;  // to SI (m, rad, Hz, J)
};

constexpr const char* kColumns =
    "AM: distance (nm), amplitude (nm), phase (deg); FM: distance (nm), frequency shift (Hz), dissipation (eV)";

std::optional<double> length_unit(const std::string& u) {
  static const std::map<std::string, double> units = {{"m", 1.0},    {"mm", 1e-3},  {"um", 1e-6},  {"µm", 1e-6},
                                                      {"nm", 1e-9},  {"pm", 1e-12}, {"a", 1e-10},  {"å", 1e-10},
                                                      {"angstrom", 1e-10}};
  const auto it = units.find(u);
  if (it == units.end()) return std::nullopt;
  return it->second;
}

Column parse_column(std::string_view text, const std::string& origin, long line, long column) {
  std::string name, unit;
  const std::string t(text);
  if (!t.empty() && (t.back() == ')' || t.back() == ']')) {
    const char open = t.back() == ')' ? '(' : '[';
    const std::size_t at = t.rfind(open);
    if (at == std::string::npos) fail(origin, line, column, fmt::format("column '{}': unbalanced '{}'", t, t.back()));
    name = std::string(trim(std::string_view(t).substr(0, at)));
    unit = std::string(trim(std::string_view(t).substr(at + 1, t.size() - at - 2)));
  } else if (const std::size_t us = t.rfind('_'); us != std::string::npos) {
    name = t.substr(0, us);
    unit = t.substr(us + 1);
  } else {
    fail(origin, line, column,
         fmt::format("column '{}' has no unit: write it as 'name (unit)', 'name [unit]' or 'name_unit' (distance "
                     "and amplitude: m, nm, pm, um, A; phase: rad or deg; frequency shift: Hz, mHz, kHz; dissipation: "
                     "J, aJ, zJ, eV, meV)",
                     t));
  }
  const std::string n = lower(name), u = lower(unit);
  Role role;
  if (n == "distance" || n == "separation" || n == "z" || n == "height" || n == "piezo" || n == "piezo separation")
    role = Role::distance;
  else if (n == "amplitude" || n == "amp")
    role = Role::amplitude;
  else if (n == "phase" || n == "phi")
    role = Role::phase;
  else if (n == "frequency shift" || n == "frequency_shift" || n == "df" || n == "delta f" || n == "delta_f" ||
           n == "Δf")
    role = Role::frequency_shift;
  else if (n == "dissipation" || n == "energy" || n == "dissipated energy" || n == "dissipated_energy")
    role = Role::dissipation;
  else
    fail(origin, line, column, fmt::format("unknown column '{}': the columns are {} (phase and dissipation optional)",
                                           name, kColumns));
  if (role == Role::phase) {
    if (u == "rad") return {role, 1.0};
    if (u == "deg" || u == "°" || u == "degree" || u == "degrees") return {role, kPi / 180.0};
    fail(origin, line, column, fmt::format("column '{}': unknown phase unit '{}' (rad or deg)", t, unit));
  }
  if (role == Role::frequency_shift) {
    static const std::map<std::string, double> hz = {{"hz", 1.0}, {"mhz", 1e-3}, {"khz", 1e3}};
    // "mHz" (milli) and "MHz" (mega) differ only in case: the unit is read as written for those two
    if (unit == "MHz") return {role, 1e6};
    if (const auto it = hz.find(u); it != hz.end()) return {role, it->second};
    fail(origin, line, column, fmt::format("column '{}': unknown frequency unit '{}' (Hz, mHz, kHz)", t, unit));
  }
  if (role == Role::dissipation) {
    static const std::map<std::string, double> joule = {
        {"j", 1.0}, {"aj", 1e-18}, {"zj", 1e-21}, {"ev", 1.602176634e-19}, {"mev", 1.602176634e-22}};
    if (const auto it = joule.find(u); it != joule.end()) return {role, it->second};
    fail(origin, line, column, fmt::format("column '{}': unknown energy unit '{}' (J, aJ, zJ, eV, meV)", t, unit));
  }
  const auto f = length_unit(u);
  if (!f)
    fail(origin, line, column,
         fmt::format("column '{}': unknown length unit '{}' (m, mm, um, µm, nm, pm, A, Å)", t, unit));
  return {role, *f};
}

double parse_number(const Cell& cell, const std::string& column, const std::string& origin, long line) {
  const std::string s(cell.text);
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec == std::errc::invalid_argument || ptr != s.data() + s.size())
    fail(origin, line, cell.column, fmt::format("'{}' is not a number (column {})", s.substr(0, 40), column));
  if (ec == std::errc::result_out_of_range || !std::isfinite(v))
    fail(origin, line, cell.column, fmt::format("'{}' is not a finite number (column {})", s.substr(0, 40), column));
  return v;
}

}  // namespace

FitCurveFile parse_fit_curve(std::string_view text, const std::string& origin) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  FitCurveFile file;
  FitCurve& c = file.am;
  FmFitCurve& f = file.fm;
  std::vector<Column> columns;
  std::vector<std::string> names;
  char sep = ',';
  long line_no = 0;
  long header_line = 0;
  std::map<double, long> seen;  // distance (SI) -> line
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t end = text.find('\n', pos);
    std::string_view line = text.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos);
    pos = end == std::string_view::npos ? text.size() + 1 : end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::string_view t = trim(line);
    if (t.empty() || t.front() == '#') continue;
    if (columns.empty()) {
      header_line = line_no;
      sep = line.find(';') != std::string_view::npos   ? ';'
            : line.find(',') != std::string_view::npos ? ','
            : line.find('\t') != std::string_view::npos ? '\t'
                                                        : ' ';
      std::vector<std::pair<std::string, long>> cells;  // column text, where it starts
      if (sep == ' ') {  // blank-separated: a column is the words up to and including its unit
        std::string current;
        long start = 0;
        for (const Cell& w : split(line, ' ')) {
          if (current.empty()) start = w.column;
          current += (current.empty() ? "" : " ") + std::string(w.text);
          const char last = w.text.empty() ? ' ' : w.text.back();
          if (last == ')' || last == ']' || w.text.find('_') != std::string_view::npos) {
            cells.emplace_back(current, start);
            current.clear();
          }
        }
        if (!current.empty()) cells.emplace_back(current, start);  // no unit: parse_column reports it
      } else {
        for (const Cell& cell : split(line, sep)) cells.emplace_back(std::string(cell.text), cell.column);
      }
      bool has[kRoles] = {};
      std::vector<long> at(kRoles, 1);
      for (const auto& [cell, column] : cells) {
        const Column col = parse_column(cell, origin, line_no, column);
        const int r = static_cast<int>(col.role);
        if (has[r]) fail(origin, line_no, column, fmt::format("column '{}' repeats a column", cell));
        has[r] = true;
        at[r] = column;
        columns.push_back(col);
        names.push_back(cell);
      }
      auto has_role = [&](Role r) { return has[static_cast<int>(r)]; };
      auto column_of = [&](Role r) { return at[static_cast<int>(r)]; };
      if (!has_role(Role::distance)) fail(origin, line_no, 1, fmt::format("no distance column ({})", kColumns));
      if (has_role(Role::amplitude) && has_role(Role::frequency_shift))
        fail(origin, line_no, column_of(Role::frequency_shift),
             fmt::format("both an amplitude and a frequency shift column: a curve is either AM or FM ({})", kColumns));
      if (!has_role(Role::amplitude) && !has_role(Role::frequency_shift))
        fail(origin, line_no, 1, fmt::format("no amplitude column (AM) and no frequency shift column (FM): {}",
                                             kColumns));
      file.mode = has_role(Role::frequency_shift) ? FitMode::fm : FitMode::am;
      if (file.mode == FitMode::fm && has_role(Role::phase))
        fail(origin, line_no, column_of(Role::phase),
             "a phase column in an FM curve (frequency shift): the FM columns are distance, frequency shift and "
             "(optionally) dissipation");
      if (file.mode == FitMode::am && has_role(Role::dissipation))
        fail(origin, line_no, column_of(Role::dissipation),
             "a dissipation column in an AM curve (amplitude): the AM columns are distance, amplitude and "
             "(optionally) phase");
      continue;
    }
    const std::vector<Cell> cells = split(line, sep);
    if (cells.size() != columns.size())
      fail(origin, line_no, cells.size() > columns.size() ? cells[columns.size()].column : static_cast<long>(line.size()) + 1,
           fmt::format("{} cells where the header (line {}) has {} columns", cells.size(), header_line,
                       columns.size()));
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const double v = parse_number(cells[k], names[k], origin, line_no) * columns[k].factor;
      switch (columns[k].role) {
        case Role::distance:
          if (const auto it = seen.find(v); it != seen.end())
            fail(origin, line_no, cells[k].column,
                 fmt::format("distance {} (column {}) repeats line {}: every distance must be distinct (average "
                             "repeated rows first)",
                             cells[k].text, names[k], it->second));
          seen[v] = line_no;
          (file.mode == FitMode::fm ? f.distance : c.distance).push_back(v);
          break;
        case Role::frequency_shift:
          f.frequency_shift.push_back(v);
          break;
        case Role::dissipation:
          f.dissipation.push_back(v);
          break;
        case Role::amplitude:
          if (!(v > 0.0))
            fail(origin, line_no, cells[k].column,
                 fmt::format("amplitude {} is out of range: must be > 0 (column {})", cells[k].text, names[k]));
          c.amplitude.push_back(v);
          break;
        case Role::phase:
          c.phase.push_back(v);
          break;
      }
    }
  }
  if (columns.empty()) fail(origin, line_no, 1, fmt::format("no header line ({})", kColumns));
  const std::size_t rows = file.mode == FitMode::fm ? f.distance.size() : c.distance.size();
  if (rows < 3) fail(origin, header_line, 1, fmt::format("{} data row(s): at least 3 are needed", rows));
  return file;
}

FitCurve parse_am_curve(std::string_view text, const std::string& origin) {
  FitCurveFile file = parse_fit_curve(text, origin);
  if (file.mode != FitMode::am)
    throw InputError(fmt::format("{}:1:1: an FM curve (frequency shift column) where an AM curve (amplitude, phase) "
                                 "is read",
                                 origin));
  return std::move(file.am);
}

FitCurveFile read_fit_curve(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot open file '{}'", path));
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_fit_curve(ss.str(), path);
}

FitCurve read_am_curve(const std::string& path) {
  FitCurveFile file = read_fit_curve(path);
  if (file.mode != FitMode::am)
    throw InputError(fmt::format("{}:1:1: an FM curve (frequency shift column) where an AM curve (amplitude, phase) "
                                 "is read",
                                 path));
  return std::move(file.am);
}

}  // namespace afmkit::spectroscopy
