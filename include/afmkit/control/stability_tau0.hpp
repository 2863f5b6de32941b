#pragma once
// Stability without delay (τ = 0), seed-2 eqs. 13, 22–24, 40–46 (docs/theory-control.md#stability-tau0).
// Static plant (eq. 3) unless a LoopSpec says otherwise; ρ = K/γ.
#include <complex>
#include <vector>

#include "afmkit/control/loop.hpp"
#include "afmkit/control/transfer_function.hpp"

namespace afmkit::control {

/// Eq. (13), one oscillator (eqs. 5–6), τ = 0, static plant: stable ⇔ a > 0 and b < γΩ/K.
bool single_oscillator_stable_tau0(double rotation_frequency, double a, double b, double gain, double plant_rate);

/// Eq. (22): p_N(s) = s P(s) + α P(s) + 2 s (αs + βΩ) Σ_k P(s)/(s² + k²Ω²), P(s) = ∏_{k=1}^N (s² + k²Ω²);
/// monic, degree 2N + 1, built by polynomial products. Its roots are the closed-loop poles for couplings (20),
/// K = γ, τ = 0. Coefficients grow like (N!)²Ω^{2N}: roots are accurate for N ≲ 15.
Polynomial closed_loop_polynomial(int harmonics, double rotation_frequency, double alpha, double beta);
/// General bank, static plant, τ = 0: d(s) + (K/γ) n(s) with C = K n/d of `tf(bank)`; its roots are the
/// eigenvalues of A − (K/γ) b c_rᵀ (x0 left out when a0 = 0).
Polynomial closed_loop_polynomial(const OscillatorBank& bank, double plant_rate);

/// Appendix B necessary conditions for p_N (couplings (20), K = γ, τ = 0).
struct NecessaryConditions {
  double coefficient_2n;             // [s^{2N}] p_N = (2N + 1) α                       (eq. 40)
  double coefficient_1_normalised;   // [s^1] p_N / P(0) = 1 + (2β/Ω) Σ_{k≤N} 1/k²        (eq. 41)
  bool alpha_positive;               // (40): α > 0
  bool coefficient_1_positive;       // (41) > 0 for this N
  bool limit_condition;              // (42): 1 + (π²/3) β/Ω > 0 ⇔ β > −3Ω/π²
};
NecessaryConditions necessary_conditions(int harmonics, double rotation_frequency, double alpha, double beta);

/// Stability border β_c(N) for τ = 0, K = γ, couplings (20): the loop is stable ⇔ α > 0 and β > β_c(N)
/// (independent of α). Crossing at s = iν, ν ∈ (0, Ω): Σ_{|k|≤N} 1/(ν − kΩ) = 0 (Im F_N(iν) = 0, eq. 46 for
/// finite N) and β_c = [Σ_{0<|k|≤N} 1/(k(ν − kΩ))]^{-1} = [Σ_{k=1}^N 2Ω/(ν² − k²Ω²)]^{-1} (Re F_N(iν) = 0).
struct CriticalBeta {
  double beta;                // β_c
  double crossing_frequency;  // ν
};
CriticalBeta critical_beta(int harmonics, double rotation_frequency);
/// N → ∞ (eq. 24, 46): β_c = −Ω/4 at ν = Ω/2.
CriticalBeta critical_beta_limit(double rotation_frequency);

/// α > 0 and β > β_c(N) (K = γ, τ = 0, static plant).
bool couplings_stable_tau0(int harmonics, double rotation_frequency, double alpha, double beta);
/// Eq. (24): α > 0 and β > −Ω/4 (N = ∞, K = γ, τ = 0).
bool infinite_bank_stable_tau0(double rotation_frequency, double alpha, double beta);

/// Eigenvalues of the closed loop with every delay set to 0 (those of closed_loop_dde(loop).undelayed_matrix()):
/// any finite bank / Smith predictor, any K, γ, plant kind. InvalidParameter("controller") for N = ∞.
/// Computed as the roots of the delay-free characteristic polynomial (Aberth–Ehrlich from the first-order
/// positions ikΩ − g_k, eq. 45), O(N) per evaluation and O(N²) in total; dense eigenvalues only as a fallback
/// for N ≤ 50.
std::vector<std::complex<double>> undelayed_poles(const LoopSpec& loop);
/// The Aberth form alone (no fallback); NumericalFailure if it does not converge.
std::vector<std::complex<double>> undelayed_poles_secular(const LoopSpec& loop);
/// max Re of undelayed_poles.
double undelayed_spectral_abscissa(const LoopSpec& loop);

/// Eq. (45): first-order root motion at α = β = 0 (roots s_k = ikΩ, k = −N..N): ds_k = −dα + (i/k) dβ,
/// ds_0 = −dα. Returns (∂s/∂α, ∂s/∂β) for harmonic k.
std::pair<std::complex<double>, std::complex<double>> root_sensitivity_at_origin(int k);

}  // namespace afmkit::control
