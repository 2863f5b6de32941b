#pragma once
// Harmonic balance for any force law (internal; the public entry points are in harmonic_balance.hpp, which
// dispatch here when the law is not piecewise linear).
//
// Unknowns. With the mean gap g = A + l and the amplitude B, the describing functions N0·A = ⟨h⟩(g, B) and
// N1(g, B) (numerical_describing_functions.hpp) do not depend on l. The first-harmonic balance is the scalar
// equation F(g, B) = (|L(iω)⁻¹ + N1(g, B)|·B − Γ)/Γ = 0, whose solution set is a curve in the (g, B) plane; the
// mean balance then gives A = −L(0)⟨h⟩ and the separation l = g − A, and φ = arg((L⁻¹ + N1)B).
//
// Coordinates. The curve is followed in (u, v): v = ln(B/B_free) and u is the "contact angle" of the orbit
// relative to the contact edge d_c (the highest switching gap of the law, 0 when it has none): with
// q_c = (g − d_c)/B, u = arccos q_c for |q_c| ≤ 1 (contact), u = −arccosh q_c for q_c ≥ 1 (no contact),
// u = π + arccosh(−q_c) for q_c ≤ −1 (permanent contact). Stiff contacts are resolved (u ~ √(penetration/B)),
// and the lines u = 0 (grazing d_c) and u = π, where F need not be smooth (a force jump at d_c makes the curve
// turn a corner there, as between the free line and the "+" branch of the closed form), are visited exactly.
//
// Algorithm. (1) The branch continuing the free oscillation is started at u = −14.5 (min gap ≈ 10⁶ B) and
// followed by secant pseudo-arclength continuation (tangents from the last three nodes, secant corrector along the
// normal, step control on corrector distance, tangent turning and the sign of ∂F/∂n — a corrector that lands on
// another part of the curve flips it); crossings of u = 0, π become corner nodes (one-sided gradients on each side).
// (2) A coarse sign grid of F (≈ 40 u values × 3 per decade of B from 1e-7 B_free to 1.5 Γ/Im L(iω)⁻¹ — the bound
// on B for a dissipative law) finds every other component that crosses a grid cell not visited by a traced one
// (isolas, branches ending at B → 0); each is refined on its grid edge and followed both ways. (3) On each smooth
// piece, extrema of l (folds) and of q along the curve are inserted as nodes: detected from node values (and from
// derivatives on the first and last segment of a piece), located by TOMS 748 on dl/ds (4th-order differences)
// or dq/ds; between nodes q and l are then monotone. Queries bracket on the nodes and refine: on a ray q = const
// (points_at_q, curve samples) by a secant in ln B, at a separation by TOMS 748 along the segment with a secant
// corrector — both to |F| ≤ 1e-13 (or the rounding level of F).
//
// Labels. Free/Plus/Minus generalise the closed form: Plus where ∂F/∂B at fixed q is > 0 (the larger root of
// E2), Minus where it is < 0; a Plus point whose orbit stays above the contact edge (g − B ≥ d_c) is Free.
// For a law of infinite range (van der Waals ∝ 1/d²) "free" is therefore the out-of-contact part of the
// branch continuing the free oscillation — only approximately B = Γ|L(iω)|, A = 0.
//
// Ends of the curve and what is not found: a component ends where B < 1e-9 B_free (e.g. where a hysteretic law
// acts as dry friction, B·N1 → 2(H_a − H_b)/π as B → 0: no oscillating solution beyond), at q_c < −1e4 (deep
// permanent contact: solutions there are not found) or at q_c > 1e6 (beyond it the free branch is continued by a
// direct solve). Components that stay inside one seed-grid cell, and pairs of extrema of l or q between two
// consecutive nodes, are not found.
#include <complex>
#include <memory>
#include <optional>
#include <vector>

#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/numerical_describing_functions.hpp"

namespace afmkit::tapping::detail {

class GeneralHarmonicBalance {
 public:
  /// Traces the curve; `cancellation` is checked every 64 evaluations of F (core/cancellation.hpp).
  explicit GeneralHarmonicBalance(const TappingModel& model, const Cancellation& cancellation = {});

  /// Every solution at separation l, sorted by increasing amplitude.
  std::vector<HbPoint> solutions(double separation) const;
  /// Every point of the curve with (A + l)/B = q, sorted by increasing amplitude.
  std::vector<HbPoint> points_at_q(double q) const;
  /// The curve at the given q samples (increasing): Free/Plus points into `upper`, Minus points into `lower`
  /// (appended, by increasing q, then amplitude).
  void sample(const std::vector<double>& q_samples, bool include_minus, std::vector<HbPoint>& upper,
              std::vector<HbPoint>& lower, const Cancellation& cancellation = {}) const;
  const std::vector<HbFold>& folds() const { return folds_; }
  double free_amplitude() const { return b_ref_; }
  /// Diagnostics: traced components, nodes, describing-function evaluations of the construction.
  int components() const { return static_cast<int>(components_.size()); }
  int nodes() const;
  long construction_evaluations() const { return construction_evaluations_; }

  struct Eval {
    double u = 0, v = 0;  // curve coordinates
    double g = 0, b = 0;  // mean gap, amplitude
    double f = 0;         // (|z| − Γ)/Γ
    double offset = 0;    // A
    double separation = 0;  // l
    double phase = 0;     // φ
    bool ok = false;      // finite
  };
  struct Node {
    Eval e;
    double tu = 0, tv = 0;  // unit tangent in (u, v), along the component's order
    double sn = 0;          // ∂F/∂n along the normal n = (−tv, tu) (∇F ≈ sn·n on the curve)
    bool break_after = false;  // the next node is the same point on the other side of a corner
    bool extremum = false;     // inserted at an extremum of l (fold) or q
  };
  /// The traced components (nodes in order; extrema of q and l inserted) — for tests and diagnostics.
  const std::vector<std::vector<Node>>& component_nodes() const { return components_; }

 private:
  DescribingFunctionQuadrature df_;
  std::complex<double> inverse_;  // L(iω)⁻¹
  double static_gain_;            // L(0)
  double gamma_;                  // Γ
  double b_ref_;                  // free amplitude Γ|L(iω)|
  double contact_edge_;           // d_c
  double v_min_, v_max_;
  std::vector<std::vector<Node>> components_;
  std::vector<bool> free_end_;    // component ends (last node) at the far free end
  std::vector<HbFold> folds_;
  long construction_evaluations_ = 0;

  friend class GeneralHbBuilder;

  Eval evaluate(double u, double v) const;
  Eval evaluate_gb(double g, double b) const;
  void fill(Eval& e) const;
  double gap_of(double u, double b) const;
  HbPoint to_point(const Eval& e, double slope) const;  // slope: ∂F/∂ln B at fixed q (sign gives the label)
  double ray_slope(const Eval& e) const;                 // ∂F/∂ln B at fixed q by central differences
  bool point_on_segment(const Node& a, const Node& b, double sigma, Eval& out) const;
  bool solve_on_ray(double q, const Node& a, const Node& b, Eval& out, double& slope) const;
  /// The point at q on the segment a–b (q between their q values; the nodes themselves when q is theirs).
  std::optional<HbPoint> segment_point(double q, const Node& a, const Node& b) const;
  bool solve_free_ray(double q, const Node& end, Eval& out, double& slope) const;
  bool solve_free_separation(double l, const Node& end, Eval& out) const;
  std::vector<HbPoint> ray_points(double q, bool with_minus) const;
};

}  // namespace afmkit::tapping::detail
