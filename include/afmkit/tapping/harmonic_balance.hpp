#pragma once
// Harmonic balance (HB) of the tapping-mode model (seed-1 eqs. 16–19, 32–33, ext. E1–E7; docs/theory-tapping.md) for
// any force law.
//
// Ansatz x(t) ≈ A + B cos(ωt − φ) for the drive Γ cos(ωt) (B > 0). The penetration parameter
// q = (A + l)/B (eq. 15) parametrises every solution.
//
// Piecewise-linear laws (model.law.piecewise_linear() non-null: eqs. 10, 11, 26) use the closed forms: for a
// given q the first-harmonic balance (33) is a real quadratic in B with roots B₊ ("+" branch) and B₋ ("−" branch)
// (E1, E2); then A (E3), l = qB − A (E4) and φ (E5) follow. For q ≥ 1 (no contact) the "+" root is the free
// oscillation B = Γ|L(iω)|, A = 0; such points are labelled HbBranch::Free.
//
// Every other law (DMT + van der Waals, Hertz, JKR-like, Lennard-Jones, Kelvin–Voigt, custom) uses numerical
// describing functions (numerical_describing_functions.hpp) and a continuation of the first-harmonic curve
// |L(iω)⁻¹ + N1(g, B)|·B = Γ in the plane of the mean gap g = A + l and B, followed over its whole extent (see
// src/tapping/hb/general_harmonic_balance.hpp for the algorithm and its limits). The labels generalise the
// closed form: Plus where ∂F/∂B at fixed q is > 0 (F = |L⁻¹ + N1|B − Γ; B₊ is the larger root of E2), Minus where
// it is < 0, and Free for a Plus point whose orbit stays above the law's contact edge (its highest switching gap,
// 0 if none). For a law of infinite range (van der Waals ∝ 1/d²) no solution is exactly free: "free" is the
// out-of-contact part of the branch that continues the free oscillation, with B ≈ Γ|L(iω)| and A ≈ 0 only
// approximately. At one q there may be more than one Plus (or Minus) point (e.g. the S-shaped DMT curve).
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/tapping/hb_branch.hpp"
#include "afmkit/tapping/model.hpp"

namespace afmkit::tapping {

/// Which root of the quadratic (E1) a solution lies on. Free = no contact (q ≥ 1), Plus/Minus = B₊/B₋ (E2).
enum class HbBranch { Free = 0, Plus = 1, Minus = -1 };

/// Text name of a branch: "free", "plus", "minus".
const char* branch_name(HbBranch branch);

struct HbPoint {
  double q;           // penetration parameter (A + l)/B, eq. 15
  double separation;  // l
  double amplitude;   // B > 0
  double offset;      // A
  double phase;       // φ [rad]: x ≈ A + B cos(ωt − φ) for drive Γ cos ωt
  HbBranch branch;
};

/// Every HB solution at model.separation (algorithm of docs/theory-tapping.md#two-branch-solution), sorted by
/// increasing amplitude. (For a general law this builds HarmonicBalance(model): reuse one object for many separations.)
std::vector<HbPoint> harmonic_balance_solutions(const TappingModel& model);

/// The HB point for a given q on a branch (std::nullopt if that root does not exist or B <= 0).
/// model.separation is ignored. For q ≥ 1, Plus and Free both give the free oscillation (labelled Free);
/// Minus gives nullopt. Free with q < 1 gives nullopt. NaN / infinite q -> InvalidParameter("q").
/// General laws: among the points at q (HarmonicBalance::points_at_q), Free gives the Free point of largest
/// amplitude, Plus the Plus-or-Free point of largest amplitude (labelled as it is), Minus the Minus point of
/// largest amplitude.
std::optional<HbPoint> harmonic_balance_at_q(const TappingModel& model, double q, HbBranch branch);

/// A fold (jump point) of the separation–amplitude curve: a local extremum of l along a contact branch,
/// dl/dq = 0 (ext. E6). Slowly sweeping l past l_jump = point.separation makes the state leave the branch.
struct HbFold {
  HbPoint point;           // q*, l_jump = l(q*), B, A, φ there (branch Plus or Minus)
  bool separation_maximum; // true: l(q) has a local maximum at q* (two solutions disappear for l > l_jump)
};

/// Options of harmonic_balance_curve.
enum class HbCurveSpacing {
  Uniform,          // q uniform on [q_min, q_max]
  RefinedGrazing,   // half the samples uniform in q, half log-uniform in 1 − q (the steep part near q → 1⁻)
};
struct HbCurveOptions {
  double q_min = -2.0;
  double q_max = 2.0;            // > q_min
  std::size_t points = 1000;     // ≥ 2 samples in q
  HbCurveSpacing spacing = HbCurveSpacing::RefinedGrazing;
  double min_gap = 1e-10;        // smallest 1 − q of the log samples (RefinedGrazing), in (0, 1)
  bool include_minus = true;     // also sample the "−" branch where it exists
  Cancellation cancellation;     // checked every 4096 samples (core/cancellation.hpp)
};

/// The parametric HB curve (l(q), B(q), A(q), φ(q)) (seed-1 eq. 19) sampled over q: each sample gives the
/// Free point (q ≥ 1) or the Plus point (if it exists) and, when include_minus, the Minus point (if it exists).
/// Order: Free/Plus points by increasing q, then Minus points by increasing q.
/// General laws: each sample gives every point at that q (points_at_q), ordered by q then amplitude within
/// each of the two blocks; RefinedGrazing refines towards q = 1 as for the closed form (for a law with a contact
/// edge d_c ≠ 0 grazing is at q = 1 + d_c/B instead).
/// Bad options (q_min ≥ q_max, points < 2, non-finite bounds, min_gap ∉ (0, 1)) -> InvalidParameter.
std::vector<HbPoint> harmonic_balance_curve(const TappingModel& model, const HbCurveOptions& options);
/// Same, writing into `out` (overwritten; piecewise-linear laws: no allocation when out.capacity() ≥ 2·points).
void harmonic_balance_curve(const TappingModel& model, const HbCurveOptions& options, std::vector<HbPoint>& out);
/// The same points in the same order, streamed: `sink` gets them in consecutive chunks of at most `chunk` (≥ 1)
/// points, so that memory is bounded by a chunk whatever options.points. The "−" block comes from a second pass
/// over the samples, run only where the first found "−" points (for a general law: only over the chunks of q
/// samples that have some). Returns the number of points.
std::size_t harmonic_balance_curve_chunks(const TappingModel& model, const HbCurveOptions& options,
                                          const std::function<void(std::span<const HbPoint>)>& sink,
                                          std::size_t chunk = 4096);

/// Every fold of the "+" and "−" branches (sorted by q), each located to |Δq| ≤ 1e-10 (closed form; general
/// laws: where dl/ds = 0 along the curve, from 4th-order differences of the numerical describing functions —
/// within ~1e-11 in q of the closed form on piecewise-linear laws). Corners of the curve (where the orbit grazes a
/// force jump, or crosses u = 0, π of general_harmonic_balance.hpp) are not folds.
std::vector<HbFold> harmonic_balance_folds(const TappingModel& model);

namespace detail {
class GeneralHarmonicBalance;
}

/// Harmonic balance of one model (the separation is an input of each query). Piecewise-linear laws: the
/// constructor scans both branches once over q ∈ [−1e7, 1) (a log grid in the contact angle near grazing, i.e.
/// 1 − q down to ~1e-16; a uniform grid in the angle elsewhere; a log grid in −q for permanent contact), locates
/// where each branch exists and every fold; afterwards each branch is monotone between consecutive scan nodes and
/// solutions(l) only brackets and refines (TOMS 748). Use it for sweeps over many separations (the scan costs
/// ~0.5 ms; each solutions(l) ~10 µs). Not found: solutions with q < −1e7 (permanent contact, l within ~1e-7 of
/// the limit E8) and the two extra solutions on a wiggle of l(q) whose two folds fall into one scan cell
/// (cells: 4 % of a for a < 0.3, Δa = 0.005 above, 6 % of |q| for q < −1).
/// Other laws: the constructor follows the whole first-harmonic curve with numerical describing functions
/// (typically 2–5 thousand evaluations, ~5–20 ms); solutions(l) brackets on its nodes and refines (~0.1 ms per
/// solution).
/// Queries are const and thread-safe in both cases.
class HarmonicBalance {
 public:
  /// `cancellation` is checked during the construction (every 64 describing-function evaluations of the general
  /// curve trace, which can take seconds for a finely tabulated law; core/cancellation.hpp).
  explicit HarmonicBalance(const TappingModel& model, const Cancellation& cancellation = {});

  /// Every solution at separation l (finite), sorted by increasing amplitude.
  std::vector<HbPoint> solutions(double separation) const;
  /// The point at q on a branch (see harmonic_balance_at_q).
  std::optional<HbPoint> at_q(double q, HbBranch branch) const;
  /// Every point with (A + l)/B = q (all branches), sorted by increasing amplitude.
  std::vector<HbPoint> points_at_q(double q) const;
  /// Folds (sorted by q).
  const std::vector<HbFold>& folds() const& { return folds_; }
  std::vector<HbFold> folds() const&& { return folds_; }  // a temporary gives a copy, never a dangling reference
  /// Free amplitude Γ|L(iω)|: the free solution exists for l ≥ this (ext. E7: jump-down point). For a law of
  /// infinite range this is the amplitude of the linear oscillator, approached by the free branch as l → ∞.
  double free_amplitude() const { return free_amplitude_; }
  /// Whether the closed forms are used (the law is piecewise linear).
  bool closed_form() const { return coefficients_.has_value(); }
  /// The closed-form coefficients; InvalidParameter("law", …) unless closed_form().
  const HbCoefficients& coefficients() const&;
  HbCoefficients coefficients() const&&;

 private:
  struct Node {
    bool permanent;     // parameter is q (q ≤ −1), else the contact angle
    double parameter;
    double separation;
    double derivative;  // dl/dparameter
  };
  using Run = std::vector<Node>;  // consecutive nodes on which the branch exists, monotone between nodes

  std::optional<HbCoefficients> coefficients_;  // piecewise-linear laws
  std::shared_ptr<const detail::GeneralHarmonicBalance> general_;  // other laws
  double free_amplitude_;
  std::vector<Run> runs_[2];  // [0]: Plus, [1]: Minus
  std::vector<HbFold> folds_;

  void scan_branch(int sign);
  [[noreturn]] void require_piecewise_linear_model() const;
  HbBranchEvaluation evaluate(const Node& like, double parameter, int sign) const;
};

}  // namespace afmkit::tapping
