#include "afmkit/spectroscopy/events.hpp"

#include <algorithm>
#include <vector>

namespace afmkit::spectroscopy {

CurveEvent adhesion_minimum(const BinnedBranch& branch, double threshold) {
  CurveEvent e;
  if (branch.size() == 0) return e;
  const std::size_t i =
      static_cast<std::size_t>(std::min_element(branch.force.begin(), branch.force.end()) - branch.force.begin());
  // the far level: the median force of the bins over the far half of the distance range
  const double middle = 0.5 * (branch.distance.front() + branch.distance.back());
  std::vector<double> far;
  for (std::size_t j = 0; j < branch.size(); ++j)
    if (branch.distance[j] >= middle) far.push_back(branch.force[j]);
  std::nth_element(far.begin(), far.begin() + static_cast<long>(far.size() / 2), far.end());
  const double level = far.empty() ? 0.0 : std::min(0.0, far[far.size() / 2]);
  if (branch.force[i] < level - threshold) {
    e.detected = true;
    e.distance = branch.distance[i];
    e.force = branch.force[i];
  }
  return e;
}

}  // namespace afmkit::spectroscopy
