#pragma once
// Internal: metrics and harmonic balance of sweep points (independent per point, OpenMP).
#include <vector>

#include "afmkit/tapping/sweep.hpp"

namespace afmkit::tapping::detail {

void finish_points(const TappingModel& base, std::vector<SweepPoint>& points, const SimulationOptions& simulation,
                   bool harmonic_balance, bool parallel, const Cancellation& cancellation = {});

}  // namespace afmkit::tapping::detail
