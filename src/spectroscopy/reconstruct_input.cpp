// Reading the measured curve of a reconstruction (reconstruct_input.hpp).
#include "afmkit/spectroscopy/reconstruct_input.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"

namespace afmkit::spectroscopy {

namespace {

enum class Role { distance, frequency, amplitude, phase };

struct ColumnSpec {
  Role role;
  double factor;  // to SI
  std::string name;
};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\"");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\"");
  return std::string(s.substr(b, e - b + 1));
}

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  if (sep == ' ') {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i >= line.size()) break;
      std::size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
      out.push_back(line.substr(i, j - i));
      i = j;
    }
    return out;
  }
  std::size_t start = 0;
  for (;;) {
    const auto p = line.find(sep, start);
    out.push_back(trim(std::string_view(line).substr(start, p == std::string::npos ? std::string::npos : p - start)));
    if (p == std::string::npos) break;
    start = p + 1;
  }
  return out;
}

std::optional<double> length_factor(const std::string& u) {
  static const std::map<std::string, double> f = {{"m", 1.0},      {"um", 1e-6},  {"µm", 1e-6}, {"nm", 1e-9},
                                                  {"pm", 1e-12},   {"a", 1e-10},  {"å", 1e-10}, {"angstrom", 1e-10},
                                                  // not lowered by tolower (multi-byte): Å, Greek mu
                                                  {"Å", 1e-10},    {"μm", 1e-6}};
  const auto it = f.find(u);
  return it == f.end() ? std::nullopt : std::optional<double>(it->second);
}

/// The column a header cell names, or an InputError.
ColumnSpec column_of(const std::string& cell, const std::string& origin, int line, std::size_t index) {
  std::string name = lower(trim(cell)), unit;
  const auto open = name.find_first_of("([");
  if (open != std::string::npos) {
    const auto close = name.find_first_of(")]", open);
    unit = trim(name.substr(open + 1, close == std::string::npos ? std::string::npos : close - open - 1));
    name = trim(name.substr(0, open));
  } else if (const auto us = name.rfind('_'); us != std::string::npos) {
    unit = name.substr(us + 1);
    name = name.substr(0, us);
  }
  const std::string where = fmt::format("{}:{}: column {} ('{}')", origin, line, index + 1, trim(cell));
  const std::string first = name.substr(0, name.find_first_of(" _\t"));
  Role role;
  if (first == "distance" || first == "separation" || first == "z" || first == "gap" || first == "height")
    role = Role::distance;
  else if (first == "frequency" || first == "df" || first == "delta" || first == "Δf")
    role = Role::frequency;
  else if (first == "amplitude")
    role = Role::amplitude;
  else if (first == "phase")
    role = Role::phase;
  else
    throw InputError(fmt::format("{}: not a column a reconstruction reads: distance (or separation), frequency "
                                 "shift, amplitude, phase",
                                 where));
  if (unit.empty())
    throw InputError(fmt::format("{}: no unit: write it in the header, e.g. '{} (nm)'", where, trim(cell)));
  double factor = 0.0;
  if (role == Role::distance || role == Role::amplitude) {
    const auto f = length_factor(unit);
    if (!f) throw InputError(fmt::format("{}: unit '{}' is not a length: one of nm, pm, A, Å, um, µm, m", where, unit));
    factor = *f;
  } else if (role == Role::frequency) {
    if (unit == "hz") factor = 1.0;
    else if (unit == "mhz") factor = 1e-3;
    else if (unit == "khz") factor = 1e3;
    else throw InputError(fmt::format("{}: unit '{}' is not a frequency: one of mHz, Hz, kHz", where, unit));
  } else {
    if (unit == "deg" || unit == "°" || unit == "degree" || unit == "degrees") factor = std::numbers::pi / 180.0;
    else if (unit == "rad") factor = 1.0;
    else throw InputError(fmt::format("{}: unit '{}' is not an angle: deg or rad", where, unit));
  }
  return {role, factor, trim(cell)};
}

}  // namespace

MeasuredCurve parse_measured_curve(std::string_view text, const std::string& origin) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  std::vector<ColumnSpec> cols;
  char sep = ',';
  int line_no = 0;
  int header_line = 0;
  MeasuredCurve c;
  std::size_t pos = 0;
  std::map<Role, std::size_t> index;
  while (pos <= text.size()) {
    const auto nl = text.find('\n', pos);
    std::string line(text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos));
    pos = nl == std::string_view::npos ? text.size() + 1 : nl + 1;
    ++line_no;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    if (cols.empty()) {
      header_line = line_no;
      sep = line.find(';') != std::string::npos ? ';' : line.find(',') != std::string::npos ? ',' : line.find('\t') != std::string::npos ? '\t' : ' ';
      const auto cells = split(line, sep);
      for (std::size_t i = 0; i < cells.size(); ++i) {
        cols.push_back(column_of(cells[i], origin, line_no, i));
        if (index.count(cols.back().role))
          throw InputError(fmt::format("{}:{}: column {} ('{}'): a second {} column", origin, line_no, i + 1,
                                       cols.back().name, cells[i]));
        index[cols.back().role] = i;
      }
      if (!index.count(Role::distance))
        throw InputError(fmt::format("{}:{}: no distance (or separation) column", origin, line_no));
      c.frequency_modulation = index.count(Role::frequency) > 0;
      if (c.frequency_modulation && (index.count(Role::amplitude) || index.count(Role::phase)))
        throw InputError(fmt::format("{}:{}: both a frequency shift (FM) and amplitude/phase (AM) columns: give one "
                                     "kind of curve",
                                     origin, line_no));
      if (!c.frequency_modulation && !(index.count(Role::amplitude) && index.count(Role::phase)))
        throw InputError(fmt::format("{}:{}: the columns are neither FM (distance, frequency shift) nor AM "
                                     "(separation, amplitude, phase)",
                                     origin, line_no));
      continue;
    }
    const auto cells = split(line, sep);
    if (cells.size() != cols.size())
      throw InputError(fmt::format("{}:{}: {} cells for {} columns", origin, line_no, cells.size(), cols.size()));
    std::vector<double> v(cells.size());
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::string& s = cells[i];
      double x = 0.0;
      const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), x);
      if (ec != std::errc() || p != s.data() + s.size() || s.empty() || !std::isfinite(x))
        throw InputError(fmt::format("{}:{}: column {} ('{}'): '{}' is not a finite number", origin, line_no, i + 1,
                                     cols[i].name, s));
      v[i] = x * cols[i].factor;
    }
    c.distance.push_back(v[index[Role::distance]]);
    if (c.frequency_modulation) c.frequency_shift.push_back(v[index[Role::frequency]]);
    else {
      c.amplitude.push_back(v[index[Role::amplitude]]);
      c.phase.push_back(v[index[Role::phase]]);
    }
    c.lines.push_back(line_no);
    const std::size_t n = c.distance.size();
    if (n >= 3) {
      const double a = c.distance[n - 3], b = c.distance[n - 2], d = c.distance[n - 1];
      if (!((b - a) * (d - b) > 0.0))
        throw InputError(fmt::format("{}:{}: column {} ('{}'): the distance is not strictly monotone ({} m after {} "
                                     "m and {} m): a curve must be one sweep in one direction",
                                     origin, line_no, index[Role::distance] + 1, cols[index[Role::distance]].name, d,
                                     b, a));
    } else if (n == 2 && c.distance[1] == c.distance[0]) {
      throw InputError(fmt::format("{}:{}: column {} ('{}'): the distance repeats", origin, line_no,
                                   index[Role::distance] + 1, cols[index[Role::distance]].name));
    }
  }
  if (cols.empty()) throw InputError(fmt::format("{}: no header line", origin));
  if (c.distance.size() < 5)
    throw InputError(fmt::format("{}:{}: {} rows: a reconstruction needs at least 5", origin, header_line,
                                 c.distance.size()));
  return c;
}

MeasuredCurve read_measured_curve(const std::string& path) {
  return parse_measured_curve(files::read_input_file(path, "measured curve"), path);
}

}  // namespace afmkit::spectroscopy
