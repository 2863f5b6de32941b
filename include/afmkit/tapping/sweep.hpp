#pragma once
// Separation sweeps of periodic orbits.
//
// sweep_instrument: what an AFM does in an approach–retract curve. The separation l is stepped from l_max
// down to l_min (approach) and back up (retract); each orbit is continued from the previous one along its branch
// (follow_branch: Newton from the tangent prediction, in sub-steps of l). The Floquet multipliers are checked at
// every sub-step: a sub-step is shortened where the stability margins det(I − M), det(I + M) shrink by more than
// half or the orbit moves by more than state_resolution·max(A_free, |z|), so stability is resolved between grid points
// whatever the grid. Where the followed branch ceases to be stable (a fold, a multiplier through −1, or a corner
// into another branch) the sub-step is bisected down to jump_tolerance·A_free: the jump is located there, the
// physical transient is simulated from the last stable state just beyond it until it settles on another orbit,
// and that orbit is followed on to the next grid point (several jumps may happen between two grid points).
//
// A jump is a discontinuity of the continued orbit — a change of branch — not a large step: a point is marked
// jumped only when neither the previous orbit's branch reaches the new orbit (forward follow) nor the new orbit's
// branch reaches the previous orbit (backward follow) through stable orbits without a fold. Grazing (a contact
// branch meeting the free branch in a corner) is continuous, hence no jump, unless a fold or a loss of stability
// makes the response leave the branch there.
//
// sweep_grid: independent points (all orbits at each l, via find_orbits), in parallel (OpenMP).
//
// Each point carries the harmonic-balance value nearest to it (NaN where HB has no solution).
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/parameter.hpp"

namespace afmkit::tapping {

enum class SweepDirection { approach, retract, continuation };
const char* direction_name(SweepDirection direction);  // "approach", "retract", "continuation"

struct SweepOptions {
  ShootingOptions shooting;
  TransientOptions transient;
  bool harmonic_balance = true;  // put the nearest HB solution beside each point (any law)
  /// The retract pass after the approach (instrument sweeps: hysteresis, retract jumps); false: approach only
  /// (SweepResult::retract and retract_jumps stay empty; half the work).
  bool retract = true;
  /// Sub-step budget of follow_branch per separation step (halving / doubling the step in l).
  int max_substeps = 200;
  /// Resolution of the followed branch: a sub-step moves the scaled orbit state z = (x, ẋ/ω) by at most this times
  /// max(A_free, |z|) (features of the branch smaller than that may be stepped over).
  double state_resolution = 0.05;
  /// Jumps are located to within this times the free amplitude (the bisection of the sub-step where the followed
  /// branch ceases to be stable stops there; the reported separation is the middle of the last bracket).
  double jump_tolerance = 1e-5;
  /// A response that does not settle (non-periodic) is stepped by transients in sub-steps of this times the free
  /// amplitude until it settles on a periodic orbit (the exit from it is known to that sub-step).
  double transient_step = 0.005;
  bool parallel = true;  // OpenMP where points are independent (HB evaluation, grid sweeps, both directions)
  /// Newton along the followed branch iterates on the map without sensitivities from the previous orbit's
  /// Jacobian (try_shoot_near) and integrates them once per orbit; false: every iteration integrates them (the
  /// path before; kept for benchmarks and tests that compare the two).
  bool lazy_sensitivities = true;
  /// Called with the number of newly finished points (thread-safe callers only: may be called concurrently).
  std::function<void(long)> progress;
  Cancellation cancellation;  // checked once per point (core/cancellation.hpp)
  void validate() const;
};

/// One orbit of a sweep.
struct SweepPoint {
  double separation = 0.0;  // l
  double parameter = 0.0;   // value of the swept parameter (= l in separation sweeps; parameter.hpp)
  SweepDirection direction = SweepDirection::approach;
  PeriodicOrbit orbit;
  OrbitMetrics metrics;
  /// The response left the branch followed so far: the orbit was reached by a transient, and neither branch
  /// (previous orbit followed forward, new orbit followed back) connects the two through stable orbits
  /// without a fold (see follow_branch).
  bool jumped = false;
  bool periodic = true;  // false: the transient did not settle (metrics then describe one period of it)
  double arclength = 0.0;  // pseudo-arclength (continuation only): a length in model units (ContinuationOptions)
  // Nearest harmonic-balance solution at the same l (NaN when none / not applicable).
  double hb_amplitude = std::numeric_limits<double>::quiet_NaN();
  double hb_offset = std::numeric_limits<double>::quiet_NaN();
  double hb_phase = std::numeric_limits<double>::quiet_NaN();
  int hb_solutions = 0;  // number of HB solutions at this l
};

/// A jump of the instrument sweep: where the followed branch ceased to be stable and the tip landed on another.
struct SweepJump {
  double separation = 0.0;  // located: the middle of the last bracket [last stable orbit, first failed sub-step]
                            // (sweeps in another parameter: the separation of the model)
  double parameter = 0.0;   // where the jump is located in the swept parameter (= separation in separation sweeps)
  double from_parameter = 0.0, to_parameter = 0.0;  // the values of `from` and `to`
  double tolerance = 0.0;   // half the bracket: |separation − where the branch ceases to be stable| <= tolerance
  SweepDirection direction = SweepDirection::approach;
  bool located = true;      // false: after a non-periodic point (reported at the grid point, grid resolution)
  PeriodicOrbit from;       // the last stable orbit of the branch left
  PeriodicOrbit to;         // the orbit landed on (at to.separation, just beyond the jump; non-periodic: one period)
  bool landed_periodic = true;
  OrbitMetrics from_metrics, to_metrics;  // filled with the points' metrics
};

struct SweepResult {
  std::vector<SweepPoint> approach;  // l decreasing from l_max to l_min
  std::vector<SweepPoint> retract;   // l increasing from l_min to l_max
  /// Separations where the response jumped (located, see SweepJump), per direction, in sweep order.
  std::vector<double> approach_jumps;
  std::vector<double> retract_jumps;
  /// Every jump, approach then retract, in sweep order.
  std::vector<SweepJump> jumps;
};

/// Natural-parameter continuation of the period-n orbit `from` (at from.separation) to separation l_to: sub-steps
/// in l, each a Newton solve from the tangent prediction z + Δl·dz/dl (dz/dl = −(M − I)⁻¹ ∂P/∂l), accepted when
/// the converged orbit is stable and lies within |Δl|·max|dz/dl| of the prediction (continuity: O(Δl²) on a
/// smooth branch, O(Δl) at a corner such as grazing), the stability margins det(I − M) and det(I + M) have not
/// shrunk by more than half and the scaled state has moved by at most state_resolution·max(A_free, |z|); a rejected
/// sub-step is halved, an accepted one doubled. Returns the orbit at l_to, or nullopt when the branch ends before
/// l_to — a fold (no orbit or only another branch beyond it), a loss of stability, or the sub-step falling below
/// jump_tolerance·A_free — or the budget of max_substeps Newton solves is spent. `from` must be a converged orbit
/// of base at from.separation.
std::optional<PeriodicOrbit> follow_branch(const TappingModel& base, const PeriodicOrbit& from, double l_to,
                                           const ShootingOptions& shooting = {}, int max_substeps = 200);

/// What follow_stable_branch found: the orbit at l_to, or where the branch ceased to be stable.
struct BranchFollow {
  std::optional<PeriodicOrbit> reached;  // the orbit at l_to
  PeriodicOrbit last;                    // the last stable orbit of the branch (= *reached when reached)
  double last_parameter = 0.0;           // its value of the followed parameter (its separation in l)
  /// Not reached: the separation of the first sub-step that failed (no stable continuation); the branch ceases
  /// to be stable in (last.separation, failed_at]. NaN when the sub-step budget ran out first.
  double failed_at = 0.0;
  int substeps = 0;  // Newton solves spent
};
/// follow_branch with the options of a sweep (resolution, tolerance, budget), telling where the branch ended.
BranchFollow follow_stable_branch(const TappingModel& base, const PeriodicOrbit& from, double l_to,
                                  const SweepOptions& options);

/// Approach (l_max -> l_min) then retract (l_min -> l_max), `points` equally spaced separations each way.
/// Starts from the free response at l_max (settled by a transient if it is in contact there).
/// Validates: finite l_min < l_max, points ≥ 2 -> InvalidParameter.
SweepResult sweep_instrument(const TappingModel& base, double l_min, double l_max, int points,
                             const SweepOptions& options = {});
/// The same over an explicit list of separations (any order, duplicates merged; at least 2 distinct, finite):
/// approach visits them from the largest down, retract from the smallest up.
SweepResult sweep_instrument(const TappingModel& base, std::vector<double> separations,
                             const SweepOptions& options = {});

/// The instrument sweep in any parameter (parameter.hpp) — like continue_orbits in a parameter, harmonic balance
/// beside each point only for piecewise-linear laws (closed form; other laws: hb_* NaN, hb_solutions 0): "approach" visits the values from p_max down to p_min,
/// "retract" back up (a down and an up sweep); each point's `parameter` is its value, each jump's `parameter` where
/// it is located (approach_jumps, retract_jumps: those values). The jump tolerance and the transient sub-step are
/// then jump_tolerance·max|p| and transient_step·max|p| (the free amplitude at the scale of the separation).
/// Validates finite p_min < p_max (InvalidParameter naming <name>_min), points >= 2.
SweepResult sweep_instrument(const TappingModel& base, const SweepParameter& parameter, double p_min, double p_max,
                             int points, const SweepOptions& options = {});
SweepResult sweep_instrument(const TappingModel& base, const SweepParameter& parameter, std::vector<double> values,
                             const SweepOptions& options = {});

/// Every orbit (find_orbits) at each separation, the separations processed in parallel.
std::vector<OrbitSearchResult> sweep_grid(const TappingModel& base, const std::vector<double>& separations,
                                          const OrbitSearchOptions& options = {},
                                          const std::function<void(long)>& progress = {});

/// Fill the hb_* fields of `point` with the HB solution nearest in amplitude at point.separation (any law; for
/// laws without closed forms each call traces the HB curve, ~10 ms: sweeps use one HarmonicBalance instead).
void attach_harmonic_balance(const TappingModel& base, SweepPoint& point);

}  // namespace afmkit::tapping
