#pragma once
// The plant of seed 2 (eqs. 1–4): height signal y, plant rate γ, rotation frequency Ω, disturbance f
// (2π-periodic topography + tilt), control u with unit sensitivity, measurement m(t) = y(t − τ).
//   first-order plant (eq. 1):  ẏ = −γ (y − f(Ωt)) + u
//   static plant      (eq. 3):  y = f(Ωt) + u/γ
#include <vector>

namespace afmkit::control {

/// f(θ) = c0 + Σ_k F_k sin(kθ + φ_k) (seed-2 eq. 14); any finite set of harmonics.
struct Disturbance {
  double offset = 0.0;  // c0
  struct Harmonic {
    int order;         // k ≥ 1
    double amplitude;  // F_k ≥ 0
    double phase;      // φ_k [rad]
  };
  std::vector<Harmonic> harmonics;

  Disturbance() = default;
  Disturbance(double offset, std::vector<Harmonic> harmonics);  // validated: finite, k ≥ 1, F_k ≥ 0, unique k
  double operator()(double theta) const;
  /// The paper's Fig. 5 example: c0 = 0.2, F1 = 1, F_k = 0.3/k for k = 2..8, phases drawn from `seed`.
  static Disturbance paper_example(unsigned seed = 1);
};

enum class PlantKind { FirstOrder, Static };

/// The delay may vary slowly in time: τ(t) = delay + delay_variation · sin(delay_variation_frequency · t).
struct Plant {
  PlantKind kind;
  double rate;                            // γ > 0
  double rotation_frequency;              // Ω > 0
  double delay;                           // τ ≥ 0 (τ ≥ T allowed but flagged by `delay_exceeds_period`)
  Disturbance disturbance;
  double delay_variation = 0.0;           // amplitude of slow delay variation (≥ 0, ≤ delay)
  double delay_variation_frequency = 0.0; // rad/s (≥ 0)

  Plant(PlantKind kind, double rate, double rotation_frequency, double delay, Disturbance disturbance,
        double delay_variation = 0.0, double delay_variation_frequency = 0.0);  // validated
  double period() const;  // T = 2π/Ω
  bool delay_exceeds_period() const;  // the paper assumes τ < T
  double delay_at(double t) const;
};

}  // namespace afmkit::control
