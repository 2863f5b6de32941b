#pragma once
// The N = ∞ controller with couplings (20) (seed-2 eqs. 28–31, docs/theory-control.md#infinite-bank)
// as a ratio of quasi-polynomials
//   C∞(s) = 𝒩(s)(1 − e^{−sT}) / (𝒜(s) − ℬ(s) e^{−sT}),   𝒩(s) = 2K s²(αs + βΩ),   T = 2π/Ω,
// realised in the time domain by the neutral delay-differential equations (32)–(33)
// (docs/theory-control.md#neutral-realisation). Only the first harmonic is rejected in this form.
#include <array>
#include <complex>

namespace afmkit::control {

struct InfiniteBank {
  double rotation_frequency;  // Ω > 0
  double alpha;               // α (finite)
  double beta;                // β (finite)
  double gain;                // K > 0

  InfiniteBank(double rotation_frequency, double alpha, double beta, double gain);  // validated
  double period() const;  // T = 2π/Ω

  /// Coefficients of 𝒜(s) = Σ A_j s^j and ℬ(s) = Σ B_j s^j (j = 0..4), 𝒩(s) = Σ n_j s^j (j = 0..3), table of B.7.
  std::array<double, 5> a_coefficients() const;
  std::array<double, 5> b_coefficients() const;
  std::array<double, 4> n_coefficients() const;
  /// Neutral ratio R = B4/A4 = (Ω − πα)/(Ω + πα); the difference equation is stable iff |R| < 1 ⇔ α > 0.
  double neutral_ratio() const;
};

}  // namespace afmkit::control
