#include "afmkit/tapping/cantilever_limits.hpp"

#include <cmath>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::tapping {

double check_cantilever_setting(const char* key, CantileverSetting setting, double value) {
  const CantileverLimit limit = cantilever_limit(setting);
  if (value > 0.0 && value <= limit.upper) return value;  // false for NaN
  const std::string unit =
      std::strcmp(limit.si_unit, "dimensionless") == 0 ? std::string() : std::string(" ") + limit.si_unit;
  throw InvalidParameter(key, fmt::format("{} = {}{} is out of range: must be > 0 and <= {:g}{}", key, value, unit,
                                          limit.upper, unit));
}

}  // namespace afmkit::tapping
