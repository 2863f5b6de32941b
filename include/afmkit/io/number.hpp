#pragma once
// Parsing numbers written by users (flags, comma lists): the whole text must be one number, nothing else.
//   real:    decimal or scientific ("0.5", "-1e-3", "+2"), or nan / inf (accepted here so that the range check
//            rejects them with the parameter's allowed range); no spaces, no hexadecimal.
//   integer: digits ("1000000"), or a real with an integral value that fits a 64-bit integer ("1e7", "2.0").
#include <optional>
#include <string_view>

namespace afmkit::io {

/// The value of `text`, or nullopt when it is not one number (or overflows a double).
std::optional<double> parse_real(std::string_view text);
/// The value of `text`, or nullopt when it is not an integer representable as a long.
std::optional<long> parse_integer(std::string_view text);

}  // namespace afmkit::io
