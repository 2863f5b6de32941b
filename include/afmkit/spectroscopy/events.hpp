#pragma once
// Step 4 of preparing a measured force curve (docs/spectroscopy.md#snap-in-and-pull-off): the snap-in of the
// approach and the pull-off of the retract, each the bin of its branch with the most negative mean force (the
// bottom of the adhesion well: for the retract the adhesion force that breaks the contact). An event counts as
// detected when that force is below the branch's far level − n·σ (σ the force noise of one sample; the far level: the
// median of the bins over the far half of the branch's distance range, which a hydrodynamic drag shifts off 0);
// otherwise the branch shows no attraction above the noise and the event is undetected (NaN).
#include <limits>

#include "afmkit/spectroscopy/binning.hpp"

namespace afmkit::spectroscopy {

struct CurveEvent {
  bool detected = false;
  double distance = std::numeric_limits<double>::quiet_NaN();  ///< tip–sample distance [m]
  double force = std::numeric_limits<double>::quiet_NaN();     ///< force there [N] (negative: attractive)
};

/// The most negative bin of `branch` if its force is below the far level − threshold [N] (threshold = n·σ).
CurveEvent adhesion_minimum(const BinnedBranch& branch, double threshold);

}  // namespace afmkit::spectroscopy
