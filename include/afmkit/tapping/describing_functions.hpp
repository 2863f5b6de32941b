#pragma once
// Describing functions of the piecewise-linear hysteresis law (seed-1 eqs. 12–15, 26–31;
// docs/theory-tapping.md#describing-functions) — the closed-form fast path; any other law:
// numerical_describing_functions.hpp (the ForceLaw overloads dispatch).
//
// Ansatz x(t) = A + B cos ωt (B > 0) with penetration parameter q = (A + l)/B (eq. 15):
//   N0·A = ⟨h⟩ = Σ_F χ̄(q) − Σ_K Ω̄(q) B                                   (eq. 29, the mean of h)
//   N1   = Φ(q)/B + Ψ(q),  Φ = −Σ_F Φ̄_R + iΔ_F Φ̄_I,  Ψ = Σ_K Ψ̄_R − iΔ_K Ψ̄_I  (eqs. 29–31)
// with Σ_F = F_a + F_b, Σ_K = K_a + K_b, Δ_F = F_b − F_a, Δ_K = K_b − K_a (eq. 28) and the bar functions
// of seed-1 eq. 28 (docs/theory-tapping.md#describing-functions) extended to every real q (q ≥ 1: no contact,
// |q| < 1: contact on the phase interval (π − a, π + a) with the contact angle a = arccos q, q ≤ −1: permanent contact). N0 alone (= ⟨h⟩/A) is
// never formed: A may be zero.
//
// Accuracy near grazing: for q → 1⁻ the differences in Ω̄ and Ψ̄_R cancel (Ω̄ ≈ a³/6π, Ψ̄_R ≈ a³/3π); they are
// evaluated by series in a, and a itself from the gap s = 1 − q as a = 2 asin(√(s/2)), so every function is
// accurate to a few ulp relative to its own size. Use the *_from_gap / *_from_contact_angle forms when q is
// within ~1e-8 of 1 and 1 − q is known more precisely than q.
#include <complex>

#include "afmkit/impact/force_law.hpp"

namespace afmkit::tapping {

/// The six bar functions of docs/theory-tapping.md#describing-functions (seed-1 eq. 28 abbreviations) at one q, or
/// their derivatives.
struct BarFunctions {
  double chi;    // χ̄
  double omega;  // Ω̄
  double phi_r;  // Φ̄_R
  double phi_i;  // Φ̄_I
  double psi_r;  // Ψ̄_R
  double psi_i;  // Ψ̄_I
};

/// Bar functions at any real q (finite; NaN/inf -> InvalidParameter("q")). Continuous at q = ±1.
BarFunctions bar_functions(double q);
/// Same, from the gap s = 1 − q (accurate for s → 0⁺).
BarFunctions bar_functions_from_gap(double gap);
/// Same, from the contact angle a = arccos q ∈ [0, π] (q = cos a).
BarFunctions bar_functions_from_contact_angle(double angle);
/// d/da of the bar functions at contact angle a ∈ [0, π] (all smooth in a, unlike d/dq at q = ±1).
BarFunctions bar_function_derivatives_in_angle(double angle);
/// Contact range |q| < 1: the bar functions and their d/da at once (one inverse-trigonometric call).
struct ContactBarFunctions {
  double angle;                   // a = arccos q
  double sine;                    // sin a = √(1 − q²)
  BarFunctions value;
  BarFunctions angle_derivative;  // d/da
};
/// From the gap s = 1 − q ∈ (0, 2) (accurate for s → 0⁺).
ContactBarFunctions contact_bar_functions_from_gap(double gap);
/// From the contact angle a ∈ [0, π].
ContactBarFunctions contact_bar_functions_from_angle(double angle);
/// d/dq of the bar functions on the permanent-contact range q ≤ −1.
BarFunctions bar_function_derivatives_permanent_contact();

/// The q-dependent parts of N1 (eq. 30): Φ(q) (offsets F_a, F_b; enters as Φ/B) and Ψ(q) (stiffnesses).
std::complex<double> adhesion_term(const impact::PiecewiseLinearLaw& law, const BarFunctions& bar);    // Φ
std::complex<double> stiffness_term(const impact::PiecewiseLinearLaw& law, const BarFunctions& bar);   // Ψ

/// N0·A and N1 of eq. (12) for the law (26) at penetration parameter q and amplitude B.
struct DescribingFunctions {
  double mean;                         // N0·A = ⟨h⟩ (mean interaction over one period)
  std::complex<double> first_harmonic; // N1
};

/// q finite, amplitude B > 0 (finite) -> else InvalidParameter("q" / "amplitude").
DescribingFunctions describing_functions(const impact::PiecewiseLinearLaw& law, double q, double amplitude);
/// Same for any ForceLaw: the closed forms when law.piecewise_linear() is non-null, else adaptive quadrature
/// (numerical_describing_functions.hpp, mean gap qB). A law with a velocity term (has_damping) needs the drive
/// frequency: InvalidParameter("frequency") here — use the overload with frequency.
DescribingFunctions describing_functions(const impact::ForceLaw& law, double q, double amplitude);
/// Same, from the ansatz x = A + B cos ωt and the separation l: q = (A + l)/B.
DescribingFunctions describing_functions(const impact::ForceLaw& law, double offset, double amplitude,
                                         double separation);
/// Same at drive frequency ω > 0 (enters only through the velocity term of a law with damping).
DescribingFunctions describing_functions(const impact::ForceLaw& law, double offset, double amplitude,
                                         double separation, double frequency);

/// The piecewise-linear coefficients of a ForceLaw, or InvalidParameter("law", …) if it is not piecewise linear.
const impact::PiecewiseLinearLaw& require_piecewise_linear(const impact::ForceLaw& law);

}  // namespace afmkit::tapping
