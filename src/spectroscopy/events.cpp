#include "afmkit/spectroscopy/events.hpp"

#include <algorithm>

namespace afmkit::spectroscopy {

CurveEvent adhesion_minimum(const BinnedBranch& branch, double threshold) {
  CurveEvent e;
  if (branch.size() == 0) return e;
  const std::size_t i =
      static_cast<std::size_t>(std::min_element(branch.force.begin(), branch.force.end()) - branch.force.begin());
  if (branch.force[i] < -threshold) {
    e.detected = true;
    e.distance = branch.distance[i];
    e.force = branch.force[i];
  }
  return e;
}

}  // namespace afmkit::spectroscopy
