#pragma once
// Internal: metrics and harmonic balance of sweep points and jumps (independent per point, OpenMP), and the path
// of models along the swept parameter shared by the instrument sweep and the continuation.
#include <vector>

#include <Eigen/Core>

#include "afmkit/tapping/parameter.hpp"
#include "afmkit/tapping/sweep.hpp"

namespace afmkit::tapping {
class HarmonicBalance;
}

namespace afmkit::tapping::detail {

/// The models along the swept parameter p, and how the continuation scales p: its unknown is scale·p (1 for the
/// separation, a length already; else free amplitude / max |p| of the range, so that the arclength weighs the
/// parameter and the orbit state alike).
struct ParameterPath {
  const TappingModel& base;
  const SweepParameter& parameter;
  double scale = 1.0;
  double width = 0.0;  // of the range (difference steps of ∂P/∂p: 1e-5·max(|p|, width))

  TappingModel at(double value) const { return parameter.at(base, value); }
  /// Step of the central differences of ∂P/∂p at `value`.
  double difference_step(double value) const;
  /// ∂(x, ẋ)(T)/∂p of one drive period from `start` at p = `value` (`end`: the map's value there), by central
  /// differences (one-sided where the model refuses p ± step). Not for the separation (exact column of the map).
  Eigen::Vector2d map_derivative(double value, TipState start, TipState end, const SimulationOptions& simulation) const;
  /// ∂P/∂p at a converged period-n orbit at p = `value`: the exact ∂P/∂l of the orbit for the separation.
  Eigen::Vector2d orbit_derivative(const PeriodicOrbit& orbit, double value, const SimulationOptions& simulation) const;
};
/// The path over [p_min, p_max] (scale and width as above).
ParameterPath make_path(const TappingModel& base, const SweepParameter& parameter, double p_min, double p_max);

void finish_points(const TappingModel& base, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   bool harmonic_balance, bool parallel, const Cancellation& cancellation = {});
/// The same with the harmonic balance of `base` built by the caller (nullptr: none), e.g. one for both directions.
void finish_points(const TappingModel& base, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   const HarmonicBalance* hb, bool parallel, const Cancellation& cancellation = {});
/// The same along any parameter: the metrics at each point's model, harmonic balance of each point's model (one
/// HB evaluation per point) when the law is piecewise linear (closed form); else hb_* stay NaN. (The separation
/// uses finish_points with one HB object for all points.)
void finish_points(const ParameterPath& path, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   bool harmonic_balance, bool parallel, const Cancellation& cancellation = {});
/// Metrics of the orbits on both sides of each jump.
void finish_jumps(const ParameterPath& path, std::vector<SweepJump>& jumps, const SimulationOptions& simulation,
                  bool parallel);

}  // namespace afmkit::tapping::detail
