#pragma once
// One numeric column of a delimited text file (the syntax of docs/curve-files.md#text-exports: separator and
// decimal mark detected, comment and metadata lines skipped, an optional header row): a measured signal handed to a
// command as a file (afmkit control simulate --signal-file).
#include <string>
#include <vector>

namespace afmkit::io::curves {

/// The values of column `column` of the text file at `path`: chosen by header name (case-insensitive, without a
/// "(unit)" or "[unit]") or by 1-based position ("2"); `column` empty: the file's only column. InputError naming
/// the file (and the line): unreadable file, no such column, several columns and none chosen, an empty or NaN cell.
std::vector<double> read_text_column(const std::string& path, const std::string& column);

/// The same from the file's bytes `text`; `origin` names it in errors (the file's path).
std::vector<double> parse_text_column(const std::string& text, const std::string& origin, const std::string& column);

}  // namespace afmkit::io::curves
