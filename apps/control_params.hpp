#pragma once
// Shared controller/plant parameters of the `afmkit control …` commands (seed 2, docs/theory-control.md).
//
// Units (nondimensional by default): rotation_frequency Ω is in rad/s (default 1, i.e. time in units of 1/Ω);
// every RATE below (alpha, beta, a, b, gain, plant_rate, model_rate) is given in units of Ω, every DELAY
// (delay, model_delay) in units of the rotation period T = 2π/Ω. Example: alpha = 0.1 means α = 0.1 Ω,
// delay = 0.1 means τ = 0.1 T. Physical run: rotation_frequency = 314.159 (50 Hz), plant_rate = 20 (γ = 20Ω).
//
//   controller      single | bank | infinite | smith          (default bank)
//   harmonics       N of the bank (eq. 15)                      (default 10; range per command: kMaxHarmonics*)
//   alpha, beta     couplings (20) in units of Ω                (default 0.1, −0.1: the "universal" setting)
//   a, b            couplings of the single oscillator (5)      (default 0.5, 0)
//   rejected        harmonics removed from the output (bank)    (default 1; e.g. "1,3")
//   gain            K in units of Ω                             (default: = plant_rate, design rule K = γ̂)
//   plant           static (eq. 3) | first_order (eq. 1)        (default static)
//   plant_rate      γ in units of Ω                             (default 20)
//   delay           τ in units of T                             (default 0.1)
//   smith_bank      bank | infinite | single: controller inside the Smith predictor (default bank)
//   smith_structure periodic | classic                          (default periodic, see smith_predictor.hpp)
//   model_plant     same | static | first_order: kind of the predictor model P̂0 (default same as plant)
//   model_rate      γ̂ in units of Ω                             (default: = plant_rate)
//   model_delay     τ̂ in units of T                             (default: = delay)
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "afmkit/control/loop.hpp"
#include "afmkit/io/params.hpp"

namespace afmkit::cli {

/// The parameters above, resolved to physical units (rad/s, s).
struct ControlSettings {
  std::string controller;          // single | bank | infinite | smith
  double rotation_frequency = 1;   // Ω [rad/s]
  double period = 0;               // T = 2π/Ω [s]
  int harmonics = 10;              // N
  double alpha = 0, beta = 0;      // α, β [rad/s]
  double a = 0, b = 0;             // single-oscillator couplings [rad/s]
  std::vector<int> rejected{1};
  double gain = 0;                 // K [rad/s]
  control::PlantKind plant = control::PlantKind::Static;
  double plant_rate = 0;           // γ [rad/s]
  double delay = 0;                // τ [s]
  std::string smith_bank = "bank";
  control::SmithPredictor::Structure smith_structure = control::SmithPredictor::Structure::Periodic;
  control::PlantKind model_plant = control::PlantKind::Static;
  double model_rate = 0;           // γ̂ [rad/s]
  double model_delay = 0;          // τ̂ [s]

  nlohmann::json to_json() const;  // resolved values (physical units) for sidecars
};

/// Largest `harmonics` of each command (docs/commands.md states the costs behind them):
///   tf: O(N) per frequency (transfer function as a sum over the oscillators);
///   roots, margin, chart, tune: O(N) per characteristic evaluation, O(N) evaluations per spectrum → O(N²);
///   simulate: O(N²) set-up (controller modes), O(N) per step with more than 2N steps per period.
inline constexpr long kMaxHarmonicsTf = 100000;
inline constexpr long kMaxHarmonicsSpectra = 1000;

/// Adds the parameters listed above to `params`; `max_harmonics` bounds `harmonics` (and `rejected`).
void add_control_params(io::ParamSet& params, long max_harmonics = kMaxHarmonicsSpectra);
/// Throws InvalidParameter(parameter, …) when a request of `rows` rows of `bytes_per_row` bytes held in memory
/// does not fit in half of the available memory (MemAvailable), before any work.
void require_memory(const std::string& parameter, double value, double bytes_per_unit);
/// Resolves the parameters (after params.resolve()); throws InvalidParameter naming the parameter.
ControlSettings control_settings_from(const io::ParamSet& params);
/// The controller described by the settings (bank / infinite / single / Smith predictor).
control::Controller control_controller_from(const ControlSettings& settings);
/// The loop described by the parameters.
control::LoopSpec control_loop_from(const io::ParamSet& params);
control::LoopSpec control_loop_from(const ControlSettings& settings);

}  // namespace afmkit::cli
