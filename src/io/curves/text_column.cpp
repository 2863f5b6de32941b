// One numeric column of a delimited text file (text_column.hpp), through the text-export parser of the curve readers.
#include "afmkit/io/curves/text_column.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "text_table.hpp"

namespace afmkit::io::curves {

namespace {
// A header cell's name: lower case, without a trailing "(unit)" or "[unit]".
std::string header_name(const std::string& cell) {
  std::string s(detail::trim(cell));
  const auto open = s.find_last_of("([");
  if (open != std::string::npos && open > 0 && (s.back() == ')' || s.back() == ']')) s = s.substr(0, open);
  return detail::lower(detail::trim(s));
}
}  // namespace

std::vector<double> read_text_column(const std::string& path, const std::string& column) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot be read (no such file, or no permission)", path));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_text_column(text.str(), path, column);
}

std::vector<double> parse_text_column(const std::string& text, const std::string& path, const std::string& column) {
  const detail::TextTable t = detail::parse_text_table(text, path);
  const std::size_t ncol = t.columns.size();
  std::size_t index = 0;
  const bool by_position = !column.empty() && column.find_first_not_of("0123456789") == std::string::npos;
  if (column.empty()) {
    if (ncol != 1)
      throw InputError(fmt::format("{}: the file has {} columns: choose one by header name or 1-based position",
                                   path, ncol));
  } else if (by_position) {
    // Digits only: a position too long for a number is simply beyond the columns (std::stoul would throw).
    const std::size_t digits = column.find_first_not_of('0');
    const bool beyond = digits != std::string::npos && column.size() - digits > 9;
    const long position = beyond ? 0 : std::stol(column);
    if (beyond || position < 1 || static_cast<std::size_t>(position) > ncol)
      throw InputError(fmt::format("{}: column {} is chosen, but the file has {} column{}", path, column, ncol,
                                   ncol == 1 ? "" : "s"));
    index = static_cast<std::size_t>(position - 1);
  } else {
    const std::string wanted = detail::lower(detail::trim(column));
    std::size_t i = 0;
    while (i < t.header.size() && header_name(t.header[i]) != wanted) ++i;
    if (i == t.header.size())
      throw InputError(t.header.empty() ? fmt::format("{}: column '{}' is chosen by name, but the file has no header "
                                                      "row (choose it by position)", path, column)
                                        : fmt::format("{}: no column named '{}' in the header (line {})", path,
                                                      column, t.header_line));
    index = i;
  }
  const std::vector<double>& values = t.columns.at(index);
  for (std::size_t r = 0; r < values.size(); ++r)
    if (!std::isfinite(values[r]))
      throw InputError(fmt::format("{}, line {}: the cell of column {} is empty or not finite: every sample must be "
                                   "a finite number", path, t.row_line.at(r), index + 1));
  return values;
}

}  // namespace afmkit::io::curves
