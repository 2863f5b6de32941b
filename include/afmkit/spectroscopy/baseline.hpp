#pragma once
// Step 2 of preparing a measured force curve (docs/spectroscopy.md#baseline): a straight line F = a + b·z (offset a
// and tilt b: interference, thermal drift, the laser's offset) fitted by least squares to the approach force over
// the far part of the height range, where the tip feels no force; subtracted from both segments. The residual RMS
// of the fit is the curve's force noise σ.
#include <cstddef>

#include "afmkit/spectroscopy/calibration.hpp"

namespace afmkit::spectroscopy {

struct BaselineFit {
  double offset = 0;        ///< a [N] (force at z = 0)
  double slope = 0;         ///< b [N/m]
  double residual_rms = 0;  ///< σ [N]: RMS of the residuals (n − 2 degrees of freedom)
  std::size_t points = 0;   ///< approach samples in the fit range
  double height_from = 0, height_to = 0;  ///< the fit range of z [m]
  double mean_height = 0;   ///< z̄ of the fitted samples [m]: the line's level there and its slope are independent
  double level_error = 0;   ///< standard error of the line at z̄: σ/√n [N]
  double slope_error = 0;   ///< standard error of the slope: σ/√Σ(z − z̄)² [N/m]
  double at(double height) const { return offset + slope * height; }
};

/// Fits the baseline to the approach samples with z ≥ z_max − fraction·(z_max − z_min) (the farthest `fraction`
/// of the approach's height range). InvalidParameter "baseline_fraction" when fraction is not in (0, 1] or the
/// range holds fewer than `min_points` samples (naming how many it holds).
BaselineFit fit_baseline(const ForceSegment& approach, double fraction, std::size_t min_points = 10);

/// Subtracts the baseline from a segment's force and recomputes its deflection d = F/k.
void subtract_baseline(ForceSegment& segment, const BaselineFit& fit, double spring_constant);

}  // namespace afmkit::spectroscopy
