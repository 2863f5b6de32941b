#pragma once
// Separation sweeps of periodic orbits.
//
// sweep_instrument: what an AFM does in an approach–retract curve. The separation l is stepped from l_max
// down to l_min (approach) and back up (retract); each orbit is continued from the previous one along its branch
// (follow_branch: Newton from the tangent prediction, in sub-steps of l where needed). Where the followed branch
// ends before the next separation (a fold, a loss of stability, or a corner into another branch) the physical
// transient is simulated from the previous state at the new l until it settles, then shot.
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

namespace afmkit::tapping {

enum class SweepDirection { approach, retract, continuation };
const char* direction_name(SweepDirection direction);  // "approach", "retract", "continuation"

struct SweepOptions {
  ShootingOptions shooting;
  TransientOptions transient;
  bool harmonic_balance = true;  // put the nearest HB solution beside each point (any law)
  /// Sub-step budget of follow_branch per separation step (halving / doubling the step in l).
  int max_substeps = 200;
  bool parallel = true;  // OpenMP where points are independent (HB evaluation, grid sweeps, both directions)
  /// Called with the number of newly finished points (thread-safe callers only: may be called concurrently).
  std::function<void(long)> progress;
  Cancellation cancellation;  // checked once per point (core/cancellation.hpp)
  void validate() const;
};

/// One orbit of a sweep.
struct SweepPoint {
  double separation = 0.0;  // l
  SweepDirection direction = SweepDirection::approach;
  PeriodicOrbit orbit;
  OrbitMetrics metrics;
  /// The response left the branch followed so far: the orbit was reached by a transient, and neither branch
  /// (previous orbit followed forward, new orbit followed back) connects the two through stable orbits
  /// without a fold (see follow_branch).
  bool jumped = false;
  bool periodic = true;  // false: the transient did not settle (metrics then describe one period of it)
  double arclength = 0.0;  // pseudo-arclength (continuation only)
  // Nearest harmonic-balance solution at the same l (NaN when none / not applicable).
  double hb_amplitude = std::numeric_limits<double>::quiet_NaN();
  double hb_offset = std::numeric_limits<double>::quiet_NaN();
  double hb_phase = std::numeric_limits<double>::quiet_NaN();
  int hb_solutions = 0;  // number of HB solutions at this l
};

struct SweepResult {
  std::vector<SweepPoint> approach;  // l decreasing from l_max to l_min
  std::vector<SweepPoint> retract;   // l increasing from l_min to l_max
  /// Separations where the response jumped (first point on the new branch), per direction.
  std::vector<double> approach_jumps;
  std::vector<double> retract_jumps;
};

/// Natural-parameter continuation of the period-n orbit `from` (at from.separation) to separation l_to: sub-steps
/// in l, each a Newton solve from the tangent prediction z + Δl·dz/dl (dz/dl = −(M − I)⁻¹ ∂P/∂l), accepted when
/// the converged orbit is stable and lies within |Δl|·max|dz/dl| of the prediction (continuity: O(Δl²) on a
/// smooth branch, O(Δl) at a corner such as grazing); a rejected sub-step is halved, an accepted one doubled.
/// Returns the orbit at l_to, or nullopt when the branch ends before l_to — a fold (no orbit or only another
/// branch beyond it), a loss of stability, or the sub-step falling below 1e-5·max(1, |l_to − l|) — or the
/// budget of max_substeps Newton solves is spent. `from` must be a converged orbit of base at from.separation.
std::optional<PeriodicOrbit> follow_branch(const TappingModel& base, const PeriodicOrbit& from, double l_to,
                                           const ShootingOptions& shooting = {}, int max_substeps = 200);

/// Approach (l_max -> l_min) then retract (l_min -> l_max), `points` equally spaced separations each way.
/// Starts from the free response at l_max (settled by a transient if it is in contact there).
/// Validates: finite l_min < l_max, points ≥ 2 -> InvalidParameter.
SweepResult sweep_instrument(const TappingModel& base, double l_min, double l_max, int points,
                             const SweepOptions& options = {});
/// The same over an explicit list of separations (any order, duplicates merged; at least 2 distinct, finite):
/// approach visits them from the largest down, retract from the smallest up.
SweepResult sweep_instrument(const TappingModel& base, std::vector<double> separations,
                             const SweepOptions& options = {});

/// Every orbit (find_orbits) at each separation, the separations processed in parallel.
std::vector<OrbitSearchResult> sweep_grid(const TappingModel& base, const std::vector<double>& separations,
                                          const OrbitSearchOptions& options = {},
                                          const std::function<void(long)>& progress = {});

/// Fill the hb_* fields of `point` with the HB solution nearest in amplitude at point.separation (any law; for
/// laws without closed forms each call traces the HB curve, ~10 ms: sweeps use one HarmonicBalance instead).
void attach_harmonic_balance(const TappingModel& base, SweepPoint& point);

}  // namespace afmkit::tapping
