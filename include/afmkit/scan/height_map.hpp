#pragma once
// A height map: a regular grid of values (heights, or any other channel) over a rectangle of the sample plane,
// with an optional per-pixel validity mask (a rotational scan covers a disc: the pixels outside it are invalid).
//
// Layout (the Gwyddion convention, so files written from it open the right way up):
//   * data is row-major: value of column i (x), row j (y) at data[j · x_resolution + i]; row 0 is the top row of
//     the image, and y grows downwards (Gwyddion draws row 0 at the top, its y axis pointing down);
//   * pixel (i, j) covers x in [x_offset + i·dx, x_offset + (i+1)·dx), dx = x_size / x_resolution, and likewise y;
//   * x_size, y_size, x_offset, y_offset are in metres; z_unit names the unit of the values ("m" for heights,
//     "V", "deg", "" for dimensionless).
// Invariant: a pixel is valid exactly when its value is finite. Invalid pixels hold NaN (the constructor writes it),
// so no computation can use them by accident.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace afmkit::scan {

/// The rectangle a height map covers and its pixel counts.
struct Grid {
  long x_resolution = 1;  ///< pixels per row (columns), >= 1
  long y_resolution = 1;  ///< rows, >= 1
  double x_size = 1.0;    ///< width of the rectangle [m], > 0
  double y_size = 1.0;    ///< height of the rectangle [m], > 0
  double x_offset = 0.0;  ///< x of the left edge [m]
  double y_offset = 0.0;  ///< y of the top edge [m]
};

/// InvalidParameter naming the field: x_resolution / y_resolution < 1; x_size / y_size not positive and finite;
/// x_offset / y_offset not finite.
void validate_grid(const Grid& grid);

class HeightMap {
 public:
  /// Validates and stores. InvalidParameter naming the field: x_resolution / y_resolution < 1; x_size / y_size not
  /// positive and finite; x_offset / y_offset not finite; data size != x_resolution · y_resolution; valid given
  /// with a different size or a value other than 0 / 1; a non-finite value at a valid pixel ("data"); z_unit with
  /// a control character or a leading / trailing blank. `valid` empty = every pixel valid (then every value must
  /// be finite); otherwise 1 = valid, 0 = invalid (its value is replaced by NaN).
  HeightMap(const Grid& grid, std::vector<double> data, std::string z_unit = "m", std::vector<std::uint8_t> valid = {});

  const Grid& grid() const& { return grid_; }
  Grid grid() && { return std::move(grid_); }  // a temporary gives its value
  long x_resolution() const { return grid_.x_resolution; }
  long y_resolution() const { return grid_.y_resolution; }
  double x_size() const { return grid_.x_size; }
  double y_size() const { return grid_.y_size; }
  double x_offset() const { return grid_.x_offset; }
  double y_offset() const { return grid_.y_offset; }
  double dx() const { return grid_.x_size / static_cast<double>(grid_.x_resolution); }  ///< pixel width [m]
  double dy() const { return grid_.y_size / static_cast<double>(grid_.y_resolution); }  ///< pixel height [m]
  const std::string& z_unit() const& { return z_unit_; }
  std::string z_unit() && { return std::move(z_unit_); }  // a temporary gives its value
  std::size_t size() const { return data_.size(); }

  /// Row-major values (NaN at invalid pixels).
  const std::vector<double>& data() const& { return data_; }
  std::vector<double> data() && { return std::move(data_); }  // a temporary gives its value
  /// Value at column i, row j (unchecked).
  double operator()(long i, long j) const { return data_[static_cast<std::size_t>(j * grid_.x_resolution + i)]; }
  /// Whether the map was given a mask (even one with every pixel valid).
  bool has_mask() const { return !valid_.empty(); }
  /// Mask: 1 valid, 0 invalid, row-major; empty when the map has none (every pixel valid).
  const std::vector<std::uint8_t>& mask() const& { return valid_; }
  std::vector<std::uint8_t> mask() && { return std::move(valid_); }  // a temporary gives its value
  bool valid(long i, long j) const {
    return valid_.empty() || valid_[static_cast<std::size_t>(j * grid_.x_resolution + i)] != 0;
  }
  std::size_t valid_count() const;

 private:
  Grid grid_;
  std::vector<double> data_;
  std::string z_unit_;
  std::vector<std::uint8_t> valid_;
};

}  // namespace afmkit::scan
