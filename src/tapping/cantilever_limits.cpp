#include "afmkit/tapping/cantilever_limits.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::tapping {

namespace {
// Each limit is in an SI unit of the registry, found when compiling (si_unit is constexpr).
constexpr bool cantilever_limit_in_si(CantileverSetting s) {
  const CantileverLimit l = cantilever_limit(s);
  return l.unit.to_si == 1.0 && l.unit.from_si == 1.0 && l.upper > 0.0;
}
static_assert(cantilever_limit_in_si(CantileverSetting::spring_constant));
static_assert(cantilever_limit_in_si(CantileverSetting::resonance_frequency));
static_assert(cantilever_limit_in_si(CantileverSetting::quality_factor));
static_assert(cantilever_limit_in_si(CantileverSetting::amplitude));
}  // namespace

double check_cantilever_setting(const char* key, CantileverSetting setting, double value) {
  const CantileverLimit limit = cantilever_limit(setting);
  if (value > 0.0 && value <= limit.upper) return value;  // false for NaN
  const std::string unit =
      limit.unit.name == "dimensionless" ? std::string() : " " + std::string(limit.unit.name);
  throw InvalidParameter(key, fmt::format("{} = {}{} is out of range: must be > 0 and <= {:g}{}", key, value, unit,
                                          limit.upper, unit));
}

}  // namespace afmkit::tapping
