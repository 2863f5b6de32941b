#pragma once
// One point of a harmonic-balance branch, with the slope of the separation along the branch
// (seed-1 ext. E1–E6, docs/theory-tapping.md#two-branch-solution). Lower-level than harmonic_balance.hpp: the root
// solver and the fold finder are built on it; it is public for users who trace the curve themselves.
//
// For a penetration parameter q < 1, with M = L(iω)⁻¹ + Ψ(q) and Φ = Φ(q) (eq. 30), the first-harmonic
// balance |MB + Φ| = Γ (eq. 33) is the real quadratic (E1)
//   |M|² B² + 2 Re(MΦ*) B + |Φ|² − Γ² = 0   ->   B± (E2, sign = ±1),
// then A = L(0)[Σ_K Ω̄ B − Σ_F χ̄] (E3), l = qB − A (E4), φ = arg(MB + Φ) (E5).
// Contact points (|q| ≤ 1) are parametrised by the contact angle a = arccos q ∈ [0, π], in which every
// bar function is analytic; permanent-contact points (q ≤ −1) by q itself.
#include <complex>

#include "afmkit/impact/force_law.hpp"
#include "afmkit/tapping/model.hpp"

namespace afmkit::tapping {

/// Model constants entering the balance equations. Throws InvalidParameter("law", …) unless the model's law
/// is piecewise linear.
struct HbCoefficients {
  explicit HbCoefficients(const TappingModel& model);

  std::complex<double> inverse_transfer;  // L(iω)⁻¹ = ω_n² − ω² + 2iξω_nω (eq. 9)
  double static_gain;                      // L(0) = 1/ω_n²
  double drive;                            // Γ
  impact::PiecewiseLinearLaw law;          // K_a, K_b, F_a, F_b (scaled)

  double free_amplitude() const { return drive / std::abs(inverse_transfer); }  // Γ|L(iω)|
  double free_phase() const { return std::arg(inverse_transfer); }               // φ of the free oscillation
};

/// A point of branch B₊ (sign = +1) or B₋ (sign = −1) of (E2).
struct HbBranchEvaluation {
  bool exists = false;   // real root with B > 0
  double q = 0;          // penetration parameter
  double gap = 0;        // 1 − q (kept separately: accurate near grazing)
  double contact_angle = 0;  // a = arccos q for |q| ≤ 1 (π for q ≤ −1)
  double amplitude = 0;  // B
  double offset = 0;     // A
  double separation = 0; // l
  double phase = 0;      // φ (x ≈ A + B cos(ωt − φ) for the drive Γ cos ωt)
  /// dl/da (contact, |q| ≤ 1) or dl/dq (permanent contact, q ≤ −1): the parameter derivative along the branch.
  double parameter_derivative = 0;
  /// dl/dq (infinite where the branch has a vertical tangent in q, e.g. at q = ±1 with F ≠ 0).
  double separation_slope = 0;
};

/// Point at contact angle a ∈ [0, π] (q = cos a). a = 0 is grazing: B₊ is the free oscillation there.
HbBranchEvaluation evaluate_branch_at_angle(const HbCoefficients& c, double contact_angle, int sign);
/// Point at q ≤ −1 (permanent contact).
HbBranchEvaluation evaluate_branch_permanent(const HbCoefficients& c, double q, int sign);
/// Point at gap s = 1 − q > 0 (any q < 1), accurate for s → 0.
HbBranchEvaluation evaluate_branch_at_gap(const HbCoefficients& c, double gap, int sign);

/// Both roots at gap s = 1 − q > 0 from one evaluation of the bar functions; the slopes
/// (parameter_derivative, separation_slope) are computed only when with_slope (else left 0).
struct HbRoots {
  HbBranchEvaluation plus;   // B₊
  HbBranchEvaluation minus;  // B₋
};
HbRoots evaluate_branches_at_gap(const HbCoefficients& c, double gap, bool with_slope = true);

}  // namespace afmkit::tapping
