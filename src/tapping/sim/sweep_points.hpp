#pragma once
// Internal: metrics and harmonic balance of sweep points and jumps (independent per point, OpenMP).
#include <vector>

#include "afmkit/tapping/sweep.hpp"

namespace afmkit::tapping::detail {

void finish_points(const TappingModel& base, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   bool harmonic_balance, bool parallel, const Cancellation& cancellation = {});
/// Metrics of the orbits on both sides of each jump.
void finish_jumps(const TappingModel& base, std::vector<SweepJump>& jumps, const SimulationOptions& simulation,
                  bool parallel);

}  // namespace afmkit::tapping::detail
