#pragma once
// Separation sweeps of periodic orbits.
//
// sweep_instrument: what an AFM does in an approach–retract curve. The separation l is stepped from l_max
// down to l_min (approach) and back up (retract); each orbit is continued from the previous one by shooting.
// When Newton from the previous orbit fails, converges to an unstable orbit, or jumps far from it, the
// physical transient is simulated from the previous state at the new l until it settles, then shot — so
// jumps and hysteresis appear exactly where the followed branch ends (folds, grazing).
//
// sweep_grid: independent points (all orbits at each l, via find_orbits), in parallel (OpenMP).
//
// Each point carries the harmonic-balance value nearest to it (piecewise-linear laws; NaN otherwise).
#include <functional>
#include <limits>
#include <vector>

#include "afmkit/tapping/orbit.hpp"

namespace afmkit::tapping {

enum class SweepDirection { approach, retract, continuation };
const char* direction_name(SweepDirection direction);  // "approach", "retract", "continuation"

struct SweepOptions {
  ShootingOptions shooting;
  TransientOptions transient;
  bool harmonic_balance = true;  // put the nearest HB solution beside each point (piecewise-linear laws)
  /// A continued orbit whose initial state moved more than this (relative to the amplitude) from the
  /// previous one is checked by a transient (a jump is only accepted when the physics makes it).
  double jump_check_distance = 0.05;
  bool parallel = true;  // OpenMP where points are independent (HB evaluation, grid sweeps, both directions)
  /// Called with the number of newly finished points (thread-safe callers only: may be called concurrently).
  std::function<void(long)> progress;
  void validate() const;
};

/// One orbit of a sweep.
struct SweepPoint {
  double separation = 0.0;  // l
  SweepDirection direction = SweepDirection::approach;
  PeriodicOrbit orbit;
  OrbitMetrics metrics;
  /// The response left the branch followed so far: the orbit was reached by a transient and does not continue
  /// the previous orbit (Newton from it at the previous separation does not return there).
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

/// Approach (l_max -> l_min) then retract (l_min -> l_max), `points` equally spaced separations each way.
/// Starts from the free response at l_max (settled by a transient if it is in contact there).
/// Validates: finite l_min < l_max, points ≥ 2 -> InvalidParameter.
SweepResult sweep_instrument(const TappingModel& base, double l_min, double l_max, int points,
                             const SweepOptions& options = {});

/// Every orbit (find_orbits) at each separation, the separations processed in parallel.
std::vector<OrbitSearchResult> sweep_grid(const TappingModel& base, const std::vector<double>& separations,
                                          const OrbitSearchOptions& options = {},
                                          const std::function<void(long)>& progress = {});

/// Fill the hb_* fields of `point` with the HB solution nearest in amplitude at point.separation.
void attach_harmonic_balance(const TappingModel& base, SweepPoint& point);

}  // namespace afmkit::tapping
