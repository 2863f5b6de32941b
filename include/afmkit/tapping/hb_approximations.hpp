#pragma once
// Large-stiffness (impulsive-impact) approximations of the harmonic balance, seed-1 eqs. (20)–(25), and the
// minimum separation with an oscillating solution (seed-1 ext. E8), as corrected in
// docs/theory-tapping.md#large-stiffness. Valid for large K_a with e = √(K_b/K_a) fixed and l < Γ|L(iω)|; (25) assumes
// ω = ω_n.
#include <optional>

#include "afmkit/tapping/model.hpp"

namespace afmkit::tapping {

/// Eq. (20): l ≈ B − A (all contact solutions have q ≈ 1). Returns the separation estimate.
double impulsive_separation(double amplitude, double offset);

/// Eq. (21): A_max = Γ L(0), the bound 0 ≤ A ≤ A_max on the offset of contact solutions (|q| < 1; holds for
/// every K_a when ω ≤ ω_n, for large K_a otherwise).
double impulsive_offset_bound(const TappingModel& model);

/// Eq. (22): B ≈ l for l < Γ|L(iω)| (when Γ L(0) ≪ l), else the free amplitude Γ|L(iω)|. Uses model.separation
/// (must be ≥ 0).
double impulsive_amplitude(const TappingModel& model);

/// Eq. (23): sin φ = Im M(q)/|M(q)|, M = L(iω)⁻¹ + N1(q), for the repulsive laws (10), (11) (F_a = F_b = 0,
/// else InvalidParameter("law")). Any finite q.
double repulsive_phase_sine(const TappingModel& model, double q);

/// Eq. (24) (with the factor L(0) restored): l(q) = [q + L(0)(Σ_K/2π)(q arccos q − √(1−q²))] Γ sin φ / Im M(q)
/// for |q| < 1 and the repulsive laws (else InvalidParameter). Identical to l(q) of eq. (18).
double repulsive_separation_from_phase(const TappingModel& model, double q);

/// Eq. (25): l ≈ Γ/(2ξω_n²) sin φ = Γ|L(iω_n)| sin φ (q ≈ 1, ω = ω_n): the separation from the phase lag.
double impulsive_separation_from_phase(const TappingModel& model, double phase);
/// Inverse of eq. (25): φ ≈ arcsin(l / Γ|L(iω_n)|) ∈ [0, π/2] for 0 ≤ l ≤ Γ|L(iω_n)| (model.separation;
/// outside that range -> InvalidParameter("separation")).
double impulsive_phase(const TappingModel& model);

/// Ext. E8, generalised to F_a, F_b and either sign of K_a − K_b: lim_{q→−∞} l(q) on the "+" branch. With
/// κ = 2(K_a − K_b)/π, δ = 2Δ_F/π:  l_∞ = −(1 + L(0)Σ_K/2)(Γ − sgn(κ)δ)/|κ| + L(0)Σ_F/2
/// (F_a = F_b = 0, K_a > K_b: exactly seed-1 ext. E8, the minimum separation with an oscillating solution).
/// −∞ if K_a = K_b and the "+" branch exists for q ≤ −1 (l → −∞); std::nullopt if the "+" branch does not reach q → −∞ (Γ ≤ sgn(κ)δ).
std::optional<double> minimum_separation_limit(const TappingModel& model);

}  // namespace afmkit::tapping
