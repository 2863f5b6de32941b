// Estimated work of a request, refused beyond the work limit (work_budget.hpp).
#include "work_budget.hpp"

#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::cli {

namespace {
/// A duration for a person: seconds, minutes, hours, days or years.
std::string duration(double seconds) {
  if (!std::isfinite(seconds)) return "forever";
  if (seconds < 120.0) return fmt::format("{:.3g} s", seconds);
  if (seconds < 7200.0) return fmt::format("{:.3g} min", seconds / 60.0);
  if (seconds < 172800.0) return fmt::format("{:.3g} h", seconds / 3600.0);
  if (seconds < 3.0e7) return fmt::format("{:.3g} days", seconds / 86400.0);
  return fmt::format("{:.3g} years", seconds / 3.156e7);
}
}  // namespace

double work_limit_seconds() {
  const char* text = std::getenv("AFMKIT_WORK_LIMIT");
  if (!text || !*text) return 3600.0;
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(value > 0) || !std::isfinite(value))
    throw InvalidParameter("AFMKIT_WORK_LIMIT", fmt::format("AFMKIT_WORK_LIMIT = '{}' is out of range: must be a "
                                                            "positive number of seconds",
                                                            text));
  return value;
}

double work_estimate(double value, double seconds_per_unit, double exponent) {
  return seconds_per_unit * std::pow(value, exponent);
}

double require_work(const std::string& parameter, double value, double seconds_per_unit, const std::string& model,
                    double exponent) {
  const double estimate = work_estimate(value, seconds_per_unit, exponent);
  const double limit = work_limit_seconds();
  if (!(estimate <= limit)) {
    const double largest = std::floor(std::pow(limit / seconds_per_unit, 1.0 / exponent));
    throw InvalidParameter(
        parameter,
        fmt::format("{} = {} would take about {} of computing ({}), more than the work limit of {} (AFMKIT_WORK_LIMIT "
                    "seconds changes it): must be <= {:.0f}",
                    parameter, value, duration(estimate), model, duration(limit), largest));
  }
  return estimate;
}

}  // namespace afmkit::cli
