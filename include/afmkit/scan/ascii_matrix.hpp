#pragma once
// A matrix of numbers in a text file (Gwyddion's "ASCII data matrix" export, a spreadsheet's CSV, numpy.savetxt):
// one row of the image per line, values separated by blanks (spaces, tabs) and/or commas; '#' starts a comment
// running to the end of the line; blank and comment-only lines are skipped; CR-LF line ends and a UTF-8 byte-order
// mark are accepted. Values are finite decimal numbers (io::parse_real: "1.5", "-2e-9"; no nan / inf).
// Errors (InputError "<origin>:<line>: …"): a cell that is not a finite number; an empty cell (two commas with
// nothing between, or a comma at the start or end of a row); a row whose length differs from the first row's
// (naming both lengths and the first row's line); no numbers at all ("<origin>: …").
#include <string>
#include <string_view>
#include <vector>

namespace afmkit::scan {

/// Values row by row (row 0 = first data line), `columns` per row.
struct AsciiMatrix {
  long rows = 0;
  long columns = 0;
  std::vector<double> values;  ///< row-major, rows · columns
};

/// The matrix in `text`; `origin` names it in messages.
AsciiMatrix parse_ascii_matrix(std::string_view text, const std::string& origin);
/// The matrix in the file at `path` (at most 512 MiB; InputError when it cannot be read).
AsciiMatrix read_ascii_matrix(const std::string& path);

}  // namespace afmkit::scan
