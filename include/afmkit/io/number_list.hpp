#pragma once
// A list of numbers written by a user in a text file: numbers separated by commas, spaces, tabs or line breaks;
// `#` starts a comment that runs to the end of the line; empty lines are ignored. Example (separations, nm):
//   # approach curve of 2026-11-23
//   20, 18, 16
//   15.5 15 14.5
#include <string>
#include <string_view>
#include <vector>

namespace afmkit::io {

/// The numbers of `text`. A word that is not a finite number (io::parse_real) raises afmkit::InputError
/// "<origin>:<line>: '<word>' is not a finite number" — `origin` names the file or parameter.
std::vector<double> parse_number_list(std::string_view text, const std::string& origin);
/// The numbers of the file at `path` (InputError naming `parameter` and the path when it cannot be read, is not a
/// regular file, or is larger than 64 MiB).
std::vector<double> read_number_list(const std::string& path, const std::string& parameter);

}  // namespace afmkit::io
