#pragma once
// Pseudo-arclength continuation of periodic orbits in the separation l, through folds.
// Unknowns u = (x(0), ẋ(0), l); equations G(u) = P_l(x(0), ẋ(0)) − (x(0), ẋ(0)) = 0 (shooting, period T)
// plus the arclength condition τ·(u − u_pred) = 0, with the exact Jacobian [M − I | ∂P/∂l]. The tangent τ is
// the null vector of that 2×3 Jacobian, oriented to keep going. Each point gets its Floquet stability, so the
// unstable middle branch between two folds (or a fold and a grazing point) is produced and flagged.
// A contact branch that ends at grazing (contact vanishing; the saltation matrices and multipliers grow without
// bound there) turns non-smoothly into the free branch: the continuation hops onto the grazing free orbit and
// follows the free branch towards larger l.
// The same engine continues in any other parameter p of the model (SweepParameter: the drive frequency or
// amplitude, a law parameter): the unknowns are then (x(0), ẋ(0)/ω, s·p) with ∂P/∂p by central differences of the
// map (docs/theory-tapping.md#parameter-continuation); folds are extrema of p along the branch.
#include <string>
#include <vector>

#include "afmkit/tapping/parameter.hpp"
#include "afmkit/tapping/sweep.hpp"

namespace afmkit::tapping {

struct ContinuationOptions {
  double initial_step = 0.02;  // arclength step (model length units: x(0), ẋ(0)/ω and s·p are lengths)
  double min_step = 1e-7;
  double max_step = 0.2;
  int max_points = 5000;
  int max_corrector_iterations = 12;
  double tolerance = 1e-10;  // corrector convergence (scaled residual)
  double time_budget_seconds = 60.0;  // whole continuation -> stops with stop_reason "time budget"
  bool harmonic_balance = true;
  bool parallel = true;      // metrics and HB of the points on both cores
  bool analyse_points = true;  // compute the metrics of every point (false: orbits only, metrics left zero)
  ShootingOptions shooting;  // integrator options; tolerance used for the starting orbit
  Cancellation cancellation;  // checked once per point (core/cancellation.hpp)
  void validate() const;
};

/// A fold of the continued branch: p(s) has a local extremum there (dp/ds changed sign).
struct ContinuationFold {
  double parameter = 0.0;          // located by cubic Hermite interpolation of p(s) between the two points
  double separation = 0.0;         // = parameter when continuing in l; else the (fixed) separation
  bool separation_maximum = false; // true: p has a local maximum (two orbits disappear for larger p)
  std::size_t point = 0;           // index into points of the point nearer the fold (its orbit describes it)
};

struct ContinuationResult {
  std::vector<SweepPoint> points;  // direction = continuation, in arclength order
  std::vector<ContinuationFold> folds;  // in arclength order
  /// Values of the parameter (separations when continuing in l) where a contact branch ran into grazing and the
  /// continuation hopped onto the free branch.
  std::vector<double> grazing;
  std::string stop_reason;         // "left range", "max points", "step below min_step (…)" …
};

/// Continue the period-1 branch through `start` (a converged orbit at start.separation) for l within
/// [l_min, l_max], first moving in the direction of increasing l if `increasing` (else decreasing).
ContinuationResult continue_orbits(const TappingModel& base, const PeriodicOrbit& start, double l_min, double l_max,
                                   bool increasing, const ContinuationOptions& options = {});

/// Convenience for the CLI: start from the largest-amplitude stable orbit found at l_min (find_orbits) and
/// continue towards increasing l until l leaves [l_min, l_max] or the budget ends.
ContinuationResult sweep_continuation(const TappingModel& base, double l_min, double l_max,
                                      const ContinuationOptions& options = {});

/// continue_orbits in any parameter: `start` is a converged orbit of parameter.at(base, start_value); p stays
/// within [p_min, p_max] (InvalidParameter naming <name>_min / <name>_max otherwise). Each point's `parameter` is
/// its value of p; its `separation` that of its model. Harmonic balance beside each point (options.harmonic_balance)
/// only for piecewise-linear laws, whose HB is a closed form at each point's model; other laws: hb_* NaN.
ContinuationResult continue_orbits(const TappingModel& base, const SweepParameter& parameter,
                                   const PeriodicOrbit& start, double start_value, double p_min, double p_max,
                                   bool increasing, const ContinuationOptions& options = {});
/// sweep_continuation in any parameter: from the largest-amplitude stable orbit at p_min towards p_max.
ContinuationResult sweep_continuation(const TappingModel& base, const SweepParameter& parameter, double p_min,
                                      double p_max, const ContinuationOptions& options = {});

}  // namespace afmkit::tapping
