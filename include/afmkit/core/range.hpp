#pragma once
// Range: the allowed values of a number, [lo, hi] with either end open. One type for the library's option
// descriptions (core/describe.hpp) and the command line's parameters (io::ParamSet, which names it io::Range), so
// that a range is declared once and checked by both.
#include <string>

namespace afmkit {

/// Allowed range of a numeric parameter.
struct Range {
  double lo = -1e308;
  double hi = 1e308;
  bool lo_open = false;  // true: value > lo, false: value >= lo
  bool hi_open = false;
  static constexpr Range positive() { return {0.0, 1e308, true, false}; }
  static constexpr Range non_negative() { return {0.0, 1e308, false, false}; }
  static constexpr Range any() { return {}; }
  static constexpr Range closed(double a, double b) { return {a, b, false, false}; }
  static constexpr Range open(double a, double b) { return {a, b, true, true}; }
  /// In words, as messages and --help give it: "in (0, 1)", "> 0 (finite)", "a finite number".
  std::string describe() const;
  /// Finite and inside the range.
  bool contains(double v) const;
};

}  // namespace afmkit
