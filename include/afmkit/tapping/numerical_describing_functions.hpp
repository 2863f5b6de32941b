#pragma once
// Describing functions of ANY force law (impact::ForceLaw) by adaptive quadrature over the orbit (issue 7.2).
//
// Ansatz x = A + B cos θ (θ = ωt − φ, B > 0): the gap is d(θ) = g + B cos θ with the mean gap g = A + l, the gap
// rate ḋ = ẋ = −Bω sin θ: θ ∈ (0, π) is the approach (ḋ < 0, branch H_a), θ ∈ (π, 2π) the departure (H_b).
// With h = −H, H = H_branch(d) − c(d)ḋ, and folding θ ↦ 2π − θ onto [0, π] (same gap, opposite rate):
//   N0·A = ⟨h⟩ = −(1/2π) ∫_0^π (H_a + H_b) dθ
//   Re N1      = −(1/πB) ∫_0^π (H_a + H_b) cos θ dθ
//   Im N1      =  (1/πB) ∫_0^π (H_a − H_b + 2c(d)Bω sin θ) sin θ dθ
// — the same quantities and sign convention as DescribingFunctions (describing_functions.hpp): for a
// piecewise-linear law they equal the closed forms of seed-1 eqs. (12)–(15), (26)–(31).
// A contact-aware law (ForceLaw::contact_aware, docs/force-laws.md#hysteresis) uses H_b only on a cycle that
// reaches its contact gap (g − B ≤ d_c: then it is the velocity-sign law, since H_a = H_b above the release gap);
// a cycle above it is free: H_a on both halves, no dissipation through the law (Im N1 from c(d) only).
//
// Quadrature. [0, π] is split where d(θ) crosses a switching gap s of the law (θ_s = arccos((s − g)/B), computed
// from the half-angle form so that it stays accurate at grazing) — the switching angles are located, never
// sampled. Each piece is integrated by a 31-point Gauss–Kronrod rule in a variable τ that makes endpoint
// behaviour like (θ − θ_s)^{p/2} smooth: θ = θ_s + L τ² at a switching end (L the piece length), the cubic
// θ = α + L τ²(3 − 2τ) when both ends are switching angles; the ends θ = 0, π need no change (d is stationary
// there). Inside a piece the gap is formed from its nearest end, d = d_e + B(cos θ − cos θ_e) with θ − θ_e taken
// from the map, so that a penetration far below the rounding of g + B cos θ (grazing) still reaches the law with
// its sign. The Kronrod–Gauss difference (QUADPACK's scaling) estimates the error; while the summed estimate is
// above relative_tolerance × ∫(|H_a + H_b| + |H_a − H_b + 2cBω sin θ|)dθ, the worst panel is bisected in τ.
// A smooth contact piece usually needs one panel; the van der Waals side of a near-contact orbit (a peak of
// width ~a0/B next to the switching angle) one or two bisections. One law evaluation per node and branch: a
// region where ForceLaw::branch_dependent is false costs one call per node (DMT: ~50–150 calls, 1.5–5 µs).
#include <complex>
#include <vector>

#include "afmkit/impact/force_law.hpp"
#include "afmkit/tapping/describing_functions.hpp"

namespace afmkit::tapping {

struct NumericalDfOptions {
  /// Bound on the estimated error relative to the scale ∫(|H_a + H_b| + |H_a − H_b + 2cBω sin θ|)dθ of the
  /// integrand; in (0, 1). The estimate (QUADPACK's scaling of |K31 − G15|) is conservative: with the default the
  /// measured actual errors are ≤ ~4e-15 of that scale for DMT, JKR-like, Kelvin–Voigt, Lennard-Jones and Hertz
  /// over contact and non-contact orbits (and rounding-level for piecewise-linear laws).
  double relative_tolerance = 1e-11;
  /// Most Gauss–Kronrod panels per evaluation (≥ 1); when reached the result is returned with its error estimate.
  int max_panels = 64;
  void validate() const;  // InvalidParameter naming the field
};

/// What one evaluation cost and how accurate it is estimated to be.
struct NumericalDfInfo {
  int panels = 0;             // Gauss–Kronrod panels used (31 nodes each)
  int law_evaluations = 0;    // calls of H_a / H_b / c
  double error_estimate = 0;  // estimated absolute error of the three integrals (summed), in units of the integrals
  double scale = 0;           // ∫(|H_a + H_b| + |H_a − H_b + 2cBω sin θ|)dθ
  bool converged = true;      // error_estimate ≤ relative_tolerance × scale (else max_panels was reached)
};

/// Describing functions of one force law at one drive frequency ω (ω enters only through the velocity term of a
/// law with damping). Reusable and thread-safe (const); the switching gaps are read once.
class DescribingFunctionQuadrature {
 public:
  /// frequency ω > 0 (finite) -> else InvalidParameter("frequency").
  DescribingFunctionQuadrature(impact::ForceLaw law, double frequency, NumericalDfOptions options = {});

  /// At mean gap g = A + l (finite) and amplitude B > 0 (finite): N0·A and N1 for the gaps d = g + B cos θ.
  /// Non-finite law values propagate (NaN / inf results).
  DescribingFunctions at_gap(double mean_gap, double amplitude, NumericalDfInfo* info = nullptr) const;
  /// At offset A, amplitude B and separation l (g = A + l).
  DescribingFunctions operator()(double offset, double amplitude, double separation) const {
    return at_gap(offset + separation, amplitude);
  }

  const impact::ForceLaw& law() const& { return law_; }
  double frequency() const { return frequency_; }
  const NumericalDfOptions& options() const& { return options_; }

 private:
  impact::ForceLaw law_;
  double frequency_;
  NumericalDfOptions options_;
  std::vector<double> gaps_;  // sorted switching gaps
};

/// One-shot form: N0·A and N1 of any law for x = A + B cos θ at separation l and drive frequency ω.
DescribingFunctions numerical_describing_functions(const impact::ForceLaw& law, double offset, double amplitude,
                                                   double separation, double frequency,
                                                   const NumericalDfOptions& options = {});

}  // namespace afmkit::tapping
