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

double check_cantilever_setting(const char* key, CantileverSetting setting, double value, std::string_view unit) {
  // the upper end in `unit` by the command line's arithmetic (apps/cantilever_params.cpp); in SI: the limit itself
  const double upper = units::from_si(unit)(cantilever_limit(setting).upper);
  if (value > 0.0 && value <= upper) return value;  // false for NaN
  const std::string shown = unit == "dimensionless" ? std::string() : fmt::format(" {}", unit);  // (GCC 12's
  // -Wrestrict false positive on " " + std::string under unity inlining)
  throw InvalidParameter(key, fmt::format("{} = {}{} is out of range: must be > 0 and <= {:g}{}", key, value, shown,
                                          upper, shown));
}

double check_cantilever_setting(const char* key, CantileverSetting setting, double value) {
  return check_cantilever_setting(key, setting, value, cantilever_limit(setting).unit.name);
}

}  // namespace afmkit::tapping
