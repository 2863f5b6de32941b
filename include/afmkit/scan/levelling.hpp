#pragma once
// Plane levelling of height maps (the usual first correction of an AFM image) and the image-versus-truth error
// measure of the virtual scanner.
#include "afmkit/scan/height_map.hpp"

namespace afmkit::scan {

/// The plane z = a + b x + c y (x, y in metres of the map frame; a in the map's z unit, b and c per metre).
struct Plane {
  double a = 0, b = 0, c = 0;
  double operator()(double x, double y) const noexcept { return a + b * x + c * y; }
};

/// Least-squares plane through the valid pixels, at their pixel-centre coordinates x_i = x_offset + (i + ½)·dx,
/// y_j = y_offset + (j + ½)·dy. Solved in pixel-index coordinates centred on the valid pixels' mean (well
/// conditioned whatever the offsets). InvalidParameter("map") with fewer than 3 valid pixels or with all valid
/// pixels on one straight line.
Plane fit_plane(const HeightMap& map);

/// map − plane at the valid pixels (pixel centres); invalid pixels stay invalid; grid, z_unit and mask kept.
HeightMap subtract_plane(const HeightMap& map, const Plane& plane);

/// subtract_plane(map, fit_plane(map)).
HeightMap level(const HeightMap& map);

/// RMS of (image − truth) over the pixels valid in both, after levelling each by its own least-squares plane fitted
/// over those common pixels (the same levelling applied to the image and to the ground truth, so a tilt or offset
/// the scan adds is not counted). Because the fit is linear this equals the RMS residual of a plane fit to
/// image − truth over the common pixels. InvalidParameter("map") if the grids differ (resolutions not equal, or
/// sizes / offsets differing by more than 1e-9 of the map size), if there are fewer than 3 common valid pixels or
/// they lie on one line.
double levelled_rms_difference(const HeightMap& image, const HeightMap& truth);

}  // namespace afmkit::scan
