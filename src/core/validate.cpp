#include "afmkit/core/validate.hpp"

#include <cmath>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::validate {

void require(bool ok, const std::string& name, double value, const std::string& requirement) {
  if (!ok) {
    throw InvalidParameter(name, fmt::format("{} = {} is out of range: must be {}", name, value, requirement));
  }
}

double finite(const std::string& name, double value) {
  require(std::isfinite(value), name, value, "a finite number");
  return value;
}

double positive(const std::string& name, double value) {
  require(std::isfinite(value) && value > 0, name, value, "> 0 and finite");
  return value;
}

double non_negative(const std::string& name, double value) {
  require(std::isfinite(value) && value >= 0, name, value, ">= 0 and finite");
  return value;
}

double in_range(const std::string& name, double value, double lo, double hi) {
  require(std::isfinite(value) && value >= lo && value <= hi, name, value, fmt::format("in [{}, {}]", lo, hi));
  return value;
}

long in_range(const std::string& name, long value, long lo, long hi) {
  if (value < lo || value > hi) {
    throw InvalidParameter(name, fmt::format("{} = {} is out of range: must be an integer in [{}, {}]", name, value, lo, hi));
  }
  return value;
}

}  // namespace afmkit::validate
