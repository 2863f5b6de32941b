#include "text_table.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "units.hpp"

namespace afmkit::io::curves::detail {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

bool is_comment(std::string_view trimmed) {
  return !trimmed.empty() && (trimmed.front() == '#' || trimmed.front() == '%');
}

std::string_view strip_comment_marker(std::string_view trimmed) {
  while (!trimmed.empty() && (trimmed.front() == '#' || trimmed.front() == '%')) trimmed.remove_prefix(1);
  return trim(trimmed);
}

// Every cell of `cells` is a number (empty cells allowed but not all).
bool all_numeric(const std::vector<std::string_view>& cells, bool decimal_comma) {
  bool any = false;
  for (std::string_view c : cells) {
    double v;
    if (!parse_cell(c, decimal_comma, v)) return false;
    any = any || !trim(c).empty();
  }
  return any;
}

// The separator and decimal mark of a line that should be numeric; false when no choice makes it numeric.
bool detect_syntax(std::string_view line, TextSyntax given, char& separator, bool& decimal_comma) {
  const char candidates[] = {'\t', ';', ',', ' '};
  for (char sep : candidates) {
    if (given.separator != 0 && sep != given.separator) continue;
    if (given.separator == 0 && sep != ' ' && line.find(sep) == std::string_view::npos) continue;
    const auto cells = split_cells(line, sep);
    for (int dc = 0; dc < 2; ++dc) {
      if (given.decimal >= 0 && dc != given.decimal) continue;
      if (dc == 1 && sep == ',') continue;  // a comma cannot be both
      if (all_numeric(cells, dc == 1)) {
        separator = sep;
        decimal_comma = dc == 1;
        return true;
      }
    }
  }
  return false;
}

}  // namespace

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split_cells(std::string_view line, char separator) {
  std::vector<std::string_view> cells;
  if (separator != ' ') {
    // Trailing separators are empty cells (a retract shorter than the approach), so only the line's own blanks
    // other than the separator are trimmed.
    while (!line.empty() && line.back() != separator && is_blank(line.back())) line.remove_suffix(1);
    while (!line.empty() && line.front() != separator && is_blank(line.front())) line.remove_prefix(1);
    std::size_t start = 0;
    while (true) {
      const std::size_t at = line.find(separator, start);
      cells.push_back(trim(line.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start)));
      if (at == std::string_view::npos) break;
      start = at + 1;
    }
    return cells;
  }
  line = trim(line);
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i >= line.size()) break;
    std::size_t j = i;
    while (j < line.size() && !is_blank(line[j])) ++j;
    const std::string_view token = line.substr(i, j - i);
    if (!cells.empty() && (token.front() == '(' || token.front() == '[')) {
      // "Height (nm)": the unit belongs to the name before it.
      const char* begin = cells.back().data();
      cells.back() = std::string_view(begin, static_cast<std::size_t>(token.data() + token.size() - begin));
    } else {
      cells.push_back(token);
    }
    i = j;
  }
  return cells;
}

bool parse_cell(std::string_view cell, bool decimal_comma, double& value) {
  cell = trim(cell);
  if (cell.empty()) {
    value = kNaN;
    return true;
  }
  if (cell.front() == '+') cell.remove_prefix(1);
  if (cell.empty() || cell.front() == '+') return false;
  char buffer[256];
  const char* begin = cell.data();
  if (decimal_comma) {
    if (cell.size() >= sizeof buffer) return false;
    std::size_t n = 0;
    for (char c : cell) {
      if (c == '.') return false;  // a point in a decimal-comma file is not part of a number
      buffer[n++] = c == ',' ? '.' : c;
    }
    begin = buffer;
  } else if (cell.find(',') != std::string_view::npos) {
    return false;
  }
  const char* end = begin + cell.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value, std::chars_format::general);
  if (ptr != end) return false;
  if (ec == std::errc::result_out_of_range) return false;
  if (ec != std::errc()) return false;
  if (std::isnan(value)) value = kNaN;  // "-nan" too
  return true;
}

TextTable parse_text_table(std::string_view text, const std::string& origin, TextSyntax syntax) {
  TextTable table;
  // Skip a UTF-8 byte-order mark.
  if (text.size() >= 3 && text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  if (const auto nul = text.substr(0, 65536).find('\0'); nul != std::string_view::npos)
    throw InputError(fmt::format("{}: byte {}: a NUL byte: not a text export (a binary file? its format may be "
                                 "jpk-force or ibw)",
                                 origin, nul));
  std::vector<std::string_view> lines;
  {
    std::size_t start = 0;
    while (start <= text.size()) {
      std::size_t at = text.find('\n', start);
      if (at == std::string_view::npos) at = text.size();
      lines.push_back(text.substr(start, at - start));
      start = at + 1;
    }
  }
  // The first numeric row: a line that splits into numbers and is followed by another such line (or ends the
  // data), so that a lone number in a metadata block is not taken for data.
  std::size_t first = lines.size();
  std::vector<TextLine> pending;  // non-numeric lines before the data
  std::vector<std::string_view> pending_raw;  // the last non-comment ones, untrimmed
  for (std::size_t i = 0; i < lines.size() && first == lines.size(); ++i) {
    const std::string_view t = trim(lines[i]);
    if (t.empty()) continue;
    if (is_comment(t)) {
      pending.push_back({static_cast<int>(i + 1), std::string(strip_comment_marker(t)), true, 0});
      continue;
    }
    char sep = 0;
    bool dc = false;
    if (detect_syntax(lines[i], syntax, sep, dc)) {
      // Confirm with the next non-blank, non-comment line.
      std::size_t k = i + 1;
      while (k < lines.size() && (trim(lines[k]).empty() || is_comment(trim(lines[k])))) ++k;
      bool confirmed = k >= lines.size();
      if (!confirmed) {
        confirmed = all_numeric(split_cells(lines[k], sep), dc);  // its count is checked as data
      }
      if (confirmed) {
        first = i;
        table.separator = sep;
        table.decimal_comma = dc;
        break;
      }
    }
    pending.push_back({static_cast<int>(i + 1), std::string(t), false, 0});
    pending_raw.push_back(lines[i]);
  }
  if (first == lines.size())
    throw InputError(fmt::format("{}: no rows of numbers found (a text export needs lines of numbers separated by "
                                 "tabs, ';', ',' or blanks)",
                                 origin));
  const std::size_t ncol = split_cells(lines[first], table.separator).size();
  // The header row: the last non-comment line before the data, when it has as many cells as the data (trailing
  // empty cells of the header, or one trailing empty column of the data, do not count: decided after the rows).
  std::vector<std::string_view> header;
  int header_line = 0;
  if (!pending.empty() && !pending.back().comment) {
    header = split_cells(pending_raw.back(), table.separator);
    while (header.size() > ncol && header.back().empty()) header.pop_back();
    if (header.size() == ncol || header.size() + 1 == ncol) {
      header_line = pending.back().line;
      pending.pop_back();
      pending_raw.pop_back();
    } else {
      header.clear();
    }
  }
  table.columns.assign(ncol, {});
  for (auto& c : table.columns) c.reserve(lines.size() - first);
  table.row_line.reserve(lines.size() - first);
  std::vector<std::string_view> cells;
  for (std::size_t i = first; i < lines.size(); ++i) {
    const std::string_view t = trim(lines[i]);
    const int line_no = static_cast<int>(i + 1);
    if (t.empty() || is_comment(t)) {
      table.interludes.push_back(
          {line_no, t.empty() ? std::string() : std::string(strip_comment_marker(t)), !t.empty(), table.rows()});
      continue;
    }
    cells = split_cells(lines[i], table.separator);
    if (cells.size() > ncol)
      throw InputError(fmt::format("{}: line {}: {} columns, but the data begin (line {}) with {}", origin, line_no,
                                   cells.size(), first + 1, ncol));
    for (std::size_t c = 0; c < ncol; ++c) {
      double v = kNaN;
      if (c < cells.size() && !parse_cell(cells[c], table.decimal_comma, v)) {
        const std::string_view shown = cells[c].substr(0, 40);
        throw InputError(fmt::format("{}: line {}, column {}: '{}' is not a number{}", origin, line_no, c + 1, shown,
                                     table.decimal_comma ? " (decimal comma expected, as in the first data line)"
                                                         : ""));
      }
      if (std::isinf(v))
        throw InputError(fmt::format("{}: line {}, column {}: '{}' is not a finite number", origin, line_no, c + 1,
                                     cells[c].substr(0, 40)));
      table.columns[c].push_back(v);
    }
    table.row_line.push_back(line_no);
  }
  if (header_line > 0 && header.size() + 1 == ncol) {
    // "a<TAB>b" over rows "1<TAB>2<TAB>": the data's last column is the rows' trailing separator when it is empty.
    bool empty = true;
    for (double v : table.columns.back()) empty = empty && std::isnan(v);
    if (empty) {
      table.columns.pop_back();
    } else {
      pending.push_back({header_line, std::string(trim(lines[static_cast<std::size_t>(header_line - 1)])), false, 0});
      header.clear();
      header_line = 0;
    }
  }
  if (header_line > 0) {
    // A row of units under the row of names ("Height<TAB>Defl" then "nm<TAB>V"): every cell a unit.
    bool units = !header.empty();
    for (std::string_view c : header) {
      std::string_view u = trim(c);
      if (u.size() >= 2 && (u.front() == '(' || u.front() == '[')) u = trim(u.substr(1, u.size() - 2));
      units = units && parse_unit(u).has_value();
    }
    if (units && !pending.empty() && !pending.back().comment && pending.back().line == header_line - 1) {
      auto names = split_cells(pending_raw.back(), table.separator);
      while (names.size() > header.size() && names.back().empty()) names.pop_back();
      if (names.size() == header.size()) {
        for (std::string_view c : header) {
          std::string_view u = trim(c);
          if (u.size() >= 2 && (u.front() == '(' || u.front() == '[')) u = trim(u.substr(1, u.size() - 2));
          table.header_units.emplace_back(u);
        }
        header = names;
        header_line = pending.back().line;
        pending.pop_back();
        pending_raw.pop_back();
      }
    }
    for (std::string_view c : header) table.header.emplace_back(c);
    table.header_line = header_line;
  }
  table.preamble = std::move(pending);
  return table;
}

}  // namespace afmkit::io::curves::detail
