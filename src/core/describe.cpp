#include "afmkit/core/describe.hpp"

#include <fmt/format.h>

namespace afmkit::detail {

void throw_out_of_range(const char* key, double value, const Range& range) {
  throw InvalidParameter(key, fmt::format("{} = {} is out of range: must be {}", key, value, range.describe()));
}

void throw_out_of_range(const char* key, long value, long lo, long hi) {
  throw InvalidParameter(key, fmt::format("{} = {} is out of range: must be an integer in [{}, {}]", key, value, lo, hi));
}

}  // namespace afmkit::detail
