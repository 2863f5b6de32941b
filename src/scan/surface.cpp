#include "afmkit/scan/surface.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::scan {

Tilt::Tilt(double angle_, double azimuth_) : angle(angle_), azimuth(azimuth_) {
  validate::require(std::isfinite(angle) && angle >= 0.0 && angle < std::numbers::pi / 2, "tilt_angle", angle,
                    "in [0, 90) degrees, i.e. 0 <= angle < pi/2 rad");
  validate::finite("tilt_azimuth", azimuth);
}

double Tilt::height(double x, double y) const noexcept {
  return std::tan(angle) * (x * std::cos(azimuth) + y * std::sin(azimuth));
}

double Tilt::slope() const noexcept { return std::tan(angle); }

Surface::Surface(HeightMap topography, Tilt tilt) : map_(std::move(topography)), tilt_(tilt.angle, tilt.azimuth) {
  if (map_.valid_count() != map_.size())
    throw InvalidParameter("sample", fmt::format("the sample topography has {} invalid pixels of {}: every pixel "
                                                 "must be valid",
                                                 map_.size() - map_.valid_count(), map_.size()));
  if (map_.z_unit() != "m")
    throw InvalidParameter("sample", fmt::format("the sample topography has z_unit \"{}\": must be \"m\" (heights)",
                                                 map_.z_unit()));
  const long columns = map_.x_resolution();
  const long rows = map_.y_resolution();
  x_first_ = map_.x_offset() + 0.5 * map_.dx();
  y_first_ = map_.y_offset() + 0.5 * map_.dy();
  inv_dx_ = 1.0 / map_.dx();
  inv_dy_ = 1.0 / map_.dy();
  u_max_ = static_cast<double>(columns - 1);
  v_max_ = static_cast<double>(rows - 1);
  i_max_ = std::max(columns - 2, 0L);
  j_max_ = std::max(rows - 2, 0L);
  row_stride_ = columns;
  column_step_ = columns >= 2 ? 1 : 0;
  row_step_ = rows >= 2 ? columns : 0;
  const double slope = std::tan(tilt_.angle);
  slope_x_ = slope * std::cos(tilt_.azimuth);
  slope_y_ = slope * std::sin(tilt_.azimuth);
}

double Surface::inscribed_radius() const noexcept {
  const double left = x_first_;
  const double right = x_first_ + u_max_ * map_.dx();
  const double top = y_first_;
  const double bottom = y_first_ + v_max_ * map_.dy();
  const double radius = std::min({-left, right, -top, bottom});
  return radius > 0.0 ? radius : 0.0;
}

}  // namespace afmkit::scan
