// The fitted parameters of `spectroscopy fit`: names, SI units, valid ranges and the transformations that keep
// them there (docs/fitting.md#bounds); validation of the inputs.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/numbers.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/spectroscopy/fit_model.hpp"
#include "afmkit/tapping/cantilever_limits.hpp"

namespace afmkit::spectroscopy {

namespace {
using afmkit::numbers::infinity;

/// InvalidParameter("distance", …) naming two equal distances.
void require_distinct(const std::vector<double>& distance) {
  std::vector<std::pair<double, std::size_t>> sorted;
  for (std::size_t i = 0; i < distance.size(); ++i) sorted.emplace_back(distance[i], i);
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 1; k < sorted.size(); ++k)
    if (sorted[k].first == sorted[k - 1].first)
      throw InvalidParameter("distance", fmt::format("distance[{}] = distance[{}] = {} m: every distance must be "
                                                     "distinct (average repeated rows first)",
                                                     sorted[k - 1].second, sorted[k].second, sorted[k].first));
}
}  // namespace

double law_unit_to_si(const std::string& unit) {
  if (unit == "nm") return 1e-9;
  if (unit == "GPa") return 1e9;
  if (unit == "nN") return 1e-9;
  return 1.0;  // N/m, J, J/m^2, Pa*s, dimensionless
}

std::string law_si_unit(const std::string& unit) {
  if (unit == "nm") return "m";
  if (unit == "GPa") return "Pa";
  if (unit == "nN") return "N";
  return unit.empty() ? "dimensionless" : unit;
}

const char* transform_name(Transform t) {
  switch (t) {
    case Transform::identity: return "identity";
    case Transform::log: return "log";
    case Transform::logistic: return "logistic";
  }
  return "?";
}

const char* fit_mode_name(FitMode m) { return m == FitMode::fm ? "fm" : "am"; }

const char* fit_status_name(FitStatus s) {
  switch (s) {
    case FitStatus::ok: return "ok";
    case FitStatus::not_converged: return "not_converged";
    case FitStatus::failed: return "failed";
  }
  return "?";
}

void FitCurve::validate() const {
  const std::size_t n = distance.size();
  if (n < 3) throw InvalidParameter("distance", fmt::format("the curve has {} point(s): at least 3 are needed", n));
  if (amplitude.size() != n)
    throw InvalidParameter("amplitude", fmt::format("amplitude has {} values, distance {}: they must be equal",
                                                    amplitude.size(), n));
  if (!phase.empty() && phase.size() != n)
    throw InvalidParameter("phase", fmt::format("phase has {} values, distance {}: they must be equal (or phase "
                                                "empty: amplitude only)",
                                                phase.size(), n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(distance[i]))
      throw InvalidParameter("distance", fmt::format("distance[{}] = {} m is not a finite number", i, distance[i]));
    if (!(std::isfinite(amplitude[i]) && amplitude[i] > 0.0))
      throw InvalidParameter("amplitude", fmt::format("amplitude[{}] = {} m is out of range: must be > 0 and finite",
                                                      i, amplitude[i]));
    if (!phase.empty() && !std::isfinite(phase[i]))
      throw InvalidParameter("phase", fmt::format("phase[{}] = {} rad is not a finite number", i, phase[i]));
  }
  require_distinct(distance);
}

void FmFitCurve::validate() const {
  const std::size_t n = distance.size();
  if (n < 3) throw InvalidParameter("distance", fmt::format("the curve has {} point(s): at least 3 are needed", n));
  if (frequency_shift.size() != n)
    throw InvalidParameter("frequency_shift", fmt::format("frequency_shift has {} values, distance {}: they must be "
                                                          "equal",
                                                          frequency_shift.size(), n));
  if (!dissipation.empty() && dissipation.size() != n)
    throw InvalidParameter("dissipation", fmt::format("dissipation has {} values, distance {}: they must be equal "
                                                      "(or dissipation empty: frequency shift only)",
                                                      dissipation.size(), n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(distance[i]))
      throw InvalidParameter("distance", fmt::format("distance[{}] = {} m is not a finite number", i, distance[i]));
    if (!std::isfinite(frequency_shift[i]))
      throw InvalidParameter("frequency_shift", fmt::format("frequency_shift[{}] = {} Hz is not a finite number", i,
                                                            frequency_shift[i]));
    if (!dissipation.empty() && !std::isfinite(dissipation[i]))
      throw InvalidParameter("dissipation",
                             fmt::format("dissipation[{}] = {} J is not a finite number", i, dissipation[i]));
  }
  require_distinct(distance);
}

// The cantilever's settings: the ranges of tapping/cantilever_limits.hpp (the command line declares the same).
void FmFitSettings::validate() const {
  using tapping::CantileverSetting;
  tapping::check_cantilever_setting("spring_constant", CantileverSetting::spring_constant, spring_constant);
  tapping::check_cantilever_setting("resonance_frequency", CantileverSetting::resonance_frequency, resonance_frequency);
  tapping::check_cantilever_setting("quality_factor", CantileverSetting::quality_factor, quality_factor);
  tapping::check_cantilever_setting("amplitude", CantileverSetting::amplitude, amplitude);
}

void FitSettings::validate() const {
  using tapping::CantileverSetting;
  tapping::check_cantilever_setting("spring_constant", CantileverSetting::spring_constant, spring_constant);
  tapping::check_cantilever_setting("resonance_frequency", CantileverSetting::resonance_frequency, resonance_frequency);
  tapping::check_cantilever_setting("quality_factor", CantileverSetting::quality_factor, quality_factor);
  tapping::check_cantilever_setting("free_amplitude", CantileverSetting::amplitude, free_amplitude);
  // 0: at f0; otherwise a drive frequency, in the resonance frequency's range
  if (drive_frequency != 0.0)
    tapping::check_cantilever_setting("drive_frequency", CantileverSetting::resonance_frequency, drive_frequency);
}

void FitOptions::validate() const {
  validate::non_negative("amplitude_noise", amplitude_noise);
  validate::non_negative("phase_noise", phase_noise);
  validate::non_negative("frequency_shift_noise", frequency_shift_noise);
  validate::non_negative("dissipation_noise", dissipation_noise);
  check_fields(*this);  // the ranges describe() declares
}

bool is_calibration(const std::string& name, FitMode mode) {
  if (name == "distance_offset") return true;
  return mode == FitMode::am ? name == "amplitude_scale" || name == "phase_offset" : name == "frequency_shift_offset";
}

bool is_calibration(const std::string& name) {
  return is_calibration(name, FitMode::am) || is_calibration(name, FitMode::fm);
}

bool residual_only(const std::string& name) { return name == "phase_offset" || name == "frequency_shift_offset"; }

namespace {
const char* calibration_names(FitMode mode) {
  return mode == FitMode::am ? "distance_offset, amplitude_scale, phase_offset"
                             : "distance_offset, frequency_shift_offset";
}
}  // namespace

double calibration_default(const std::string& name) { return name == "amplitude_scale" ? 1.0 : 0.0; }

double calibration_value(const FitOptions& options, const std::string& name) {
  const auto it = options.initial.find(name);
  return it != options.initial.end() ? it->second : calibration_default(name);
}

ModelValues ModelValues::of(const FitOptions& options) {
  ModelValues v;
  v.law = options.law_values;
  v.distance_offset = calibration_value(options, "distance_offset");
  v.amplitude_scale = calibration_value(options, "amplitude_scale");
  v.phase_offset = calibration_value(options, "phase_offset");
  v.frequency_shift_offset = calibration_value(options, "frequency_shift_offset");
  return v;
}

void ModelValues::set(const std::string& name, double p) {
  if (name == "distance_offset") distance_offset = p;
  else if (name == "amplitude_scale") amplitude_scale = p;
  else if (name == "phase_offset") phase_offset = p;
  else if (name == "frequency_shift_offset") frequency_shift_offset = p;
  else law[name] = p;
}

std::vector<FitParameterInfo> fit_parameter_info(const FitOptions& options, FitMode mode) {
  const impact::LawRegistry registry = impact::LawRegistry::builtin();
  const impact::LawSpec& spec = registry.find(options.law);
  if (spec.needs_object)  // its callables are given, not parameters
    throw InvalidParameter("law", fmt::format("law = {} cannot be fitted: the fit adjusts the parameters of a built-in "
                                              "law (docs/force-laws.md), and a law written in Python has none",
                                              options.law));
  if (options.parameters.empty())
    throw InvalidParameter("parameters", fmt::format("no parameter to fit: name at least one (a key of the law, or "
                                                     "of the calibration: {})",
                                                     calibration_names(mode)));
  for (const auto& [key, value] : options.initial) {
    if (is_calibration(key) && !is_calibration(key, mode))
      throw InvalidParameter(key, fmt::format("{} does not apply to an {} curve: its calibration parameters are {}",
                                              key, mode == FitMode::fm ? "FM" : "AM", calibration_names(mode)));
    if (!is_calibration(key) &&
        std::find(options.parameters.begin(), options.parameters.end(), key) == options.parameters.end())
      throw InvalidParameter(key, fmt::format("an initial value is given for {}, which is not fitted: give fixed law "
                                              "values as law parameters, or add {} to the fitted parameters",
                                              key, key));
  }
  std::set<std::string> seen;
  std::vector<FitParameterInfo> out;
  for (const std::string& name : options.parameters) {
    if (!seen.insert(name).second)
      throw InvalidParameter("parameters", fmt::format("parameter '{}' is named twice", name));
    FitParameterInfo p;
    p.name = name;
    if (is_calibration(name) && !is_calibration(name, mode))
      throw InvalidParameter("parameters", fmt::format("'{}' is not a calibration parameter of an {} curve: they are "
                                                       "{}",
                                                       name, mode == FitMode::fm ? "FM" : "AM",
                                                       calibration_names(mode)));
    if (is_calibration(name)) {
      p.initial = calibration_value(options, name);
      // the offsets: unbounded, u = 1 is 1 nm, 1 rad or 1 Hz
      const bool offset = name != "amplitude_scale";
      if (offset) {
        p.lower = -infinity, p.upper = infinity, p.transform = Transform::identity;
        p.unit = name == "distance_offset" ? "m" : name == "phase_offset" ? "rad" : "Hz";
        p.scale = name == "distance_offset" ? 1e-9 : 1.0;
      } else {
        p.unit = "dimensionless", p.lower = 0.0, p.upper = infinity, p.transform = Transform::log;
      }
    } else {
      if (std::find(spec.keys.begin(), spec.keys.end(), name) == spec.keys.end()) {
        const auto users = registry.laws_using(name);
        throw InvalidParameter(
            "parameters",
            users.empty() ? fmt::format("'{}' is not a parameter that can be fitted: law = {} reads {}; the "
                                        "calibration parameters are {}",
                                        name, options.law, fmt::join(spec.keys, ", "), calibration_names(mode))
                          : fmt::format("'{}' is not a parameter of law = {} (it is one of law {}); law = {} reads {}",
                                        name, options.law, fmt::join(users, ", "), options.law,
                                        fmt::join(spec.keys, ", ")));
      }
      const impact::LawKey* key = nullptr;
      for (const auto& k : registry.keys())
        if (k.key == name) key = &k;
      const double f = law_unit_to_si(key->unit);
      p.unit = law_si_unit(key->unit);
      p.lower = key->lower * f;
      p.upper = key->upper * f;
      if (const auto it = options.initial.find(name); it != options.initial.end()) p.initial = it->second;
      else if (const auto lt = options.law_values.find(name); lt != options.law_values.end()) p.initial = lt->second;
      else {
        impact::LawArguments args;
        for (const auto& [k, v] : options.law_values) {
          double unit = 1.0;
          for (const auto& d : registry.keys())
            if (d.key == k) unit = law_unit_to_si(d.unit);
          args.values[k] = v / unit;
        }
        p.initial = args.real(*key, registry.keys()) * f;
      }
      const bool bounded_below = std::isfinite(p.lower), bounded_above = std::isfinite(p.upper);
      p.transform = bounded_below && bounded_above ? Transform::logistic
                    : bounded_below               ? Transform::log
                                                  : Transform::identity;
      if (!bounded_below && bounded_above)  // not among the registry's keys; kept general: a mirrored log
        p.transform = Transform::log;
      p.scale = std::max(std::abs(p.initial), 1e-30);
    }
    if (!std::isfinite(p.initial))
      throw InvalidParameter(name, fmt::format("initial value of {} = {} {} is not a finite number", name, p.initial,
                                               p.unit));
    const bool inside = p.transform == Transform::identity ||
                        (p.initial > p.lower && p.initial < p.upper);
    if (!inside)
      throw InvalidParameter(name, fmt::format("initial value of {} = {} {} is out of range: a fitted {} must be "
                                               "strictly inside ({}, {}) {} (it is fitted on a {} scale)",
                                               name, p.initial, p.unit, name, p.lower, p.upper, p.unit,
                                               transform_name(p.transform)));
    out.push_back(p);
  }
  return out;
}

double to_parameter(const FitParameterInfo& p, double u) {
  switch (p.transform) {
    case Transform::identity: return p.initial + u * p.scale;
    case Transform::log:
      if (std::isfinite(p.lower)) return p.lower + (p.initial - p.lower) * std::exp(u);
      return p.upper - (p.upper - p.initial) * std::exp(-u);
    case Transform::logistic: {
      const double w = p.upper - p.lower;
      const double u0 = std::log((p.initial - p.lower) / (p.upper - p.initial));
      return p.lower + w / (1.0 + std::exp(-(u + u0)));
    }
  }
  return p.initial;
}

double parameter_derivative(const FitParameterInfo& p, double u) {
  switch (p.transform) {
    case Transform::identity: return p.scale;
    case Transform::log:
      if (std::isfinite(p.lower)) return (p.initial - p.lower) * std::exp(u);
      return (p.upper - p.initial) * std::exp(-u);
    case Transform::logistic: {
      const double w = p.upper - p.lower;
      const double u0 = std::log((p.initial - p.lower) / (p.upper - p.initial));
      const double e = std::exp(-(u + u0));
      return w * e / ((1.0 + e) * (1.0 + e));
    }
  }
  return 1.0;
}

}  // namespace afmkit::spectroscopy
