#include "afmkit/core/range.hpp"

#include <cmath>

#include <fmt/format.h>

namespace afmkit {

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  bool ok_lo = lo_open ? v > lo : v >= lo;
  bool ok_hi = hi_open ? v < hi : v <= hi;
  return ok_lo && ok_hi;
}

std::string Range::describe() const {
  bool has_lo = lo > -1e307, has_hi = hi < 1e307;
  if (has_lo && has_hi) return fmt::format("in {}{:g}, {:g}{}", lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
  if (has_lo) return fmt::format("{} {:g} (finite)", lo_open ? ">" : ">=", lo);
  if (has_hi) return fmt::format("{} {:g} (finite)", hi_open ? "<" : "<=", hi);
  return "a finite number";
}

}  // namespace afmkit
