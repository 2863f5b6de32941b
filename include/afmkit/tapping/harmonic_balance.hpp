#pragma once
// Harmonic balance (HB) of the tapping-mode model with a piecewise-linear hysteresis law
// (seed-1 eqs. 16–19, 32–33 and MATH.md ext. E1–E7).
//
// Ansatz x(t) ≈ A + B cos(ωt − φ) for the drive Γ cos(ωt) (B > 0). The penetration parameter
// q = (A + l)/B (eq. 15) parametrises every solution: for a given q the first-harmonic balance (33) is a real
// quadratic in B with roots B₊ ("+" branch) and B₋ ("−" branch) (E1, E2); then A (E3), l = qB − A (E4) and
// φ (E5) follow. For q ≥ 1 (no contact) the "+" root is the free oscillation B = Γ|L(iω)|, A = 0; such points
// are labelled HbBranch::Free.
//
// HB applies only to piecewise-linear laws (model.law.piecewise_linear() non-null); every function here
// throws InvalidParameter("law", …) otherwise.
#include <optional>
#include <vector>

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

/// Every HB solution at model.separation (MATH.md A.7 algorithm), sorted by increasing amplitude.
std::vector<HbPoint> harmonic_balance_solutions(const TappingModel& model);

/// The HB point for a given q on a branch (std::nullopt if that root does not exist or B <= 0).
/// model.separation is ignored. For q ≥ 1, Plus and Free both give the free oscillation (labelled Free);
/// Minus gives nullopt. Free with q < 1 gives nullopt. NaN / infinite q -> InvalidParameter("q").
std::optional<HbPoint> harmonic_balance_at_q(const TappingModel& model, double q, HbBranch branch);

/// A fold (jump point) of the separation–amplitude curve: dl/dq = 0 on a contact branch (ext. E6).
struct HbFold {
  HbPoint point;  // q*, l_jump = l(q*), B, A, φ there
  double curvature;  // d²l/dq² at q* (sign tells whether l(q*) is a local max (<0) or min (>0))
};

/// Every fold of the "+" and "−" contact branches for q in [q_min, 1) (sorted by q), located to |Δq| ≤ 1e-10.
/// q_min must be finite and < 1.
std::vector<HbFold> harmonic_balance_folds(const TappingModel& model, double q_min = -20.0);

/// Options of harmonic_balance_curve.
struct HbCurveOptions {
  double q_min = -2.0;
  double q_max = 2.0;
  std::size_t points = 1000;  // ≥ 2 samples in q (log-spaced in 1 − q near grazing when log_near_grazing)
  bool log_near_grazing = true;  // cluster samples at q → 1⁻ (the steep part of l(q) for stiff samples)
  bool include_minus = true;     // also sample the "−" branch (only where it exists)
};

/// The parametric HB curve (l(q), B(q), A(q), φ(q)) (seed-1 eq. 19) sampled over q ∈ [q_min, q_max]:
/// each sample q gives the Free point (q ≥ 1) or the Plus point and, if it exists, the Minus point.
/// Output order: Plus/Free points by increasing q, then Minus points by increasing q.
std::vector<HbPoint> harmonic_balance_curve(const TappingModel& model, const HbCurveOptions& options);

/// Same, writing into `out` (cleared first; its capacity is reused, no allocation when large enough).
void harmonic_balance_curve(const TappingModel& model, const HbCurveOptions& options, std::vector<HbPoint>& out);

}  // namespace afmkit::tapping
