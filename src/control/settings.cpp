// The control loop from user-facing settings (settings.hpp): validation in the user's units, conversion to rad/s
// and s, construction of the bank, controller and loop.
#include "afmkit/control/settings.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

const char* to_string(ControllerKind kind) {
  switch (kind) {
    case ControllerKind::Single: return "single";
    case ControllerKind::Infinite: return "infinite";
    case ControllerKind::Smith: return "smith";
    default: return "bank";
  }
}

ControllerKind controller_kind_from(std::string_view name, const std::string& parameter) {
  for (ControllerKind k : {ControllerKind::Single, ControllerKind::Bank, ControllerKind::Infinite, ControllerKind::Smith})
    if (name == to_string(k)) return k;
  throw InvalidParameter(parameter, fmt::format("{} = '{}' is not a controller: must be one of single, bank, "
                                                "infinite, smith", parameter, name));
}

const char* to_string(PlantKind kind) { return kind == PlantKind::FirstOrder ? "first_order" : "static"; }

PlantKind plant_kind_from(std::string_view name, const std::string& parameter) {
  if (name == "static") return PlantKind::Static;
  if (name == "first_order") return PlantKind::FirstOrder;
  throw InvalidParameter(parameter, fmt::format("{} = '{}' is not a plant: must be one of static, first_order",
                                                parameter, name));
}

const char* to_string(SmithPredictor::Structure s) {
  return s == SmithPredictor::Structure::Classic ? "classic" : "periodic";
}

namespace {
// `value` in the user's unit is finite and stays finite once multiplied by `scale` (to rad/s or s).
void finite_scaled(const std::string& name, double value, double scale, const char* unit) {
  validate::finite(name, value);
  const double limit = std::numeric_limits<double>::max() / scale;
  validate::require(std::abs(value) <= limit, name, value,
                    fmt::format("at most {:.6g} in magnitude (units of {}: the value in {} must be finite)", limit,
                                unit, unit[0] == 'T' ? "s" : "rad/s"));
}
}  // namespace

void ControlSettings::validate() const {
  const RotationUnits u = units();
  validate::in_range("harmonics", static_cast<long>(harmonics), 1L, static_cast<long>(std::numeric_limits<int>::max()));
  for (const auto& [name, value] : {std::pair{"alpha", alpha}, std::pair{"beta", beta}, std::pair{"a", a},
                                    std::pair{"b", b}})
    finite_scaled(name, value, u.rotation_frequency(), "Omega");
  for (const auto& [name, value] : {std::pair{"plant_rate", plant_rate}, std::pair{"gain", gain_value()},
                                    std::pair{"model_rate", model_rate_value()}}) {
    validate::positive(name, value);
    finite_scaled(name, value, u.rotation_frequency(), "Omega");
  }
  for (const auto& [name, value] : {std::pair{"delay", delay}, std::pair{"model_delay", model_delay_value()}}) {
    validate::non_negative(name, value);
    finite_scaled(name, value, u.period(), "T");
  }
  if (smith_bank == ControllerKind::Smith)
    throw InvalidParameter("smith_bank", "smith_bank = smith is out of range: must be bank, infinite or single");
  if (rejected.empty()) throw InvalidParameter("rejected", "rejected: the list must not be empty");
  const ControllerKind bank = bank_kind();
  if (bank == ControllerKind::Infinite && (rejected.size() != 1 || rejected[0] != 1))
    throw InvalidParameter("rejected", "rejected: the infinite bank (eq. 31) rejects only harmonic 1 (must be 1)");
  if (bank == ControllerKind::Bank) {
    for (std::size_t i = 0; i < rejected.size(); ++i) {
      validate::in_range("rejected", static_cast<long>(rejected[i]), 1L, static_cast<long>(harmonics));
      if (std::find(rejected.begin(), rejected.begin() + static_cast<long>(i), rejected[i]) != rejected.begin() + static_cast<long>(i))
        throw InvalidParameter("rejected", fmt::format("rejected: harmonic {} listed twice", rejected[i]));
    }
  }
}

ControlSettingsSi to_si(const ControlSettings& s) {
  s.validate();
  const RotationUnits u = s.units();
  return {u.rotation_frequency(), u.period(), u.rate(s.alpha), u.rate(s.beta), u.rate(s.a), u.rate(s.b),
          u.rate(s.gain_value()), u.rate(s.plant_rate), u.rate(s.model_rate_value()), u.delay(s.delay),
          u.delay(s.model_delay_value())};
}

Bank bank_from(const ControlSettings& s) {
  const ControlSettingsSi si = to_si(s);
  switch (s.bank_kind()) {
    case ControllerKind::Single: return OscillatorBank::single(si.rotation_frequency, si.a, si.b, si.gain);
    case ControllerKind::Infinite: return InfiniteBank(si.rotation_frequency, si.alpha, si.beta, si.gain);
    default:
      return OscillatorBank::with_couplings(si.rotation_frequency, s.harmonics, si.alpha, si.beta, si.gain,
                                            s.rejected);
  }
}

Controller controller_from(const ControlSettings& s) {
  Bank bank = bank_from(s);
  if (s.controller == ControllerKind::Smith) {
    const ControlSettingsSi si = to_si(s);
    return SmithPredictor(std::move(bank), s.model_plant_value(), si.model_rate, si.model_delay, s.smith_structure);
  }
  return std::visit([](auto&& x) -> Controller { return std::move(x); }, std::move(bank));
}

LoopSpec loop_from(const ControlSettings& s) {
  const ControlSettingsSi si = to_si(s);
  return LoopSpec(controller_from(s), s.plant, si.plant_rate, si.delay);
}

}  // namespace afmkit::control
