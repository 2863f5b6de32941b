#include "tapping_fm_params.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/number_list.hpp"
#include "cantilever_params.hpp"
#include "tapping_params.hpp"

namespace afmkit::cli {

namespace {
/// The shared keys that do not apply to the self-excited cantilever, and why.
const std::vector<std::pair<const char*, const char*>>& keys_not_for_fm() {
  static const std::vector<std::pair<const char*, const char*>> keys{
      {"drive_amplitude", "the drive is set by the amplitude controller: give amplitude"},
      {"free_amplitude", "the drive is set by the amplitude controller: give amplitude"},
      {"frequency_ratio", "the oscillation frequency is set by the phase-locked loop"},
      {"separation", "give separation_min and separation_max, or separations"},
      {"max_period_multiple", "FM orbits have the period of the oscillation"},
      {"max_transient_periods", "FM orbits are found by Newton, without transients"}};
  return keys;
}
}  // namespace

void add_tapping_fm_params(io::ParamSet& p) {
  // refused when given (reject_keys_not_for_fm): never in the records
  for (const auto& [key, why] : keys_not_for_fm()) p.recorded_only_if_given(key);
  p.group("FM-AFM");
  add_cantilever_param(p, CantileverKey::amplitude, CantileverDefault::of(5.0),
                       "oscillation amplitude A held by the amplitude controller (first harmonic of the deflection)",
                       kLengthUnit);
  add_separation_range_params(p, 3.0, 10.0);
  add_separation_points_param(p, 71, 2, 10000000, "separations of the approach (>= 2)");
  add_separation_list_params(p, "explicit separations instead of the uniform grid (any order; run from the largest)");
  p.text("axis", "separation",
            "what separation_min, separation_max and separations set: separation (the rest position l, stepped as an "
            "instrument's piezo) or min_gap (the tip-sample distance at the lower turning point; l is solved for)",
            {"separation", "min_gap"})
      .flag("jumps", true, "where the branch ends in a fold in the separation, follow it through the fold to the branch "
                           "that reaches the next separation (row jumped = 1); --no-jumps: row no_orbit")
      .integer("max_bisections", 6, "where Newton fails from the previous separation, halve the step up to this "
                                    "many times",
               0, 20);
}

void reject_keys_not_for_fm(const io::ParamSet& p) {
  for (const auto& [key, why] : keys_not_for_fm())
    if (p.was_set(key)) throw InvalidParameter(key, fmt::format("{} does not apply to tapping fm: {}", key, why));
}

std::vector<double> fm_separations(const io::ParamSet& p, const units::Unit& length) {
  if (p.was_set("separations") && p.was_set("separations_file"))
    throw InvalidParameter("separations", "give either separations or separations_file, not both");
  std::vector<double> list;
  if (p.was_set("separations") || p.was_set("separations_file")) {
    const char* key = p.was_set("separations") ? "separations" : "separations_file";
    list = p.was_set("separations") ? p.reals("separations")
                                    : io::read_number_list(p.text("separations_file"), "separations_file");
    for (double l : list)
      if (!(std::abs(l) <= 1e6))
        throw InvalidParameter(key, fmt::format("{} contains {}: every separation must be in [-1e+06, 1e+06]", key, l));
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    if (list.empty()) throw InvalidParameter(key, fmt::format("{} holds no separation", key));
  } else {
    const double lo = p.real("separation_min"), hi = p.real("separation_max");
    if (!(lo < hi))
      throw InvalidParameter("separation_min", fmt::format("separation_min = {} is out of range: must be < "
                                                           "separation_max = {}",
                                                           lo, hi));
    const long n = p.integer("points");
    for (long i = 0; i < n; ++i) list.push_back(lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(n - 1));
  }
  for (double& l : list) l = length.internal(l);
  std::sort(list.begin(), list.end(), std::greater<>());
  return list;
}

double fm_amplitude(const io::ParamSet& p, const units::Unit& length) { return length.internal(p.real("amplitude")); }

}  // namespace afmkit::cli
