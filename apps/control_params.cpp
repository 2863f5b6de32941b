#include "control_params.hpp"

#include "afmkit/io/quantity.hpp"

#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/quantity.hpp"

namespace afmkit::cli {

using io::Range;

void add_control_params(io::ParamSet& p, long max_harmonics) {
  p.group("Controller");
  p.text("controller", "bank", "controller: single oscillator (eqs. 5-6), bank of N oscillators (eq. 15), "
                               "infinite bank (eq. 31) or Smith predictor around a bank",
         {"single", "bank", "infinite", "smith"})
      .real("rotation_frequency", 1.0, "rotation angular frequency Omega; rates below are in units of Omega, delays "
                                       "in units of T = 2 pi/Omega", Range{0.0, 1e12, true, false})
      .unit("rad/s")
      .integer("harmonics", 10,
               max_harmonics == kMaxHarmonicsTf
                   ? "number N of oscillators of the bank (eq. 15); cost O(N) per frequency"
                   : "number N of oscillators of the bank (eq. 15); cost O(N) per characteristic evaluation, "
                     "O(N^2) per spectrum / per simulated period",
               1, max_harmonics)
      .real("alpha", 0.1, "coupling alpha of eq. (20)")
      .unit("Omega")
      .real("beta", -0.1, "coupling beta of eq. (20)")
      .unit("Omega")
      .real("a", 0.5, "coupling a of the single oscillator (eq. 5)")
      .unit("Omega")
      .real("b", 0.0, "coupling b of the single oscillator (eq. 5)")
      .unit("Omega")
      .reals("rejected", {1.0}, "harmonic numbers removed from the output (bank controller), e.g. 1,3",
             Range::closed(1, static_cast<double>(max_harmonics)))
      .unit("count")
      .real("gain", 20.0, "controller gain K (design rule K = gamma)", Range{0.0, 1e12, true, false})
      .unit("Omega")
      .default_text("= plant_rate")
      .group("Plant and delay")
      .text("plant", "static", "plant: static y = f + u/gamma (eq. 3) or first order (eq. 1)", {"static", "first_order"})
      .real("plant_rate", 20.0, "plant rate gamma", Range{0.0, 1e12, true, false})
      .unit("Omega")
      .real("delay", 0.1, "measurement delay tau", Range::non_negative())
      .unit("T")
      .group("Smith predictor")
      .text("smith_bank", "bank", "controller inside the Smith predictor", {"bank", "infinite", "single"})
      .text("smith_structure", "periodic", "Smith predictor structure (periodic keeps exact rejection)",
            {"periodic", "classic"})
      .text("model_plant", "same", "kind of the Smith predictor's plant model", {"same", "static", "first_order"})
      .real("model_rate", 20.0, "Smith model rate gamma_hat", Range{0.0, 1e12, true, false})
      .unit("Omega")
      .default_text("= plant_rate")
      .real("model_delay", 0.1, "Smith model delay tau_hat", Range::non_negative())
      .unit("T")
      .default_text("= delay");
}

void require_memory(const std::string& parameter, double value, double bytes_per_unit) {
  memory::require_fits(parameter, value, bytes_per_unit);
}

control::ControlSettings control_settings_from(const io::ParamSet& p) {
  control::ControlSettings c;
  c.controller = control::controller_kind_from(p.text("controller"));
  c.rotation_frequency = p.real("rotation_frequency");
  c.harmonics = static_cast<int>(p.integer("harmonics"));
  c.alpha = p.real("alpha");
  c.beta = p.real("beta");
  c.a = p.real("a");
  c.b = p.real("b");
  c.rejected.clear();
  for (double r : p.reals("rejected")) {
    if (r != std::floor(r))
      throw InvalidParameter("rejected", fmt::format("rejected contains {}: every entry must be an integer "
                                                     "harmonic number in [1, harmonics]", r));
    c.rejected.push_back(static_cast<int>(r));
  }
  if (p.was_set("gain")) c.gain = p.real("gain");
  c.plant = control::plant_kind_from(p.text("plant"));
  c.plant_rate = p.real("plant_rate");
  c.delay = p.real("delay");
  c.smith_bank = control::controller_kind_from(p.text("smith_bank"), "smith_bank");
  c.smith_structure = p.text("smith_structure") == "classic" ? control::SmithPredictor::Structure::Classic
                                                             : control::SmithPredictor::Structure::Periodic;
  if (p.text("model_plant") != "same") c.model_plant = control::plant_kind_from(p.text("model_plant"), "model_plant");
  if (p.was_set("model_rate")) c.model_rate = p.real("model_rate");
  if (p.was_set("model_delay")) c.model_delay = p.real("model_delay");
  c.validate();
  return c;
}

namespace {
nlohmann::json settings_common(const control::ControlSettings& c, double rate, double delay) {
  nlohmann::json j;
  j["controller"] = control::to_string(c.controller);
  j["rotation_frequency"] = c.rotation_frequency;
  j["harmonics"] = c.harmonics;
  j["alpha"] = c.alpha * rate;
  j["beta"] = c.beta * rate;
  j["a"] = c.a * rate;
  j["b"] = c.b * rate;
  j["rejected"] = c.rejected;
  j["gain"] = c.gain_value() * rate;
  j["plant"] = control::to_string(c.plant);
  j["plant_rate"] = c.plant_rate * rate;
  j["delay"] = c.delay * delay;
  if (c.controller == control::ControllerKind::Smith) {
    j["smith_bank"] = control::to_string(c.smith_bank);
    j["smith_structure"] = control::to_string(c.smith_structure);
    j["model_plant"] = control::to_string(c.model_plant_value());
    j["model_rate"] = c.model_rate_value() * rate;
    j["model_delay"] = c.model_delay_value() * delay;
  }
  return j;
}
nlohmann::json settings_units(const control::ControlSettings& c, const char* rate, const char* delay) {
  nlohmann::json u = {{"rotation_frequency", "rad/s"}, {"harmonics", "count"}, {"alpha", rate}, {"beta", rate},
                      {"a", rate}, {"b", rate}, {"rejected", "count"}, {"gain", rate}, {"plant_rate", rate},
                      {"delay", delay}};
  if (c.controller == control::ControllerKind::Smith) {
    u["model_rate"] = rate;
    u["model_delay"] = delay;
  }
  return u;
}
}  // namespace

nlohmann::json settings_json(const control::ControlSettings& c) {
  nlohmann::json j = settings_common(c, 1.0, 1.0);
  j["units"] = settings_units(c, control::RotationUnits::rate_unit, control::RotationUnits::delay_unit);
  return j;
}

nlohmann::json settings_si_json(const control::ControlSettings& c) {
  const control::RotationUnits u = c.units();
  nlohmann::json j = settings_common(c, u.rotation_frequency(), u.period());
  j["period"] = u.period();
  nlohmann::json units = settings_units(c, control::RotationUnits::si_rate_unit, control::RotationUnits::si_delay_unit);
  units["period"] = control::RotationUnits::si_delay_unit;
  j["units"] = units;
  return j;
}

io::ParamSet params_as_run(const io::ParamSet& p, const control::ControlSettings& c,
                           const std::vector<std::pair<std::string, double>>& values) {
  io::ParamSet run = p;
  run.set_from_string("gain", fmt::format("{}", c.gain_value()));
  run.set_from_string("model_rate", fmt::format("{}", c.model_rate_value()));
  run.set_from_string("model_delay", fmt::format("{}", c.model_delay_value()));
  for (const auto& [key, value] : values) run.set_from_string(key, fmt::format("{}", value));
  return run;
}

std::string rate_summary(double rad_per_s, const control::RotationUnits& units, int digits) {
  return io::normalised(units.in_omega(rad_per_s), control::RotationUnits::rate_unit, digits,
                        fmt::format("{:.{}g} rad/s", rad_per_s, digits));
}

std::string delay_summary(double seconds, const control::RotationUnits& units, int digits) {
  return io::normalised(units.in_periods(seconds), control::RotationUnits::delay_unit, digits,
                        io::quantity(seconds, "s", digits));
}

}  // namespace afmkit::cli
