#pragma once
// The table of a delimited text export (docs/curve-files.md#text-exports): the separator and decimal mark
// detected (or given), the comment and metadata lines before the data, the header row, and the numeric columns
// with the line each row came from (for messages). Internal to the io_curves readers.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace afmkit::io::curves::detail {

/// A line of text outside the numeric rows: a comment (its marker '#' or '%' removed) or a metadata line.
struct TextLine {
  int line = 0;              ///< 1-based line number in the file
  std::string text;          ///< trimmed, comment marker removed
  bool comment = false;      ///< began with '#' or '%'
  std::size_t row = 0;       ///< the number of numeric rows before it
};

/// A parsed delimited text table.
struct TextTable {
  char separator = '\t';                 ///< '\t', ';', ',' or ' ' (runs of blanks)
  bool decimal_comma = false;            ///< "1,5" means 1.5
  std::vector<std::string> header;       ///< header cells (empty: no header row)
  int header_line = 0;                   ///< its line (0: none)
  std::vector<std::string> header_units; ///< a row of units under the header row (empty: none)
  std::vector<TextLine> preamble;        ///< comment and metadata lines before the first numeric row
  std::vector<TextLine> interludes;      ///< comment lines and blank lines (text empty) among the numeric rows
  std::vector<std::vector<double>> columns;  ///< columns[c][r]; NaN where a cell is empty or "NaN"
  std::vector<int> row_line;             ///< the line of each row
  std::size_t rows() const { return row_line.size(); }
};

/// How to split: separator 0 = detect; decimal -1 = detect, 0 = point, 1 = comma.
struct TextSyntax {
  char separator = 0;
  int decimal = -1;
};

/// Parses `text`. InputError naming `origin`, the line and the column for a cell that is not a number, a row with
/// more cells than the first, or a file without numeric rows.
TextTable parse_text_table(std::string_view text, const std::string& origin, TextSyntax syntax = {});

/// Splits one line by `separator` (' ' = runs of blanks; a "(unit)" or "[unit]" cell joins the cell before it).
std::vector<std::string_view> split_cells(std::string_view line, char separator);

/// `s` without leading and trailing blanks (space, tab, CR).
std::string_view trim(std::string_view s);

/// `s` in lower case (ASCII letters only: headers, units, extensions).
std::string lower(std::string_view s);

/// Parses one cell: true with the value (NaN for an empty cell or "nan"), false when it is not a number.
bool parse_cell(std::string_view cell, bool decimal_comma, double& value);

}  // namespace afmkit::io::curves::detail
