#pragma once
// Step 1 of preparing a measured force curve (docs/spectroscopy.md#calibration): the spring constant k and the
// inverse optical lever sensitivity InvOLS from the file, overridden by the user's values; deflection d = InvOLS·V
// when the file has only the photodetector signal; force F = k·d (or d = F/k when the file gives the force).
#include <limits>
#include <string>
#include <vector>

#include "afmkit/io/curves/raw_curve.hpp"

namespace afmkit::spectroscopy {

/// The user's calibration; NaN: take the file's.
struct Calibration {
  double spring_constant = std::numeric_limits<double>::quiet_NaN();  ///< k [N/m]
  double invols = std::numeric_limits<double>::quiet_NaN();           ///< [m/V]
};

/// One segment in force: piezo height z [m] (increasing away from the sample), deflection d [m] and force F = k·d
/// [N] (positive repulsive), sample by sample as recorded.
struct ForceSegment {
  std::vector<double> height, deflection, force;
  std::size_t size() const { return height.size(); }
};

/// The approach and the retract of one curve in force, with the calibration used.
struct CalibratedCurve {
  ForceSegment approach, retract;
  double spring_constant = 0;  ///< k used [N/m]
  double invols = std::numeric_limits<double>::quiet_NaN();  ///< InvOLS used [m/V] (NaN: not needed)
  std::string spring_constant_source, invols_source;          ///< "file", "option" or "" (not needed)
  std::string origin;
  std::vector<std::string> notes;  ///< e.g. segments ignored
};

/// Calibrates `raw`: the first approach segment and the first retract segment after it (kind from the file, or
/// from the height's direction when unknown; pauses ignored). Throws InvalidParameter "spring_constant" / "invols"
/// when a value needed is missing (naming the option that supplies it), not finite or ≤ 0; InputError naming the
/// curve's origin for a curve without an approach or a retract segment, a segment with fewer than 2 samples or
/// without height, non-finite samples, or a non-monotone piezo height (a step back by more than 1 % of the
/// segment's height range against its direction).
CalibratedCurve calibrate(const io::curves::RawCurve& raw, const Calibration& user = {});

}  // namespace afmkit::spectroscopy
