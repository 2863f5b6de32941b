#pragma once
// Distances in the phase plane of the tip (x, ẋ/ω), in the model's length unit: how the sweep, the transient and
// the orbit comparisons measure "the same state".
#include <cmath>

#include "afmkit/tapping/events.hpp"

namespace afmkit::tapping::detail {

/// |a − b| with the velocity scaled by the drive frequency ω.
inline double phase_distance(TipState a, TipState b, double omega) {
  return std::hypot(a.position - b.position, (a.velocity - b.velocity) / omega);
}
/// |a| with the velocity scaled by ω.
inline double phase_magnitude(TipState a, double omega) { return std::hypot(a.position, a.velocity / omega); }

}  // namespace afmkit::tapping::detail
