#pragma once
// Validation helpers for value-type constructors: each throws afmkit::InvalidParameter with a message
// "<name> = <value> is out of range: must be <range>". The checks are inline and take the name as a view, so a
// constructor on a hot path (a flow built per integration) pays a comparison, not a string; the message is built
// only on failure (out of line).
#include <cmath>
#include <string_view>

namespace afmkit::validate {

/// Throws InvalidParameter(name, "<name> = <value> is out of range: must be <requirement>").
[[noreturn]] void fail(std::string_view name, double value, std::string_view requirement);
/// Throws the message of in_range (real lo, hi).
[[noreturn]] void fail_range(std::string_view name, double value, double lo, double hi);
/// Throws the message of in_range (integer lo, hi).
[[noreturn]] void fail_range(std::string_view name, long value, long lo, long hi);

/// Throw InvalidParameter(name, "<name> = <value> is out of range: must be <requirement>") if !ok.
inline void require(bool ok, std::string_view name, double value, std::string_view requirement) {
  if (!ok) fail(name, value, requirement);
}
/// value must be a finite number
inline double finite(std::string_view name, double value) {
  if (!std::isfinite(value)) fail(name, value, "a finite number");
  return value;
}
/// value > 0 (and finite)
inline double positive(std::string_view name, double value) {
  if (!(std::isfinite(value) && value > 0)) fail(name, value, "> 0 and finite");
  return value;
}
/// value >= 0 (and finite)
inline double non_negative(std::string_view name, double value) {
  if (!(std::isfinite(value) && value >= 0)) fail(name, value, ">= 0 and finite");
  return value;
}
/// lo <= value <= hi (closed interval; finite)
inline double in_range(std::string_view name, double value, double lo, double hi) {
  if (!(std::isfinite(value) && value >= lo && value <= hi)) fail_range(name, value, lo, hi);
  return value;
}
/// integer lo <= value <= hi
inline long in_range(std::string_view name, long value, long lo, long hi) {
  if (value < lo || value > hi) fail_range(name, value, lo, hi);
  return value;
}

}  // namespace afmkit::validate
