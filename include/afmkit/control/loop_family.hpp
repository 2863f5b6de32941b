#pragma once
// A two-parameter family of seed-2 loops for stability charts, delay-margin maps and robust tuning: the chart
// coordinates (x, y) are the couplings (a, b) of the single oscillator (eqs. 5–6, Fig. 2) or (α, β) of the
// coupling choice (20) (bank of N oscillators, or N = ∞; Fig. 4). Everything else (gain K, plant, delay,
// rejected harmonics, Smith predictor model) is fixed by the template loop. The characteristic function is affine
// in (x, y) (used by the D-subdivision boundaries).
#include <optional>
#include <string>
#include <vector>

#include "afmkit/control/loop.hpp"

namespace afmkit::control {

struct LoopFamily {
  enum class Kind { SingleOscillator, Bank, Infinite };
  struct SmithModel {
    PlantKind model_kind;
    double model_rate;
    double model_delay;
    SmithPredictor::Structure structure;
  };

  Kind kind = Kind::Bank;
  double rotation_frequency = 1.0;   // Ω
  int harmonics = 10;                // N (Bank)
  std::vector<int> rejected{1};      // rejected harmonics (Bank)
  double gain = 1.0;                 // K
  PlantKind plant_kind = PlantKind::Static;
  double plant_rate = 1.0;           // γ
  double delay = 0.0;                // τ
  std::optional<SmithModel> smith;   // Smith predictor around the bank

  /// The family through `loop`: a single oscillator (N = 1, a0 = 0) gives (a, b); any other finite bank is
  /// replaced by couplings (20) with its N, K and rejected set; the N = ∞ bank gives (α, β).
  static LoopFamily from_loop(const LoopSpec& loop);

  /// The loop at (x, y) [rad/s]; validated by the constructors (InvalidParameter naming the parameter).
  LoopSpec at(double x, double y) const;
  /// The loop at (x, y) with a different delay and gain ratio ρ = K/γ (the plant rate becomes γ = K/ρ).
  LoopSpec at(double x, double y, double delay, double gain_ratio) const;

  const char* x_name() const { return kind == Kind::SingleOscillator ? "a" : "alpha"; }
  const char* y_name() const { return kind == Kind::SingleOscillator ? "b" : "beta"; }
  bool neutral() const { return kind == Kind::Infinite; }
  std::string describe() const;
};

}  // namespace afmkit::control
