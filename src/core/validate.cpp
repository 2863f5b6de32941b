#include "afmkit/core/validate.hpp"

#include <fmt/format.h>

#include <string>

#include "afmkit/core/error.hpp"

namespace afmkit::validate {

void fail(std::string_view name, double value, std::string_view requirement) {
  throw InvalidParameter(std::string(name), fmt::format("{} = {} is out of range: must be {}", name, value, requirement));
}

void fail_range(std::string_view name, double value, double lo, double hi) {
  fail(name, value, fmt::format("in [{}, {}]", lo, hi));
}

void fail_range(std::string_view name, long value, long lo, long hi) {
  throw InvalidParameter(std::string(name),
                         fmt::format("{} = {} is out of range: must be an integer in [{}, {}]", name, value, lo, hi));
}

}  // namespace afmkit::validate
