#include "afmkit/scan/levelling.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::scan {
namespace {

// Least-squares plane z = a + b x + c y through the pixels where `use(k)` holds (k = row-major index; the caller
// guarantees their values are finite). Fitted as z = A + B (i − ī) + C (j − j̄) in pixel indices, centred on the
// used pixels' mean index (ī, j̄), then converted to metres.
template <class Use>
Plane fit_over(const HeightMap& map, const char* pixels, Use&& use) {
  const long columns = map.x_resolution();
  const long rows = map.y_resolution();
  const std::vector<double>& z = map.data();
  // Pass 1: count and mean index / value.
  double count = 0, sum_i = 0, sum_j = 0, sum_z = 0;
  for (long j = 0; j < rows; ++j)
    for (long i = 0; i < columns; ++i) {
      const auto k = static_cast<std::size_t>(j * columns + i);
      if (!use(k)) continue;
      count += 1;
      sum_i += static_cast<double>(i);
      sum_j += static_cast<double>(j);
      sum_z += z[k];
    }
  if (count < 3)
    throw InvalidParameter("map", fmt::format("map: a plane fit needs at least 3 {}; there are {}", pixels, count));
  const double mean_i = sum_i / count, mean_j = sum_j / count, mean_z = sum_z / count;
  // Pass 2: centred second moments.
  double s_ii = 0, s_jj = 0, s_ij = 0, s_iz = 0, s_jz = 0;
  for (long j = 0; j < rows; ++j) {
    const double dj = static_cast<double>(j) - mean_j;
    for (long i = 0; i < columns; ++i) {
      const auto k = static_cast<std::size_t>(j * columns + i);
      if (!use(k)) continue;
      const double di = static_cast<double>(i) - mean_i;
      const double dz = z[k] - mean_z;
      s_ii += di * di;
      s_jj += dj * dj;
      s_ij += di * dj;
      s_iz += di * dz;
      s_jz += dj * dz;
    }
  }
  // Normal equations [s_ii s_ij; s_ij s_jj] [B; C] = [s_iz; s_jz]. Points on a line make the matrix singular
  // (Cauchy–Schwarz equality); the relative threshold is far above rounding (~1e-16 · pixels) and far below any
  // non-degenerate set (e.g. 3 pixels in an L give 0.75).
  const double determinant = s_ii * s_jj - s_ij * s_ij;
  if (!(determinant > 1e-9 * s_ii * s_jj))
    throw InvalidParameter("map", fmt::format("map: a plane fit needs {} that are not all on one straight line; "
                                              "the {} there are lie on one line",
                                              pixels, count));
  const double slope_i = (s_iz * s_jj - s_jz * s_ij) / determinant;  // B, per column
  const double slope_j = (s_jz * s_ii - s_iz * s_ij) / determinant;  // C, per row
  // x = x_first + i·dx  =>  B (i − ī) = (B/dx)(x − x̄) with x̄ = x_first + ī·dx; likewise y.
  const double x_mean = map.x_offset() + (mean_i + 0.5) * map.dx();
  const double y_mean = map.y_offset() + (mean_j + 0.5) * map.dy();
  Plane plane;
  plane.b = slope_i / map.dx();
  plane.c = slope_j / map.dy();
  plane.a = mean_z - plane.b * x_mean - plane.c * y_mean;
  return plane;
}

bool same_grid(const Grid& p, const Grid& q) {
  const auto close = [](double u, double v, double scale) { return std::abs(u - v) <= 1e-9 * scale; };
  return p.x_resolution == q.x_resolution && p.y_resolution == q.y_resolution &&
         close(p.x_size, q.x_size, p.x_size) && close(p.y_size, q.y_size, p.y_size) &&
         close(p.x_offset, q.x_offset, p.x_size) && close(p.y_offset, q.y_offset, p.y_size);
}

}  // namespace

Plane fit_plane(const HeightMap& map) {
  const std::vector<double>& z = map.data();
  return fit_over(map, "valid pixels", [&z](std::size_t k) { return std::isfinite(z[k]); });  // finite = valid (HeightMap invariant)
}

HeightMap subtract_plane(const HeightMap& map, const Plane& plane) {
  std::vector<double> data = map.data();
  const long columns = map.x_resolution();
  const double dx = map.dx(), dy = map.dy();
  for (long j = 0; j < map.y_resolution(); ++j) {
    const double y = map.y_offset() + (static_cast<double>(j) + 0.5) * dy;
    for (long i = 0; i < columns; ++i)
      data[static_cast<std::size_t>(j * columns + i)] -= plane(map.x_offset() + (static_cast<double>(i) + 0.5) * dx, y);
  }  // NaN − plane stays NaN; the mask is passed on
  return HeightMap(map.grid(), std::move(data), map.z_unit(), map.mask());
}

HeightMap level(const HeightMap& map) { return subtract_plane(map, fit_plane(map)); }

double levelled_rms_difference(const HeightMap& image, const HeightMap& truth) {
  if (!same_grid(image.grid(), truth.grid()))
    throw InvalidParameter(
        "map", fmt::format("map: the image grid ({} × {} pixels, {:g} m × {:g} m at ({:g}, {:g}) m) differs from the truth "
                           "grid ({} × {}, {:g} m × {:g} m at ({:g}, {:g}) m): they must be the same",
                           image.x_resolution(), image.y_resolution(), image.x_size(), image.y_size(),
                           image.x_offset(), image.y_offset(), truth.x_resolution(), truth.y_resolution(),
                           truth.x_size(), truth.y_size(), truth.x_offset(), truth.y_offset()));
  const std::vector<double>& a = image.data();
  const std::vector<double>& b = truth.data();
  const auto common = [&](std::size_t k) { return std::isfinite(a[k]) && std::isfinite(b[k]); };
  const Plane plane_a = fit_over(image, "pixels valid in both image and truth", common);
  const Plane plane_b = fit_over(truth, "pixels valid in both image and truth", common);
  const long columns = image.x_resolution();
  const double dx = image.dx(), dy = image.dy();
  double sum_squares = 0, count = 0;
  for (long j = 0; j < image.y_resolution(); ++j) {
    const double y = image.y_offset() + (static_cast<double>(j) + 0.5) * dy;
    for (long i = 0; i < columns; ++i) {
      const auto k = static_cast<std::size_t>(j * columns + i);
      if (!common(k)) continue;
      const double x = image.x_offset() + (static_cast<double>(i) + 0.5) * dx;
      const double difference = (a[k] - plane_a(x, y)) - (b[k] - plane_b(x, y));
      sum_squares += difference * difference;
      count += 1;
    }
  }
  return std::sqrt(sum_squares / count);
}

}  // namespace afmkit::scan
