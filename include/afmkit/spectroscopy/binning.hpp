#pragma once
// Step 4 of preparing a measured force curve (docs/spectroscopy.md#binning): samples (of one or several repeated
// curves) averaged onto a monotone grid of tip–sample distances: bins of width w centred on the multiples of w
// (distance 0, the contact point, is a bin centre); each bin that holds samples gives the mean distance and the mean
// force of its samples (the mean distance, not the centre: a bin the samples cover only in part — at a branch's
// ends, beside a snap-in gap — keeps its force at the distance it belongs to) and the standard error of the mean
// force; empty bins are dropped.
#include <cstddef>
#include <vector>

namespace afmkit::spectroscopy {

struct BinnedBranch {
  std::vector<double> distance;    ///< mean distance of the samples of each bin, strictly ascending [m]
  std::vector<double> centre;      ///< the bin's centre [m] (a multiple of the width)
  std::vector<double> force;       ///< mean force per bin [N]
  std::vector<double> force_error; ///< standard deviation / √count (0 for a single sample) [N]
  std::vector<std::size_t> count;  ///< samples per bin
  std::size_t size() const { return distance.size(); }
};

/// Bins (distance [m], force [N]) with width `width` [m]. InvalidParameter "bin_width" when width is not > 0 or
/// makes more than 10⁶ bins over the distance range.
BinnedBranch bin_branch(const std::vector<double>& distance, const std::vector<double>& force, double width);

}  // namespace afmkit::spectroscopy
