#include "control_params.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"

namespace afmkit::cli {

using io::Range;

void add_control_params(io::ParamSet& p, long max_harmonics) {
  p.group("Controller");
  p.text("controller", "bank", "controller: single oscillator (eqs. 5-6), bank of N oscillators (eq. 15), "
                               "infinite bank (eq. 31) or Smith predictor around a bank",
         {"single", "bank", "infinite", "smith"})
      .real("rotation_frequency", 1.0, "rotation angular frequency Omega [rad/s]; rates below are in units of "
                                       "Omega, delays in units of T = 2 pi/Omega", Range{0.0, 1e12, true, false})
      .integer("harmonics", 10,
               max_harmonics == kMaxHarmonicsTf
                   ? "number N of oscillators of the bank (eq. 15); cost O(N) per frequency"
                   : "number N of oscillators of the bank (eq. 15); cost O(N) per characteristic evaluation, "
                     "O(N^2) per spectrum / per simulated period",
               1, max_harmonics)
      .real("alpha", 0.1, "coupling alpha of eq. (20) [units of Omega]")
      .real("beta", -0.1, "coupling beta of eq. (20) [units of Omega]")
      .real("a", 0.5, "coupling a of the single oscillator (eq. 5) [units of Omega]")
      .real("b", 0.0, "coupling b of the single oscillator (eq. 5) [units of Omega]")
      .reals("rejected", {1.0}, "harmonics removed from the output (bank controller), e.g. 1,3",
             Range::closed(1, static_cast<double>(max_harmonics)))
      .real("gain", 20.0, "controller gain K [units of Omega] (design rule K = gamma)", Range{0.0, 1e12, true, false})
      .default_text("= plant_rate")
      .group("Plant and delay")
      .text("plant", "static", "plant: static y = f + u/gamma (eq. 3) or first order (eq. 1)", {"static", "first_order"})
      .real("plant_rate", 20.0, "plant rate gamma [units of Omega]", Range{0.0, 1e12, true, false})
      .real("delay", 0.1, "measurement delay tau [units of T]", Range::non_negative())
      .group("Smith predictor")
      .text("smith_bank", "bank", "controller inside the Smith predictor", {"bank", "infinite", "single"})
      .text("smith_structure", "periodic", "Smith predictor structure (periodic keeps exact rejection)",
            {"periodic", "classic"})
      .text("model_plant", "same", "kind of the Smith predictor's plant model", {"same", "static", "first_order"})
      .real("model_rate", 20.0, "Smith model rate gamma_hat [units of Omega]", Range{0.0, 1e12, true, false})
      .default_text("= plant_rate")
      .real("model_delay", 0.1, "Smith model delay tau_hat [units of T]", Range::non_negative())
      .default_text("= delay");
}

void require_memory(const std::string& parameter, double value, double bytes_per_unit) {
  memory::require_fits(parameter, value, bytes_per_unit);
}

namespace {
control::PlantKind plant_kind(const std::string& s) {
  return s == "first_order" ? control::PlantKind::FirstOrder : control::PlantKind::Static;
}
const char* plant_name(control::PlantKind k) { return k == control::PlantKind::FirstOrder ? "first_order" : "static"; }
}  // namespace

ControlSettings control_settings_from(const io::ParamSet& p) {
  ControlSettings c;
  c.controller = p.text("controller");
  c.rotation_frequency = p.real("rotation_frequency");
  const double w = c.rotation_frequency;
  c.period = 2.0 * std::numbers::pi / w;
  c.harmonics = static_cast<int>(p.integer("harmonics"));
  c.alpha = p.real("alpha") * w;
  c.beta = p.real("beta") * w;
  c.a = p.real("a") * w;
  c.b = p.real("b") * w;
  c.rejected.clear();
  for (double r : p.reals("rejected")) {
    if (r != std::floor(r))
      throw InvalidParameter("rejected", fmt::format("rejected contains {}: every entry must be an integer "
                                                     "harmonic number in [1, harmonics]", r));
    c.rejected.push_back(static_cast<int>(r));
  }
  if (c.rejected.empty()) throw InvalidParameter("rejected", "rejected: the list must not be empty");
  c.plant = plant_kind(p.text("plant"));
  c.plant_rate = p.real("plant_rate") * w;
  c.gain = p.was_set("gain") ? p.real("gain") * w : c.plant_rate;
  c.delay = p.real("delay") * c.period;
  c.smith_bank = p.text("smith_bank");
  c.smith_structure = p.text("smith_structure") == "classic" ? control::SmithPredictor::Structure::Classic
                                                             : control::SmithPredictor::Structure::Periodic;
  c.model_plant = p.text("model_plant") == "same" ? c.plant : plant_kind(p.text("model_plant"));
  c.model_rate = p.was_set("model_rate") ? p.real("model_rate") * w : c.plant_rate;
  c.model_delay = p.was_set("model_delay") ? p.real("model_delay") * c.period : c.delay;
  return c;
}

nlohmann::json ControlSettings::to_json() const {
  nlohmann::json j;
  j["controller"] = controller;
  j["rotation_frequency"] = rotation_frequency;
  j["period"] = period;
  j["harmonics"] = harmonics;
  j["alpha"] = alpha;
  j["beta"] = beta;
  j["a"] = a;
  j["b"] = b;
  j["rejected"] = rejected;
  j["gain"] = gain;
  j["plant"] = plant_name(plant);
  j["plant_rate"] = plant_rate;
  j["delay"] = delay;
  if (controller == "smith") {
    j["smith_bank"] = smith_bank;
    j["smith_structure"] = smith_structure == control::SmithPredictor::Structure::Classic ? "classic" : "periodic";
    j["model_plant"] = plant_name(model_plant);
    j["model_rate"] = model_rate;
    j["model_delay"] = model_delay;
  }
  j["units"] = "rad/s for rates and frequencies, s for delays";
  return j;
}

namespace {
control::Bank bank_from(const ControlSettings& c, const std::string& kind) {
  if (kind == "single") return control::OscillatorBank::single(c.rotation_frequency, c.a, c.b, c.gain);
  if (kind == "infinite") {
    if (c.rejected.size() != 1 || c.rejected[0] != 1)
      throw InvalidParameter("rejected", "rejected: the infinite bank (eq. 31) rejects only harmonic 1");
    return control::InfiniteBank(c.rotation_frequency, c.alpha, c.beta, c.gain);
  }
  return control::OscillatorBank::with_couplings(c.rotation_frequency, c.harmonics, c.alpha, c.beta, c.gain,
                                                 c.rejected);
}
}  // namespace

control::Controller control_controller_from(const ControlSettings& c) {
  if (c.controller == "smith") {
    return control::SmithPredictor(bank_from(c, c.smith_bank), c.model_plant, c.model_rate, c.model_delay,
                                   c.smith_structure);
  }
  control::Bank bank = bank_from(c, c.controller);
  return std::visit([](auto&& x) -> control::Controller { return x; }, std::move(bank));
}

control::LoopSpec control_loop_from(const ControlSettings& c) {
  return control::LoopSpec(control_controller_from(c), c.plant, c.plant_rate, c.delay);
}

control::LoopSpec control_loop_from(const io::ParamSet& p) { return control_loop_from(control_settings_from(p)); }

}  // namespace afmkit::cli
