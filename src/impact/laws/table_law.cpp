// A force law from a measured force curve: the table reader and the PCHIP law (format and rules in
// include/afmkit/impact/laws/table_law.hpp).
#include "afmkit/impact/laws/table_law.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <optional>
#include <sstream>
#include <system_error>
#include <utility>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"

namespace afmkit::impact {

namespace {

// ---------------------------------------------------------------------------------------------------------------
// Reading the table
// ---------------------------------------------------------------------------------------------------------------

[[noreturn]] void fail(const std::string& origin, long line, const std::string& message) {
  throw InputError(fmt::format("{}:{}: {}", origin, line, message));
}

/// Whether `s` is well-formed UTF-8 (so that it can be echoed in a message as it is).
bool valid_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t len = 0;
    std::uint32_t cp = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      len = 2, cp = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      len = 3, cp = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      len = 4, cp = c & 0x07;
    } else {
      return false;
    }
    if (i + len > s.size()) return false;
    for (std::size_t k = 1; k < len; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if ((b & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (b & 0x3F);
    }
    if ((len == 2 && cp < 0x80) || (len == 3 && cp < 0x800) || (len == 4 && cp < 0x10000) || cp > 0x10FFFF ||
        (cp >= 0xD800 && cp <= 0xDFFF))
      return false;
    i += len;
  }
  return true;
}

/// A cell or column name for a message: quoted, at most 40 bytes, control bytes (and every byte ≥ 0x80 unless
/// the text is valid UTF-8) written as \xNN.
std::string shown(std::string_view text) {
  constexpr std::size_t limit = 40;
  const bool cut = text.size() > limit;
  if (cut) {
    text = text.substr(0, limit);
    while (!text.empty() && (static_cast<unsigned char>(text.back()) & 0xC0) == 0x80) text.remove_suffix(1);
    if (!text.empty() && static_cast<unsigned char>(text.back()) >= 0xC0) text.remove_suffix(1);
  }
  const bool utf8 = valid_utf8(text);
  std::string out = "'";
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7F || (c >= 0x80 && !utf8))
      out += fmt::format("\\x{:02x}", c);
    else
      out += ch;
  }
  out += cut ? "…'" : "'";
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

/// Trimmed, without enclosing double quotes.
std::string_view clean_cell(std::string_view s) {
  s = trim(s);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = trim(s.substr(1, s.size() - 2));
  return s;
}

enum class Separator { semicolon, comma, tab, blank };

Separator separator_of(std::string_view header) {
  if (header.find(';') != std::string_view::npos) return Separator::semicolon;
  if (header.find(',') != std::string_view::npos) return Separator::comma;
  if (header.find('\t') != std::string_view::npos) return Separator::tab;
  return Separator::blank;
}

std::vector<std::string_view> split(std::string_view line, Separator sep) {
  std::vector<std::string_view> cells;
  if (sep == Separator::blank) {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      if (i > start) cells.push_back(clean_cell(line.substr(start, i - start)));
    }
    return cells;
  }
  const char c = sep == Separator::semicolon ? ';' : sep == Separator::comma ? ',' : '\t';
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = line.find(c, start);
    cells.push_back(clean_cell(line.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start)));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return cells;
}

struct Unit {
  bool length;    // else force
  double factor;  // to nm or nN: value · factor, or value / (1/factor) when factor < 1 (exact for 1e-3 and 0.1)
  double convert(double v) const { return factor < 1.0 ? v / (1.0 / factor) : v * factor; }
};

std::optional<Unit> unit_of(std::string_view u) {
  // µ as U+00B5 (micro sign) or U+03BC (Greek mu); Å as U+00C5 or U+212B (angstrom sign).
  static const std::array<std::pair<std::string_view, Unit>, 18> units{{
      {"nm", {true, 1.0}},
      {"A", {true, 0.1}},
      {"\xC3\x85", {true, 0.1}},
      {"\xE2\x84\xAB", {true, 0.1}},
      {"angstrom", {true, 0.1}},
      {"Angstrom", {true, 0.1}},
      {"um", {true, 1e3}},
      {"\xC2\xB5m", {true, 1e3}},
      {"\xCE\xBCm", {true, 1e3}},
      {"m", {true, 1e9}},
      {"nN", {false, 1.0}},
      {"pN", {false, 1e-3}},
      {"uN", {false, 1e3}},
      {"\xC2\xB5N", {false, 1e3}},
      {"\xCE\xBCN", {false, 1e3}},
      {"N", {false, 1e9}},
      {"nanometer", {true, 1.0}},
      {"nanometre", {true, 1.0}},
  }};
  for (const auto& [name, unit] : units)
    if (u == name) return unit;
  return std::nullopt;
}

constexpr const char* known_units = "length: nm, A, \xC3\x85, angstrom, um, \xC2\xB5m, m; force: nN, pN, uN, \xC2\xB5N, N";

enum class Role { distance, approach_force, retract_force, approach_distance, retract_distance };

struct Column {
  std::string text;  // as written in the header
  Role role;
  Unit unit;
};

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

/// One header column "name (unit)", "name [unit]" or "name_unit".
Column parse_column(std::string_view text, const std::string& origin, long line) {
  text = clean_cell(text);
  if (text.empty()) fail(origin, line, "empty column name in the header");
  std::string_view name, unit_text;
  if (text.back() == ')' || text.back() == ']') {
    const char open = text.back() == ')' ? '(' : '[';
    const std::size_t at = text.rfind(open);
    if (at == std::string_view::npos)
      fail(origin, line, fmt::format("column {}: unbalanced '{}' around the unit", shown(text), text.back()));
    name = trim(text.substr(0, at));
    unit_text = trim(text.substr(at + 1, text.size() - at - 2));
    if (!unit_of(unit_text))
      fail(origin, line, fmt::format("column {}: unknown unit {} (known units: {})", shown(text), shown(unit_text),
                                     known_units));
  } else {
    const std::size_t at = text.rfind('_');
    if (at == std::string_view::npos || !unit_of(text.substr(at + 1)))
      fail(origin, line,
           fmt::format("column {} has no unit: write it as 'name (nm)', 'name [nm]' or 'name_nm' ({})", shown(text),
                       known_units));
    name = text.substr(0, at);
    unit_text = text.substr(at + 1);
  }
  const Unit unit = *unit_of(unit_text);
  // words of the name: runs of ASCII letters and digits, lower case
  const std::string lname = lower(name);
  std::vector<std::string> words;
  std::string word;
  for (char c : lname + " ") {
    if ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')) {
      word += c;
    } else if (!word.empty()) {
      words.push_back(word);
      word.clear();
    }
  }
  bool approach = false, retract = false, says_distance = false, says_force = false;
  for (const std::string& w : words) {
    if (starts_with(w, "approach") || starts_with(w, "exten") || starts_with(w, "trace")) approach = true;
    if (starts_with(w, "retrac") || starts_with(w, "withdraw")) retract = true;
    if (starts_with(w, "distanc") || starts_with(w, "separation") || w == "gap" || w == "z") says_distance = true;
    if (w == "force") says_force = true;
  }
  if (approach && retract)
    fail(origin, line, fmt::format("column {} names both branches (approach and retract)", shown(text)));
  if (unit.length && says_force)
    fail(origin, line, fmt::format("column {} is called a force but its unit {} is a length", shown(text),
                                   shown(unit_text)));
  if (!unit.length && says_distance)
    fail(origin, line, fmt::format("column {} is called a distance but its unit {} is a force", shown(text),
                                   shown(unit_text)));
  Role role;
  if (unit.length) {
    role = approach ? Role::approach_distance : retract ? Role::retract_distance : Role::distance;
  } else {
    if (!approach && !retract)
      fail(origin, line,
           fmt::format("force column {} does not say its branch: its name needs a word starting with approach, "
                       "extend or trace, or with retract, retrace or withdraw",
                       shown(text)));
    role = approach ? Role::approach_force : Role::retract_force;
  }
  return {std::string(text), role, unit};
}

/// Columns of a blank-separated header: each is the words up to and including one that carries its unit
/// (ends with ")" or "]", or has a "_unit" suffix).
std::vector<std::string> blank_header_columns(std::string_view header) {
  std::vector<std::string> columns;
  std::string current;
  for (std::string_view token : split(header, Separator::blank)) {
    if (!current.empty()) current += ' ';
    current += token;
    const std::size_t at = token.rfind('_');
    if (token.back() == ')' || token.back() == ']' || (at != std::string_view::npos && unit_of(token.substr(at + 1)))) {
      columns.push_back(current);
      current.clear();
    }
  }
  if (!current.empty()) columns.push_back(current);  // a name without a unit: parse_column reports it
  return columns;
}

/// A strict decimal number: the whole cell, optional leading '+', no nan/inf, no overflow.
double parse_number(std::string_view cell, const std::string& column, const std::string& origin, long line) {
  std::string_view t = cell;
  if (t.size() > 1 && t.front() == '+' && t[1] != '+' && t[1] != '-') t.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (error != std::errc() || end != t.data() + t.size())
    fail(origin, line, fmt::format("{} is not a number (column {})", shown(cell), shown(column)));
  if (!std::isfinite(value))
    fail(origin, line, fmt::format("{} is not a finite number (column {})", shown(cell), shown(column)));
  return value;
}

/// The points of one branch while reading: order and contiguity checks with line numbers.
struct BranchReader {
  const char* name;  // "approach" / "retract"
  std::vector<double> gap, force;
  std::vector<long> lines;
  int direction = 0;     // +1 ascending, −1 descending, 0 not known yet
  long ended_at = 0;     // the first row after the branch's last point (0: not ended)

  void add(double d, double f, long line, const std::string& origin) {
    if (ended_at != 0)
      fail(origin, line, fmt::format("the {} branch resumes after it ended at line {} (a branch's rows must be "
                                     "contiguous; empty cells only before its first or after its last point)",
                                     name, ended_at));
    if (!gap.empty()) {
      const double last = gap.back();
      if (d == last)
        fail(origin, line, fmt::format("duplicate {} distance {} nm (also at line {})", name, d, lines.back()));
      const int dir = d > last ? 1 : -1;
      if (direction == 0) direction = dir;
      if (dir != direction)
        fail(origin, line, fmt::format("{} distance {} nm breaks the {} order of the branch (previous {} nm at line "
                                       "{}): each branch must be strictly monotone in distance",
                                       name, d, direction > 0 ? "ascending" : "descending", last, lines.back()));
      if (!std::isfinite((f - force.back()) / (d - last)))
        fail(origin, line, fmt::format("{} distance {} nm is too close to {} nm (line {}) for the force change: the "
                                       "slope overflows",
                                       name, d, last, lines.back()));
    }
    gap.push_back(d);
    force.push_back(f);
    lines.push_back(line);
  }
  void none(long line) {
    if (!gap.empty() && ended_at == 0) ended_at = line;
  }
};

}  // namespace

ForceCurve parse_force_curve(std::string_view text, const std::string& origin) {
  if (starts_with(text, "\xEF\xBB\xBF")) text.remove_prefix(3);  // UTF-8 byte-order mark
  std::vector<Column> columns;
  Separator sep = Separator::blank;
  long header_line = 0, line_number = 0;
  bool shared = false;
  int index[5] = {-1, -1, -1, -1, -1};  // column of each Role
  BranchReader approach{"approach", {}, {}, {}}, retract{"retract", {}, {}, {}};
  long rows = 0;

  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t end = text.find('\n', pos);
    std::string_view line = text.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos);
    pos = end == std::string_view::npos ? text.size() + 1 : end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::string_view content = trim(line);
    if (content.empty() || content.front() == '#') continue;

    if (header_line == 0) {  // the header
      header_line = line_number;
      sep = separator_of(content);
      {
        const std::vector<std::string_view> first = split(content, sep);
        const bool numeric = std::all_of(first.begin(), first.end(), [](std::string_view c) {
          double v = 0.0;
          if (!c.empty() && c.front() == '+') c.remove_prefix(1);
          const auto r = std::from_chars(c.data(), c.data() + c.size(), v);
          return !c.empty() && r.ec == std::errc() && r.ptr == c.data() + c.size();
        });
        if (numeric)
          fail(origin, line_number,
               "no header line: the first line holds numbers; expected column names with units first, e.g. "
               "'distance (nm), approach (nN), retract (nN)'");
      }
      std::vector<std::string> names;
      if (sep == Separator::blank) {
        names = blank_header_columns(content);
      } else {
        for (std::string_view cell : split(content, sep)) names.emplace_back(cell);
      }
      for (const std::string& n : names) columns.push_back(parse_column(n, origin, line_number));
      for (std::size_t c = 0; c < columns.size(); ++c) {
        int& slot = index[static_cast<int>(columns[c].role)];
        if (slot >= 0)
          fail(origin, line_number, fmt::format("columns {} and {} have the same role", shown(columns[slot].text),
                                                shown(columns[c].text)));
        slot = static_cast<int>(c);
      }
      const bool has_shared = index[static_cast<int>(Role::distance)] >= 0;
      const bool has_branch_distance = index[static_cast<int>(Role::approach_distance)] >= 0 ||
                                       index[static_cast<int>(Role::retract_distance)] >= 0;
      const char* layouts =
          "expected 'distance (nm), approach (nN), retract (nN)' or 'approach distance (nm), approach force (nN), "
          "retract distance (nm), retract force (nN)'";
      if (has_shared && has_branch_distance)
        fail(origin, line_number, fmt::format("both a shared distance column and per-branch distance columns; {}",
                                              layouts));
      if (!has_shared && !has_branch_distance)
        fail(origin, line_number, fmt::format("no distance column; {}", layouts));
      shared = has_shared;
      for (Role r : {Role::approach_force, Role::retract_force})
        if (index[static_cast<int>(r)] < 0)
          fail(origin, line_number,
               fmt::format("no {} force column (the {} branch is missing); {}",
                           r == Role::approach_force ? "approach" : "retract",
                           r == Role::approach_force ? "approach" : "retract", layouts));
      if (!shared)
        for (Role r : {Role::approach_distance, Role::retract_distance})
          if (index[static_cast<int>(r)] < 0)
            fail(origin, line_number,
                 fmt::format("no {} distance column; {}", r == Role::approach_distance ? "approach" : "retract",
                             layouts));
      continue;
    }

    // a data row
    const std::vector<std::string_view> cells = split(content, sep);
    if (cells.size() > columns.size() || (sep != Separator::blank && cells.size() < columns.size()))
      fail(origin, line_number, fmt::format("{} cells, but the header (line {}) has {} columns", cells.size(),
                                            header_line, columns.size()));
    if (std::all_of(cells.begin(), cells.end(), [](std::string_view c) { return c.empty(); })) continue;
    auto value = [&](Role r) -> std::optional<double> {
      const auto c = static_cast<std::size_t>(index[static_cast<int>(r)]);
      if (c >= cells.size() || cells[c].empty()) return std::nullopt;
      const double v = columns[c].unit.convert(parse_number(cells[c], columns[c].text, origin, line_number));
      if (!std::isfinite(v))
        fail(origin, line_number, fmt::format("{} (column {}) overflows when converted to {}", shown(cells[c]),
                                              shown(columns[c].text),
                                              r == Role::approach_force || r == Role::retract_force ? "nN" : "nm"));
      return v;
    };
    ++rows;
    const std::optional<double> fa = value(Role::approach_force), fb = value(Role::retract_force);
    std::optional<double> da, db;
    if (shared) {
      da = db = value(Role::distance);
      if (!da)
        fail(origin, line_number, fmt::format("the distance cell (column {}) is empty",
                                              shown(columns[static_cast<std::size_t>(index[0])].text)));
      if (!fa && !fb) fail(origin, line_number, "a distance without any force: both force cells are empty");
    } else {
      da = value(Role::approach_distance);
      db = value(Role::retract_distance);
      if (da.has_value() != fa.has_value())
        fail(origin, line_number, fmt::format("the approach {} is given but its {} cell is empty",
                                              da ? "distance" : "force", da ? "force" : "distance"));
      if (db.has_value() != fb.has_value())
        fail(origin, line_number, fmt::format("the retract {} is given but its {} cell is empty",
                                              db ? "distance" : "force", db ? "force" : "distance"));
    }
    if (fa)
      approach.add(*da, *fa, line_number, origin);
    else
      approach.none(line_number);
    if (fb)
      retract.add(*db, *fb, line_number, origin);
    else
      retract.none(line_number);
  }

  if (header_line == 0)
    fail(origin, std::max(line_number, 1L),
         "no header line: expected column names with units, e.g. 'distance (nm), approach (nN), retract (nN)'");
  if (rows == 0) fail(origin, header_line, "no data rows after the header");
  for (BranchReader* b : {&approach, &retract})
    if (b->gap.size() < 4)
      fail(origin, header_line, fmt::format("the {} branch has {} point{}: at least 4 are needed", b->name,
                                            b->gap.size(), b->gap.size() == 1 ? "" : "s"));

  ForceCurve curve;
  curve.origin = origin;
  for (BranchReader* b : {&approach, &retract}) {
    if (b->direction < 0) {
      std::reverse(b->gap.begin(), b->gap.end());
      std::reverse(b->force.begin(), b->force.end());
    }
  }
  curve.approach_gap = std::move(approach.gap);
  curve.approach_force = std::move(approach.force);
  curve.retract_gap = std::move(retract.gap);
  curve.retract_force = std::move(retract.force);
  return curve;
}

ForceCurve read_force_curve(const std::string& path) {
  return parse_force_curve(files::read_input_file(path, "force curve"), path);
}

// ---------------------------------------------------------------------------------------------------------------
// The law
// ---------------------------------------------------------------------------------------------------------------

namespace {
bool opposite_or_zero(double a, double b) { return a == 0 || b == 0 || (a > 0) != (b > 0); }

/// Shape-preserving three-point end slope (Fritsch–Carlson; as in Moler's pchip): h0, d0 at the end interval,
/// h1, d1 at its neighbour.
double end_slope(double h0, double h1, double d0, double d1) {
  double m = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
  if (opposite_or_zero(m, d0)) return 0.0;
  if (opposite_or_zero(d0, d1) && std::abs(m) > std::abs(3.0 * d0)) m = 3.0 * d0;
  return m;
}
}  // namespace

TableLaw::Branch TableLaw::build(const std::vector<double>& x, const std::vector<double>& y, const std::string& what,
                                 const std::string& origin) {
  const std::string where = origin.empty() ? what : fmt::format("{}: {}", origin, what);
  const std::size_t n = x.size();
  if (y.size() != n)
    throw InvalidParameter("force_curve",
                           fmt::format("{}: {} distances but {} forces", where, n, y.size()));
  if (n < 4)
    throw InvalidParameter("force_curve",
                           fmt::format("{}: {} points: at least 4 are needed", where, n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]))
      throw InvalidParameter("force_curve", fmt::format("{}: point {} (distance {} nm, force {} nN) is not finite",
                                                        where, i, x[i], y[i]));
    if (i > 0 && !(x[i] > x[i - 1]))
      throw InvalidParameter("force_curve",
                             fmt::format("{}: distances must be strictly ascending: {} nm follows {} nm", where, x[i],
                                         x[i - 1]));
  }
  std::vector<double> h(n - 1), delta(n - 1), m(n);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    h[i] = x[i + 1] - x[i];
    delta[i] = (y[i + 1] - y[i]) / h[i];
    if (!std::isfinite(h[i]) || !std::isfinite(delta[i]))
      throw InvalidParameter("force_curve",
                             fmt::format("{}: the slope between {} nm and {} nm overflows (distances too close for "
                                         "the forces, or values too large)",
                                         where, x[i], x[i + 1]));
  }
  // Fritsch–Butland slopes: the weighted harmonic mean of the neighbouring secants, 0 at a local extremum.
  for (std::size_t k = 1; k + 1 < n; ++k) {
    if (opposite_or_zero(delta[k - 1], delta[k])) {
      m[k] = 0.0;
    } else {
      const double w1 = 2.0 * h[k] + h[k - 1], w2 = h[k] + 2.0 * h[k - 1];
      m[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k]);
    }
  }
  m[0] = end_slope(h[0], h[1], delta[0], delta[1]);
  m[n - 1] = end_slope(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);

  Branch b;
  b.x = x;
  b.piece.resize(n);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    b.piece[i] = {y[i], m[i], (3.0 * delta[i] - 2.0 * m[i] - m[i + 1]) / h[i],
                  (m[i] + m[i + 1] - 2.0 * delta[i]) / h[i] / h[i]};
  }
  b.piece[n - 1] = {y[n - 1], m[n - 1], 0.0, 0.0};
  b.below_slope = m[0];
  b.inverse_mean_step = static_cast<double>(n - 1) / (x[n - 1] - x[0]);  // may be inf or 0: eval() copes
  b.cumulative.assign(n, 0.0);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const Piece& p = b.piece[i];
    const double t = h[i];
    b.cumulative[i + 1] = b.cumulative[i] + t * (p.y + t * (p.c1 / 2.0 + t * (p.c2 / 3.0 + t * p.c3 / 4.0)));
  }
  if (!std::isfinite(b.cumulative[n - 1]))
    throw InvalidParameter("force_curve", fmt::format("{}: the integral of the branch overflows", where));
  for (std::size_t i = 0; i < n; ++i) {
    const Piece& p = b.piece[i];
    if (!std::isfinite(p.c1) || !std::isfinite(p.c2) || !std::isfinite(p.c3))
      throw InvalidParameter("force_curve",
                             fmt::format("{}: the interpolant at {} nm overflows (distances too close for the forces, "
                                         "or values too large)",
                                         where, x[i]));
  }
  return b;
}

std::size_t TableLaw::Branch::locate(double d) const {
  // binary search for i with x_i ≤ d < x_{i+1}, i ∈ [0, n − 2], given x_0 ≤ d < x_{n−1}
  const double* xs = x.data();
  std::size_t lo = 0, len = x.size() - 1;
  while (len > 1) {
    const std::size_t half = len / 2;
    lo = xs[lo + half] <= d ? lo + half : lo;
    len -= half;
  }
  return lo;
}

double TableLaw::Branch::eval(double d) const {
  const double* xs = x.data();
  const std::size_t n = x.size();
  if (!(d >= xs[0])) {  // below the table (and NaN): the linear continuation
    return piece[0].y + below_slope * (d - xs[0]);
  }
  if (d >= xs[n - 1]) return d > xs[n - 1] ? 0.0 : piece[n - 1].y;
  // the interval i with x_i ≤ d < x_{i+1}, i ∈ [0, n − 2]: first the guess of an evenly spaced table (AFM
  // exports are; then it is exact or one off), else a binary search
  const double guess = (d - xs[0]) * inverse_mean_step;
  std::size_t lo = guess < static_cast<double>(n - 2) ? static_cast<std::size_t>(guess) : n - 2;  // (NaN: n − 2)
  if (xs[lo] > d) {
    if (lo > 0 && xs[lo - 1] <= d) --lo;
    else lo = locate(d);
  } else if (xs[lo + 1] <= d) {
    if (lo + 2 < n && xs[lo + 2] > d) ++lo;
    else lo = locate(d);
  }
  const Piece& p = piece[lo];
  const double t = d - xs[lo];
  return p.y + t * (p.c1 + t * (p.c2 + t * p.c3));
}

double TableLaw::Branch::integral(double d) const {
  const double* xs = x.data();
  const std::size_t n = x.size();
  if (!(d >= xs[0])) {
    const double t = d - xs[0];
    return t * (piece[0].y + 0.5 * below_slope * t);
  }
  if (d >= xs[n - 1]) return cumulative[n - 1];
  const std::size_t i = locate(d);
  const Piece& p = piece[i];
  const double t = d - xs[i];
  return cumulative[i] + t * (p.y + t * (p.c1 / 2.0 + t * (p.c2 / 3.0 + t * p.c3 / 4.0)));
}

double TableLaw::hysteresis_area(double lo, double hi) const {
  return (approach_.integral(hi) - approach_.integral(lo)) - (retract_.integral(hi) - retract_.integral(lo));
}

namespace {
/// The smallest value of the cubic y + t (c1 + t (c2 + t c3)) on [0, len] and where it is taken: the ends and the
/// zeros of its derivative c1 + 2 c2 t + 3 c3 t² inside (exact up to rounding: no sampling).
std::pair<double, double> cubic_minimum(double y, double c1, double c2, double c3, double len) {
  auto value = [&](double t) { return y + t * (c1 + t * (c2 + t * c3)); };
  std::pair<double, double> best{value(0.0), 0.0};
  auto consider = [&](double t) {
    if (!(t > 0.0 && t < len)) return;
    const double v = value(t);
    if (v < best.first) best = {v, t};
  };
  if (len > 0.0) {
    const double end = value(len);
    if (end < best.first) best = {end, len};
  }
  const double a = 3.0 * c3, b = 2.0 * c2, c = c1;
  if (a == 0.0) {
    if (b != 0.0) consider(-c / b);
  } else {
    const double disc = b * b - 4.0 * a * c;
    if (disc >= 0.0) {
      // the stable pair of roots: q = −(b + sign(b)√disc)/2, t = q/a and c/q
      const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
      consider(q / a);
      if (q != 0.0) consider(c / q);
    }
  }
  return best;
}
}  // namespace

TableLaw::TableLaw(ForceCurve curve, bool allow_energy_gain, Hysteresis hysteresis, double release_tolerance)
    : curve_(std::move(curve)),
      allow_gain_(allow_energy_gain),
      approach_(build(curve_.approach_gap, curve_.approach_force, "approach branch", curve_.origin)),
      retract_(build(curve_.retract_gap, curve_.retract_force, "retract branch", curve_.origin)),
      hysteresis_(hysteresis) {
  switching_ = {approach_.x.back(), retract_.x.back()};
  // a retract stiffer at its deepest point than the approach continues below its table with the approach's end
  // slope (table_law.hpp): its kink there is a switching gap
  if (retract_.below_slope < approach_.below_slope) {
    retract_.below_slope = approach_.below_slope;
    switching_.push_back(retract_.x.front());
  }
  if (!(release_tolerance >= 0.0 && std::isfinite(release_tolerance)))
    throw InvalidParameter("release_tolerance", fmt::format("release_tolerance = {} nN must be finite and >= 0",
                                                            release_tolerance));
  double scale = 0.0;
  for (const auto* f : {&curve_.approach_force, &curve_.retract_force})
    for (double v : *f) scale = std::max(scale, std::abs(v));
  difference_end_ = compute_difference_end(release_tolerance > 0.0 ? release_tolerance : 1e-9 * scale);
  release_ = std::max(contact_gap(), difference_end_);
  if (hysteresis_ == Hysteresis::contact) {
    switching_.push_back(contact_gap());
    switching_.push_back(release_);
  }
  std::sort(switching_.begin(), switching_.end());
  switching_.erase(std::unique(switching_.begin(), switching_.end()), switching_.end());
  // regions (between consecutive switching gaps) where H_a and H_b may differ: up to the table's end, or (contact)
  // up to the release gap, above which they are equal
  const double top = hysteresis_ == Hysteresis::contact ? release_ : switching_.back();
  dependent_regions_ = static_cast<int>(std::upper_bound(switching_.begin(), switching_.end(), top) - switching_.begin());
  if (hysteresis_ == Hysteresis::contact) {
    // region r covers [s_{r−1}, s_r): the regions up to and including the one ending at d_r
    dependent_regions_ = static_cast<int>(std::lower_bound(switching_.begin(), switching_.end(), top) - switching_.begin()) + 1;
  }
}

double TableLaw::compute_difference_end(double tolerance) const {
  std::vector<double> knots = approach_.x;
  knots.insert(knots.end(), retract_.x.begin(), retract_.x.end());
  std::sort(knots.begin(), knots.end());
  knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
  // from the top down: the first knot interval (or knot) where |H_a − H_b| exceeds the tolerance; its upper end
  // (beyond the last knot both branches are 0)
  for (std::size_t k = knots.size(); k-- > 0;) {
    const double a = knots[k];
    if (k + 1 < knots.size()) {
      const double b = knots[k + 1];
      const Piece pa = approach_.local(a, b), pb = retract_.local(a, b);
      const double len = b - a;
      const auto [low, t_low] = cubic_minimum(pa.y - pb.y, pa.c1 - pb.c1, pa.c2 - pb.c2, pa.c3 - pb.c3, len);
      const auto [neg_high, t_high] = cubic_minimum(pb.y - pa.y, pb.c1 - pa.c1, pb.c2 - pa.c2, pb.c3 - pa.c3, len);
      (void)t_low, (void)t_high;
      if (low < -tolerance || -neg_high > tolerance) return b;
    }
    if (std::abs(approach_.eval(a) - retract_.eval(a)) > tolerance) return a;
  }
  return -std::numeric_limits<double>::infinity();
}


TableLaw::Piece TableLaw::Branch::local(double a, double b) const {
  const std::size_t n = x.size();
  if (b <= x.front()) {  // the straight-line continuation below the table
    return {piece[0].y + below_slope * (a - x.front()), below_slope, 0.0, 0.0};
  }
  if (a >= x.back()) return {0.0, 0.0, 0.0, 0.0};  // beyond the table
  const std::size_t i = locate(a);                  // (a, b) lies inside [x_i, x_{i+1}]
  const Piece& p = piece[std::min(i, n - 2)];
  const double s = a - x[i];  // the Taylor shift of the piece to the origin a
  return {p.y + s * (p.c1 + s * (p.c2 + s * p.c3)), p.c1 + s * (2.0 * p.c2 + 3.0 * s * p.c3), p.c2 + 3.0 * s * p.c3,
          p.c3};
}

void TableLaw::require_dissipative() const {
  if (allow_gain_) return;
  // H_a(d) ≥ H_b(d) − tolerance for every d, as the law is evaluated: the table's cubics between the knots of
  // either branch, the straight-line continuations below the tables, and 0 beyond each table's end (one branch
  // may end before the other). Between consecutive knots of the union both branches are polynomials of degree
  // ≤ 3, so H_a − H_b is a cubic whose minimum is found exactly (ends and stationary points).
  double scale = 0.0;
  for (const auto* f : {&curve_.approach_force, &curve_.retract_force})
    for (double v : *f) scale = std::max(scale, std::abs(v));
  const double tolerance = 1e-9 * scale;
  const std::string prefix = curve_.origin.empty() ? "" : curve_.origin + ": ";
  const char* remedy =
      "the curve would create energy (H_a >= H_b is needed for a hysteresis law to dissipate; set "
      "allow_energy_gain = true to accept it)";
  const double a_lo = approach_.x.front(), a_hi = approach_.x.back();
  const double b_lo = retract_.x.front(), b_hi = retract_.x.back();
  auto region = [&](double d) -> std::string {
    std::string r;
    if (d < a_lo && d < b_lo) return "below both tables, where both branches continue as straight lines";
    if (d < a_lo) r = "below the approach table, where the approach continues as a straight line";
    if (d < b_lo) r = "below the retract table, where the retract continues as a straight line";
    if (d > a_hi) r = "beyond the end of the approach table, where the approach force is 0";
    if (d > b_hi) r = "beyond the end of the retract table, where the retract force is 0";
    return r.empty() ? "inside both tables" : r;
  };
  auto refuse = [&](double ha, double hb, const std::string& at, double d, double inside) {
    throw InvalidParameter("force_curve", fmt::format("{}the retract force {} nN exceeds the approach force {} nN {} "
                                                      "distance {} nm ({}): {}",
                                                      prefix, hb, ha, at, d, region(inside), remedy));
  };

  std::vector<double> knots = approach_.x;
  knots.insert(knots.end(), retract_.x.begin(), retract_.x.end());
  std::sort(knots.begin(), knots.end());
  knots.erase(std::unique(knots.begin(), knots.end()), knots.end());

  // Below every knot both branches are straight lines and the retract's is never steeper than the approach's (the
  // constructor gives it the approach's slope then): H_a − H_b = g0 + (s_a − s_b)(d − d0) does not fall below its
  // value g0 at the lowest knot, which the loop checks.
  for (std::size_t k = 0; k < knots.size(); ++k) {
    const double a = knots[k];
    {  // the knot itself (at a table's end the branch holds its last value)
      const double ha = approach_.eval(a), hb = retract_.eval(a);
      if (hb > ha + tolerance) refuse(ha, hb, "at", a, a);
    }
    if (k + 1 == knots.size()) break;  // beyond the last knot both branches are 0
    const double b = knots[k + 1];
    const Piece pa = approach_.local(a, b), pb = retract_.local(a, b);
    const auto [least, t] = cubic_minimum(pa.y - pb.y, pa.c1 - pb.c1, pa.c2 - pb.c2, pa.c3 - pb.c3, b - a);
    if (least < -tolerance) {
      const double ha = pa.y + t * (pa.c1 + t * (pa.c2 + t * pa.c3));
      const double hb = pb.y + t * (pb.c1 + t * (pb.c2 + t * pb.c3));
      // at t = 0 the open interval's limit: the force of a branch ending at `a` is 0 just above it
      refuse(ha, hb, t == 0.0 ? "just above" : "at", a + t, a + 0.5 * (b - a));
    }
  }
}

double TableLaw::contact_gap() const {
  const auto& d = curve_.approach_gap;
  const auto& f = curve_.approach_force;
  const auto lowest = std::min_element(f.begin(), f.end());
  if (*lowest < 0) return d[static_cast<std::size_t>(lowest - f.begin())];
  for (std::size_t i = f.size(); i-- > 0;)
    if (f[i] > 0) return d[i];
  return d.front();
}

}  // namespace afmkit::impact
