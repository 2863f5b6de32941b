// Text matrices (format and rules in include/afmkit/scan/ascii_matrix.hpp).
#include "afmkit/scan/ascii_matrix.hpp"

#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/number.hpp"
#include "file_bytes.hpp"

namespace afmkit::scan {

namespace {
constexpr std::uintmax_t ascii_max_file_bytes = std::uintmax_t{512} << 20;
bool blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }
}  // namespace

AsciiMatrix parse_ascii_matrix(std::string_view text, const std::string& origin) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  AsciiMatrix m;
  long first_line = 0;
  long line = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    ++line;
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view row = text.substr(start, end - start);
    start = end + 1;
    if (const std::size_t hash = row.find('#'); hash != std::string_view::npos) row = row.substr(0, hash);
    long count = 0;
    bool cell_expected = false;  // after a comma: a value must follow
    bool any = false;
    std::size_t i = 0;
    while (i < row.size()) {
      const char c = row[i];
      if (blank(c)) {
        ++i;
      } else if (c == ',') {
        if (!any || cell_expected)
          throw InputError(fmt::format("{}:{}: empty cell (a comma with no value before it)", origin, line));
        cell_expected = true;
        ++i;
      } else {
        std::size_t j = i;
        while (j < row.size() && !blank(row[j]) && row[j] != ',') ++j;
        const std::string_view word = row.substr(i, j - i);
        const auto v = io::parse_real(word);
        if (!v || !std::isfinite(*v))
          throw InputError(fmt::format("{}:{}: {} is not a finite number", origin, line, detail::shown(word)));
        m.values.push_back(*v);
        ++count;
        any = true;
        cell_expected = false;
        i = j;
      }
    }
    if (cell_expected) throw InputError(fmt::format("{}:{}: empty cell (the row ends with a comma)", origin, line));
    if (count == 0) continue;
    if (m.rows == 0) {
      m.columns = count;
      first_line = line;
    } else if (count != m.columns) {
      throw InputError(fmt::format("{}:{}: ragged rows: this row has {} value{}, the first row (line {}) has {}", origin,
                                   line, count, count == 1 ? "" : "s", first_line, m.columns));
    }
    ++m.rows;
  }
  if (m.rows == 0) throw InputError(fmt::format("{}: no numbers: an ASCII matrix needs at least one value", origin));
  return m;
}

AsciiMatrix read_ascii_matrix(const std::string& path) {
  return parse_ascii_matrix(detail::read_file_bytes(path, "ASCII matrix", ascii_max_file_bytes), path);
}

}  // namespace afmkit::scan
