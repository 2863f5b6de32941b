#include "afmkit/io/table.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace afmkit::io {

namespace {
bool same_value(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }
}  // namespace

GridRecord::GridRecord(std::vector<GridDimension> grid) : grid_(std::move(grid)), stride_(grid_.size(), 1),
                                                          coords_(grid_.size()) {
  for (std::size_t d = grid_.size(); d-- > 1;) stride_[d - 1] = stride_[d] * grid_[d].size;  // the last fastest
}

void GridRecord::value(std::size_t d, double v) {
  const std::size_t index = grid_[d].size == 0 ? 0 : (rows_ / stride_[d]) % grid_[d].size;
  std::vector<double>& axis = coords_[d];
  if (index == axis.size() && rows_ / stride_[0] < grid_[0].size) {
    axis.push_back(v);  // first row at this point of the dimension
  } else if (index >= axis.size() || !same_value(axis[index], v)) {
    throw std::logic_error(fmt::format("row {} of a table declared as a grid is not at its grid point (column {})",
                                       rows_, grid_[d].column));
  }
}

nlohmann::json GridRecord::json() const {
  std::size_t points = 1;
  for (const GridDimension& d : grid_) points *= d.size;
  if (rows_ != points)
    throw std::logic_error(fmt::format("a table declared as a grid of {} points has {} rows", points, rows_));
  nlohmann::json dims = nlohmann::json::array(), columns = nlohmann::json::array(), shape = nlohmann::json::array();
  nlohmann::json coords = nlohmann::json::object();
  for (std::size_t d = 0; d < grid_.size(); ++d) {
    dims.push_back(grid_[d].name);
    columns.push_back(grid_[d].column);
    shape.push_back(grid_[d].size);
    coords[grid_[d].name] = coords_[d];
  }
  return {{"dims", dims}, {"columns", columns}, {"shape", shape}, {"coords", finite_json(coords)}};
}

}  // namespace afmkit::io
