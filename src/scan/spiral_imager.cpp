// Spiral scan stream → Cartesian image (spiral_imager.hpp: algorithm, error bound).
#include "afmkit/scan/spiral_imager.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "afmkit/core/numbers.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "file_bytes.hpp"

namespace afmkit::scan {

namespace {

using afmkit::numbers::two_pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMaxTablePosition = 9007199254740992.0;  // 2^53: table indices stay exact in a double
constexpr int kMinTable = 16;
constexpr int kMaxTable = 1 << 22;

Grid checked(const Grid& grid) {
  validate_grid(grid);
  constexpr long kMaxPixels = std::numeric_limits<std::uint32_t>::max();
  if (grid.x_resolution > kMaxPixels / grid.y_resolution)
    throw InvalidParameter("x_resolution",
                           fmt::format("x_resolution · y_resolution = {} · {} is out of range: the imager indexes at "
                                       "most 2^32 − 1 pixels",
                                       grid.x_resolution, grid.y_resolution));
  return grid;
}

std::vector<std::string> checked_units(std::vector<std::string> units) {
  if (units.empty())
    throw InvalidParameter("channel_units", "channel_units is empty: must name one unit per channel (>= 1 channel)");
  for (const std::string& u : units) detail::check_header_text("channel_units", u);
  return units;
}

int checked_table(int m) {
  validate::in_range("angular_samples", static_cast<long>(m), static_cast<long>(kMinTable),
                     static_cast<long>(kMaxTable));
  return m;
}

}  // namespace

SpiralImager::SpiralImager(const Grid& grid, std::vector<std::string> channel_units, int angular_samples)
    : grid_(checked(grid)), units_(checked_units(std::move(channel_units))), table_size_(checked_table(angular_samples)) {
  const long columns = grid_.x_resolution;
  const auto pixels = static_cast<std::size_t>(columns * grid_.y_resolution);
  const double dx = grid_.x_size / static_cast<double>(columns);
  const double dy = grid_.y_size / static_cast<double>(grid_.y_resolution);
  auto centre = [&](std::size_t k) {
    const auto i = static_cast<double>(static_cast<long>(k) % columns);
    const auto j = static_cast<double>(static_cast<long>(k) / columns);
    return std::pair{grid_.x_offset + (i + 0.5) * dx, grid_.y_offset + (j + 0.5) * dy};
  };

  // Pixel centres sorted by distance from the spindle axis (the origin): a bucket sort (buckets of equal width in ρ,
  // about 32 pixels each, in ρ order since the bucket index is monotone in ρ), then each bucket sorted.
  const double extent = std::max({std::abs(grid_.x_offset), std::abs(grid_.x_offset + grid_.x_size),
                                  std::abs(grid_.y_offset), std::abs(grid_.y_offset + grid_.y_size)});
  const bool plain = extent < 1e150;  // x² + y² cannot overflow
  pixel_radius_.resize(pixels);
  for (std::size_t k = 0; k < pixels; ++k) {
    const auto [x, y] = centre(k);
    pixel_radius_[k] = plain ? std::sqrt(x * x + y * y) : std::hypot(x, y);
  }
  {
    const auto [lo_it, hi_it] = std::minmax_element(pixel_radius_.begin(), pixel_radius_.end());
    const double lo = *lo_it, width = *hi_it - *lo_it;
    const std::size_t buckets = std::max<std::size_t>(1, pixels / 32);
    const double per_width = width > 0 && std::isfinite(width) ? static_cast<double>(buckets) / width : 0.0;
    auto bucket = [&](double rho) {
      const double b = (rho - lo) * per_width;  // monotone in ρ
      return b < static_cast<double>(buckets - 1) ? static_cast<std::size_t>(b) : buckets - 1;
    };
    std::vector<std::size_t> start(buckets + 1, 0);
    for (double rho : pixel_radius_) ++start[bucket(rho) + 1];
    for (std::size_t b = 0; b < buckets; ++b) start[b + 1] += start[b];
    std::vector<std::pair<double, std::uint32_t>> order(pixels);
    {
      std::vector<std::size_t> fill(start.begin(), start.end() - 1);
      for (std::size_t k = 0; k < pixels; ++k)
        order[fill[bucket(pixel_radius_[k])]++] = {pixel_radius_[k], static_cast<std::uint32_t>(k)};
    }
    for (std::size_t b = 0; b < buckets; ++b)
      std::sort(order.begin() + static_cast<std::ptrdiff_t>(start[b]),
                order.begin() + static_cast<std::ptrdiff_t>(start[b + 1]));
    pixel_angle_.resize(pixels);
    pixel_index_.resize(pixels);
    for (std::size_t n = 0; n < pixels; ++n) {
      const auto [x, y] = centre(order[n].second);
      double a = std::atan2(y, x);
      if (a < 0) a += two_pi;
      pixel_radius_[n] = order[n].first;
      pixel_angle_[n] = a;
      pixel_index_[n] = order[n].second;
    }
  }
  images_.assign(units_.size(), std::vector<double>(pixels, kNaN));
  const std::size_t table = (units_.size() + 1) * static_cast<std::size_t>(table_size_ + 1);
  lower_.assign(table, kNaN);
  upper_.assign(table, kNaN);
  last_values_.assign(units_.size(), kNaN);
  per_radian_ = static_cast<double>(table_size_) / two_pi;
}

void SpiralImager::add(double angle, double radius, std::span<const double> values) {
  if (finished_) throw std::logic_error("SpiralImager::add called after finish()");
  const std::size_t channels = units_.size();
  if (values.size() != channels)
    throw InvalidParameter("values", fmt::format("values has {} entries: must have one per channel ({})",
                                                 values.size(), channels));
  if (!(std::isfinite(radius) && radius >= 0.0))
    throw InvalidParameter("radius", fmt::format("radius = {} m is out of range: must be finite and >= 0", radius));
  if (!std::isfinite(angle))
    throw InvalidParameter("angle", fmt::format("angle = {} rad is out of range: must be finite", angle));
  const std::size_t stride = static_cast<std::size_t>(table_size_ + 1);

  if (samples_ == 0) {
    first_angle_ = angle;
    first_phase_ = angle - two_pi * std::floor(angle / two_pi);
    if (!(first_phase_ < two_pi)) first_phase_ = 0.0;  // rounding of a tiny negative angle
    upper_[0] = radius;
    for (std::size_t c = 0; c < channels; ++c) upper_[(c + 1) * stride] = values[c];
    next_entry_ = 1;
    next_column_ = 1;
    last_position_ = 0.0;
  } else {
    if (!(angle > last_angle_))
      throw InvalidParameter("angle", fmt::format("angle = {} rad is out of range: the unwrapped angle must increase "
                                                  "strictly (previous sample: {} rad)",
                                                  angle, last_angle_));
    const double position = (angle - first_angle_) * per_radian_;  // s
    if (!(position < kMaxTablePosition))
      throw InvalidParameter("angle", fmt::format("angle = {} rad is out of range: must be < first angle {} rad + "
                                                  "2π·2^53/angular_samples",
                                                  angle, first_angle_));
    const double span = position - last_position_;
    while (static_cast<double>(next_entry_) <= position) {
      // span > 0 here: next_entry_ > last_position_ (every entry <= last_position_ is written).
      const double w = (static_cast<double>(next_entry_) - last_position_) / span;
      const auto j = static_cast<std::size_t>(next_column_);
      upper_[j] = last_radius_ + w * (radius - last_radius_);
      for (std::size_t c = 0; c < channels; ++c) {
        const double a = last_values_[c];
        upper_[(c + 1) * stride + j] = a + w * (values[c] - a);
      }
      ++next_entry_;
      ++next_column_;
      if (next_column_ > table_size_) complete_turn();
    }
    last_position_ = position;
  }
  last_angle_ = angle;
  last_radius_ = radius;
  for (std::size_t c = 0; c < channels; ++c) last_values_[c] = values[c];
  ++samples_;
}

// upper_ holds turn turn_ completely (entries 0 … M): fill its strip, then start turn turn_ + 1.
void SpiralImager::complete_turn() {
  if (turn_ == 0) {
    fill_centre();
  } else {
    fill_strip(lower_, upper_, table_size_, static_cast<double>(table_size_));
  }
  std::swap(lower_, upper_);
  const std::size_t stride = static_cast<std::size_t>(table_size_ + 1);
  for (std::size_t r = 0; r <= units_.size(); ++r) upper_[r * stride] = lower_[r * stride + stride - 1];
  ++turn_;
  next_column_ = 1;
}

// Rule 3 of the header: lower_ (free while turn 0 completes) becomes the centre point, r = 0, values v_c.
void SpiralImager::fill_centre() {
  const std::size_t stride = static_cast<std::size_t>(table_size_ + 1);
  const double* r = upper_.data();
  const double pitch = r[table_size_] - r[0];
  const double r_min = *std::min_element(r, r + stride);
  const double r_max = *std::max_element(r, r + stride);
  if (!(pitch > 0.0 && r_min <= pitch)) return;

  std::fill(lower_.begin(), lower_.begin() + static_cast<std::ptrdiff_t>(stride), 0.0);
  for (std::size_t c = 0; c < units_.size(); ++c) {
    // Least-squares plane value + a·x + b·y through the finite points of turn 0 (coordinates scaled by 1/r_max).
    const double* v = upper_.data() + (c + 1) * stride;
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < stride; ++j) {
      if (!std::isfinite(v[j])) continue;
      const double phi = first_angle_ + static_cast<double>(j) / per_radian_;
      const Eigen::Vector3d basis(1.0, r[j] / r_max * std::cos(phi), r[j] / r_max * std::sin(phi));
      normal += basis * basis.transpose();
      rhs += basis * v[j];
    }
    Eigen::FullPivLU<Eigen::Matrix3d> lu(normal);
    lu.setThreshold(1e-10);
    const double centre = lu.rank() == 3 ? lu.solve(rhs)(0) : kNaN;
    std::fill_n(lower_.begin() + static_cast<std::ptrdiff_t>((c + 1) * stride), stride, centre);
  }
  fill_strip(lower_, upper_, table_size_, static_cast<double>(table_size_));
  centre_filled_ = true;
}

// Fills the pixels between the curves `lower` (complete, entries 0 … M) and `upper`, whose entries 0 … n
// (n = upper_uniform_end) sit at table coordinates 0 … n, and, when upper_end > n, entry n + 1 at upper_end.
// Only pixels with table coordinate u <= upper_end are considered.
void SpiralImager::fill_strip(const std::vector<double>& lower, const std::vector<double>& upper,
                              long upper_uniform_end, double upper_end) {
  const long m = table_size_;
  const std::size_t stride = static_cast<std::size_t>(m + 1);
  const long n = upper_uniform_end;
  const bool extra = upper_end > static_cast<double>(n);
  const std::size_t upper_points = static_cast<std::size_t>(n) + (extra ? 2 : 1);
  if (upper_points < 2) return;

  const double* lr = lower.data();
  const double* ur = upper.data();
  const auto [l_lo, l_hi] = std::minmax_element(lr, lr + stride);
  const auto [u_lo, u_hi] = std::minmax_element(ur, ur + upper_points);
  const double lo = std::min(*l_lo, *u_lo);
  const double hi = std::max(*l_hi, *u_hi);
  const double mm = static_cast<double>(m);
  const double nn = static_cast<double>(n);
  const std::size_t channels = units_.size();

  const auto begin = std::lower_bound(pixel_radius_.begin(), pixel_radius_.end(), lo) - pixel_radius_.begin();
  const auto count = static_cast<std::ptrdiff_t>(pixel_radius_.size());
  for (std::ptrdiff_t p = begin; p < count; ++p) {
    const double rho = pixel_radius_[static_cast<std::size_t>(p)];
    if (!(rho < hi)) break;
    double u = pixel_angle_[static_cast<std::size_t>(p)] - first_phase_;
    if (u < 0) u += two_pi;
    u = std::min(u * per_radian_, mm);  // table coordinate in [0, M]
    if (u > upper_end) continue;

    const std::size_t ja = static_cast<std::size_t>(std::min(static_cast<long>(u), m - 1));
    const double fa = u - static_cast<double>(ja);
    std::size_t jb = 0;
    double fb = 0.0;
    if (u < nn) {
      jb = static_cast<std::size_t>(u);
      fb = u - static_cast<double>(jb);
    } else if (extra) {
      jb = static_cast<std::size_t>(n);
      fb = (u - nn) / (upper_end - nn);
    } else {  // u == n == upper_end, n >= 1
      jb = static_cast<std::size_t>(n - 1);
      fb = 1.0;
    }
    const double ra = lr[ja] + fa * (lr[ja + 1] - lr[ja]);
    const double rb = ur[jb] + fb * (ur[jb + 1] - ur[jb]);
    if (!(rho >= std::min(ra, rb) && rho < std::max(ra, rb))) continue;
    const double t = (rho - ra) / (rb - ra);
    const std::size_t pixel = pixel_index_[static_cast<std::size_t>(p)];
    for (std::size_t c = 0; c < channels; ++c) {
      const double* la = lr + (c + 1) * stride;
      const double* ub = ur + (c + 1) * stride;
      const double va = la[ja] + fa * (la[ja + 1] - la[ja]);
      const double vb = ub[jb] + fb * (ub[jb + 1] - ub[jb]);
      images_[c][pixel] = va + t * (vb - va);
    }
  }
}

std::vector<HeightMap> SpiralImager::finish() {
  if (finished_) throw std::logic_error("SpiralImager::finish called twice");
  finished_ = true;
  if (turn_ >= 1) {
    // The partial turn: entries 0 … n written, the last sample (table coordinate u_end >= n) as a final point.
    const long n = next_column_ - 1;
    const double u_end = last_position_ - static_cast<double>(turn_) * static_cast<double>(table_size_);
    if (u_end > static_cast<double>(n)) {
      const std::size_t stride = static_cast<std::size_t>(table_size_ + 1);
      const auto j = static_cast<std::size_t>(n + 1);
      upper_[j] = last_radius_;
      for (std::size_t c = 0; c < units_.size(); ++c) upper_[(c + 1) * stride + j] = last_values_[c];
    }
    fill_strip(lower_, upper_, n, std::max(u_end, static_cast<double>(n)));
  }
  std::vector<HeightMap> out;
  out.reserve(units_.size());
  for (std::size_t c = 0; c < units_.size(); ++c) {
    std::vector<double>& data = images_[c];
    std::vector<std::uint8_t> valid(data.size());
    for (std::size_t k = 0; k < data.size(); ++k) valid[k] = std::isfinite(data[k]) ? 1 : 0;
    out.emplace_back(grid_, std::move(data), units_[c], std::move(valid));
  }
  // the imager is spent: release its pixel table and turn tables now (a caller may keep the object alive)
  pixel_radius_ = {};
  pixel_angle_ = {};
  pixel_index_ = {};
  images_ = {};
  lower_ = {};
  upper_ = {};
  return out;
}

}  // namespace afmkit::scan
