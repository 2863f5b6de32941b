#pragma once
// A request's work, estimated from its size options before it starts (docs/development.md#work-and-time): a cost
// model (elementary steps as a product of the size options) times the measured time of one step. A request
// estimated beyond the work limit (1 hour; the environment variable AFMKIT_WORK_LIMIT in seconds changes it) is
// bad input (InvalidParameter, exit 2) naming the option, the estimate, the other options that enter the model and
// the largest value of the option that fits; a run estimated above a few seconds shows progress on stderr.
#include <string>

namespace afmkit::cli {

/// The work limit in seconds: AFMKIT_WORK_LIMIT (a positive number of seconds) if set, else 3600.
/// A malformed value -> InvalidParameter("AFMKIT_WORK_LIMIT").
double work_limit_seconds();

/// Refuses a request whose estimate `seconds_per_unit` · value^exponent (+ `other_seconds`) exceeds the work limit.
/// `model` names the cost model and the other options with their values (e.g. "points x (harmonics + 8) evaluations
/// of an oscillator term, harmonics = 100000"); the message ends with the largest value of `parameter` that fits.
/// Returns the estimate in seconds (for deciding to show progress).
double require_work(const std::string& parameter, double value, double seconds_per_unit, const std::string& model,
                    double exponent = 1.0);
/// The estimate require_work compares with the work limit: seconds_per_unit · value^exponent.
double work_estimate(double value, double seconds_per_unit, double exponent = 1.0);
/// require_work with the cost model's text made only when the request is refused (`model()`: a run within the limit
/// formats no message).
template <class ModelText>
double require_work_with(const std::string& parameter, double value, double seconds_per_unit, ModelText model,
                         double exponent = 1.0) {
  const double estimate = work_estimate(value, seconds_per_unit, exponent);
  if (estimate <= work_limit_seconds()) return estimate;
  return require_work(parameter, value, seconds_per_unit, model(), exponent);  // throws
}

/// Runs estimated above this many seconds show progress on stderr.
inline constexpr double kProgressAfterSeconds = 2.0;

}  // namespace afmkit::cli
