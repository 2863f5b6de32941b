#pragma once
// The sample of a rotational-scanning AFM as the tip sees it: a topography (a height map) plus the tilt of the
// sample plane, evaluated at any point of the map's frame (x right, y down, metres — the frame of Grid).
#include <utility>

#include "afmkit/scan/height_map.hpp"

namespace afmkit::scan {

/// Sample tilt: the sample is tilted by `angle` ψ [rad] from the spindle axis, towards `azimuth` φ_t [rad]:
///   tilt height at (x, y) = tan ψ · (x cos φ_t + y sin φ_t),
/// so the tilted plane rises along the direction φ_t (measured from +x towards +y of the map frame) with slope tan ψ;
/// with z up, its normal (−tan ψ cos φ_t, −tan ψ sin φ_t, 1) leans from the spindle axis by ψ towards φ_t + π.
/// The fields are public; the constructor validates: 0 ≤ angle < π/2 (InvalidParameter "tilt_angle"),
/// azimuth finite ("tilt_azimuth"). Surface re-validates whatever it is given.
struct Tilt {
  double angle = 0.0;    ///< ψ [rad], in [0, π/2)
  double azimuth = 0.0;  ///< φ_t [rad], any finite value

  Tilt() = default;
  Tilt(double angle, double azimuth);
  /// tan ψ · (x cos φ_t + y sin φ_t) [m] at (x, y) [m].
  double height(double x, double y) const noexcept;
  /// tan ψ: the largest slope of the tilted plane.
  double slope() const noexcept;
};

/// Topography plus tilt, evaluated anywhere in the map's frame.
///   * Between pixel centres: bilinear interpolation of the four surrounding centres (exact on planes).
///   * Outside the rectangle of pixel centres: the nearest point of that rectangle is used (edge values clamped),
///     so a point beyond a corner gets the corner value. Infinite coordinates clamp likewise; a NaN coordinate is
///     treated as the first pixel-centre coordinate (never undefined behaviour).
///   * The tilt is added exactly as Tilt::height (not clamped).
/// topography() and operator() are noexcept and allocation-free (called once per simulated sample).
class Surface {
 public:
  /// InvalidParameter("sample", …) if the map has an invalid pixel or its z_unit is not "m";
  /// "tilt_angle" / "tilt_azimuth" as Tilt's constructor.
  Surface(HeightMap topography, Tilt tilt);

  /// Bilinearly interpolated (edge-clamped) topography [m] at (x, y) [m].
  double topography(double x, double y) const noexcept {
    // Continuous pixel coordinates: u = 0 at the centre of column 0, u = x_resolution − 1 at the last one.
    double u = (x - x_first_) * inv_dx_;
    double v = (y - y_first_) * inv_dy_;
    u = u > 0.0 ? u : 0.0;  // also maps NaN to 0
    v = v > 0.0 ? v : 0.0;
    u = u < u_max_ ? u : u_max_;
    v = v < v_max_ ? v : v_max_;
    long i = static_cast<long>(u);  // u >= 0: truncation = floor
    long j = static_cast<long>(v);
    i = i < i_max_ ? i : i_max_;  // keep i + 1 inside (i_max_ = x_resolution − 2, or 0 with one column)
    j = j < j_max_ ? j : j_max_;
    const double t = u - static_cast<double>(i);
    const double s = v - static_cast<double>(j);
    const double* p = map_.data().data() + j * row_stride_ + i;
    // Weights (1 − t, t): exact at the nodes, so clamped edges and corners give the pixel values exactly.
    const double top = (1.0 - t) * p[0] + t * p[column_step_];
    const double bottom = (1.0 - t) * p[row_step_] + t * p[row_step_ + column_step_];
    return (1.0 - s) * top + s * bottom;
  }
  /// Topography plus tilt height [m] at (x, y) [m].
  double operator()(double x, double y) const noexcept {
    return topography(x, y) + slope_x_ * x + slope_y_ * y;
  }

  const HeightMap& map() const& { return map_; }
  HeightMap map() && { return std::move(map_); }  // a temporary gives its map
  const Tilt& tilt() const& { return tilt_; }

  /// Largest radius R such that the disc of radius R about (0, 0) lies inside the rectangle of pixel centres
  /// (0 if the origin is outside it). The part of a rotational scan that needs no edge clamping.
  double inscribed_radius() const noexcept;

 private:
  HeightMap map_;
  Tilt tilt_;
  double x_first_ = 0, y_first_ = 0;  // centre of pixel (0, 0) [m]
  double inv_dx_ = 1, inv_dy_ = 1;    // 1 / pixel size [1/m]
  double u_max_ = 0, v_max_ = 0;      // x_resolution − 1, y_resolution − 1
  long i_max_ = 0, j_max_ = 0;        // max(x_resolution − 2, 0), max(y_resolution − 2, 0)
  long row_stride_ = 0;               // x_resolution
  long column_step_ = 0, row_step_ = 0;  // offset to the right / lower neighbour (0 with one column / row)
  double slope_x_ = 0, slope_y_ = 0;  // tan ψ cos φ_t, tan ψ sin φ_t
};

}  // namespace afmkit::scan
