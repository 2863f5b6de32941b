#pragma once
// The seed-2 loop as the `afmkit control …` commands state it (docs/commands.md#control, docs/units.md): rates in
// units of Ω, delays in units of T = 2π/Ω; and its construction in the library's units (rad/s, s).
//   ControlSettings s;               // defaults: bank N = 10, α = 0.1 Ω, β = −0.1 Ω, γ = K = 20 Ω, τ = 0.1 T
//   s.delay = 0.2;                   // τ = 0.2 T
//   LoopSpec loop = loop_from(s);    // validated; InvalidParameter naming the parameter in the user's units
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "afmkit/control/loop.hpp"
#include "afmkit/control/units.hpp"

namespace afmkit::control {

/// single oscillator (eqs. 5–6), bank of N oscillators (eq. 15), N = ∞ bank (eq. 31), Smith predictor around a bank.
enum class ControllerKind { Single, Bank, Infinite, Smith };
const char* to_string(ControllerKind kind);  ///< "single" | "bank" | "infinite" | "smith"
/// The kind named `name` (as to_string); InvalidParameter(parameter, …) listing the names otherwise.
ControllerKind controller_kind_from(std::string_view name, const std::string& parameter = "controller");
const char* to_string(PlantKind kind);       ///< "static" | "first_order"
PlantKind plant_kind_from(std::string_view name, const std::string& parameter = "plant");
const char* to_string(SmithPredictor::Structure structure);  ///< "periodic" | "classic"

struct ControlSettings {
  ControllerKind controller = ControllerKind::Bank;
  double rotation_frequency = 1.0;     // Ω [rad/s]
  int harmonics = 10;                  // N of the bank (eq. 15)
  double alpha = 0.1, beta = -0.1;     // couplings (20) [Ω]
  double a = 0.5, b = 0.0;             // single-oscillator couplings (5) [Ω]
  std::vector<int> rejected{1};        // harmonics removed from the output (bank); N = ∞: {1} only
  std::optional<double> gain;          // K [Ω]; default = plant_rate (design rule K = γ)
  PlantKind plant = PlantKind::Static; // eq. 3 (static) or eq. 1 (first order)
  double plant_rate = 20.0;            // γ [Ω]
  double delay = 0.1;                  // τ [T]
  ControllerKind smith_bank = ControllerKind::Bank;  // controller inside the Smith predictor (not Smith)
  SmithPredictor::Structure smith_structure = SmithPredictor::Structure::Periodic;
  std::optional<PlantKind> model_plant;  // kind of the predictor model P̂0; default = plant
  std::optional<double> model_rate;      // γ̂ [Ω]; default = plant_rate
  std::optional<double> model_delay;     // τ̂ [T]; default = delay

  RotationUnits units() const { return RotationUnits(rotation_frequency); }  // validates Ω
  double gain_value() const { return gain.value_or(plant_rate); }             // K [Ω]
  PlantKind model_plant_value() const { return model_plant.value_or(plant); }
  double model_rate_value() const { return model_rate.value_or(plant_rate); }  // γ̂ [Ω]
  double model_delay_value() const { return model_delay.value_or(delay); }     // τ̂ [T]
  /// The bank of the loop: `smith_bank` for a Smith predictor, else `controller`.
  ControllerKind bank_kind() const { return controller == ControllerKind::Smith ? smith_bank : controller; }

  /// Throws InvalidParameter naming the parameter and its allowed range (in these units): Ω > 0; N ≥ 1;
  /// couplings finite; K, γ, γ̂ > 0; τ, τ̂ ≥ 0; every value finite in rad/s and s too; rejected non-empty, integers
  /// in [1, N] without repeats ({1} for an N = ∞ bank); smith_bank not smith.
  void validate() const;
};

/// The same loop in the library's units (rad/s for rates, s for delays); defaults resolved.
struct ControlSettingsSi {
  double rotation_frequency, period;  // Ω [rad/s], T [s]
  double alpha, beta, a, b;           // [rad/s]
  double gain, plant_rate, model_rate;  // K, γ, γ̂ [rad/s]
  double delay, model_delay;          // τ, τ̂ [s]
};
ControlSettingsSi to_si(const ControlSettings& settings);  // validated

/// The bank of the settings (bank_kind(): single / bank / infinite), validated.
Bank bank_from(const ControlSettings& settings);
/// The controller (bank, or the Smith predictor around it), validated.
Controller controller_from(const ControlSettings& settings);
/// The loop (controller, plant, delay), validated.
LoopSpec loop_from(const ControlSettings& settings);

}  // namespace afmkit::control
