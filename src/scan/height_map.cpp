#include "afmkit/scan/height_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "file_bytes.hpp"

namespace afmkit::scan {

void validate_grid(const Grid& grid) {
  validate::require(grid.x_resolution >= 1, "x_resolution", static_cast<double>(grid.x_resolution), "an integer >= 1");
  validate::require(grid.y_resolution >= 1, "y_resolution", static_cast<double>(grid.y_resolution), "an integer >= 1");
  validate::positive("x_size", grid.x_size);
  validate::positive("y_size", grid.y_size);
  validate::finite("x_offset", grid.x_offset);
  validate::finite("y_offset", grid.y_offset);
}

HeightMap::HeightMap(const Grid& grid, std::vector<double> data, std::string z_unit, std::vector<std::uint8_t> valid)
    : grid_(grid), data_(std::move(data)), z_unit_(std::move(z_unit)), valid_(std::move(valid)) {
  validate_grid(grid_);
  detail::check_header_text("z_unit", z_unit_);
  const auto columns = static_cast<unsigned long>(grid_.x_resolution);
  const auto rows = static_cast<unsigned long>(grid_.y_resolution);
  if (columns > data_.size() / rows || columns * rows != data_.size())
    throw InvalidParameter("data", fmt::format("data has {} values, but x_resolution · y_resolution = {} · {}",
                                               data_.size(), columns, rows));
  if (!valid_.empty() && valid_.size() != data_.size())
    throw InvalidParameter("valid", fmt::format("valid has {} entries, but the map has {} pixels ({} · {})",
                                                valid_.size(), data_.size(), columns, rows));
  for (std::size_t k = 0; k < data_.size(); ++k) {
    const bool is_valid = valid_.empty() || valid_[k] == 1;
    if (!valid_.empty() && valid_[k] > 1)
      throw InvalidParameter("valid", fmt::format("valid[{}] = {}: must be 1 (valid) or 0 (invalid)", k, valid_[k]));
    if (!is_valid) {
      data_[k] = std::numeric_limits<double>::quiet_NaN();
    } else if (!std::isfinite(data_[k])) {
      throw InvalidParameter("data", fmt::format("data[{}] (column {}, row {}) = {} at a valid pixel: must be finite "
                                                 "(mark the pixel invalid instead)",
                                                 k, k % columns, k / columns, data_[k]));
    }
  }
}

std::size_t HeightMap::valid_count() const {
  if (valid_.empty()) return data_.size();
  return static_cast<std::size_t>(std::count(valid_.begin(), valid_.end(), std::uint8_t{1}));
}

}  // namespace afmkit::scan
