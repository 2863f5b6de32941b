#pragma once
// Numbers the library's sources share: "undefined" (a quiet NaN: docs/conventions.md#undefined-values says how files and summaries
// show it), infinity and 2π. Declared once here so that sources take them by a using-declaration, which may repeat
// (the sources of a domain are compiled together in a unity build: docs/development.md#build-time).
#include <limits>
#include <numbers>

namespace afmkit::numbers {

inline constexpr double nan = std::numeric_limits<double>::quiet_NaN();
inline constexpr double infinity = std::numeric_limits<double>::infinity();
inline constexpr double two_pi = 2.0 * std::numbers::pi;

}  // namespace afmkit::numbers
