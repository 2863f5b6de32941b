#pragma once
// A table declared once: each column carries its name, unit, description and how its value is read from a row
// (docs/development.md#where-new-code-goes). The header, the sidecar's "columns" and every row's cells come from
// the same list, so a column and its values cannot drift apart:
//
//   const io::TableOf<tapping::HbPoint> table{
//       {"q", "dimensionless", "penetration parameter q", &tapping::HbPoint::q},
//       {"amplitude", "nm", "first-harmonic amplitude B", [s](const tapping::HbPoint& p) { return p.amplitude * s; }},
//       {"branch", "label", "plus, minus or free", [](const tapping::HbPoint& p) { return branch_name(p.branch); }}};
//   io::TableWriter out(path, table.columns());
//   for (const auto& p : curve) io::write_row(out, table, p);
//
// A table whose rows are every point of a Cartesian grid says so (grid(): the columns spanning it, slowest first,
// and the number of points along each); the commands record the grid's dimensions and coordinates with the table
// (the sidecar's "grid"), from which Python's Result.to_xarray() shapes the data without guessing.
#include <cstddef>
#include <functional>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "afmkit/core/units.hpp"
#include "afmkit/io/output.hpp"

namespace afmkit::io {

/// One cell of a row: a number, an integer (counts, ids), a flag (0/1 in CSV, true/false in JSON) or a text.
using Cell = std::variant<double, long, bool, std::string>;

/// The cell of a value: bool stays a flag, other integers become long, floating-point values double, anything
/// convertible to a string_view (const char*, std::string) a text.
template <class T>
Cell to_cell(const T& value) {
  using V = std::decay_t<T>;
  if constexpr (std::is_same_v<V, bool>) return Cell(std::in_place_type<bool>, value);
  else if constexpr (std::is_integral_v<V>) return Cell(std::in_place_type<long>, static_cast<long>(value));
  else if constexpr (std::is_floating_point_v<V>) return Cell(std::in_place_type<double>, static_cast<double>(value));
  else if constexpr (std::is_convertible_v<const V&, std::string_view>)
    return Cell(std::in_place_type<std::string>, std::string(std::string_view(value)));
  else static_assert(!sizeof(V), "a column's value must be a number, an integer, a bool or a text");
}

/// The cell as a JSON value (the rows of --json and of the Python module).
inline nlohmann::json cell_json(const Cell& cell) {
  return std::visit([](const auto& v) { return nlohmann::json(v); }, cell);
}

/// One column of a TableOf<Row>: the column (name, unit, description) and its value in a row.
template <class Row>
struct ColumnOf {
  Column column;
  std::function<Cell(const Row&)> value;

  /// `accessor`: a callable taking `const Row&` (a lambda, a function) or a pointer to a data member of Row.
  template <class Accessor>
  ColumnOf(std::string name, std::string unit, std::string description, Accessor accessor)
      : column{std::move(name), std::move(unit), std::move(description)},
        value([f = std::move(accessor)](const Row& row) { return to_cell(std::invoke(f, row)); }) {}
  /// A number whose unit converts the row's value (SI or the model's units) into the unit shown: the column's unit
  /// and its conversion are one declaration (afmkit/core/units.hpp), e.g. {"amplitude", units.length, …, &P::amplitude}.
  template <class Accessor>
  ColumnOf(std::string name, const units::Unit& unit, std::string description, Accessor accessor)
      : column{std::move(name), unit.name, std::move(description)},
        value([u = unit, f = std::move(accessor)](const Row& row) {
          return to_cell(u(static_cast<double>(std::invoke(f, row))));
        }) {}
};

/// One grid dimension: the column spanning it, the dimension's name (the column's name, or the name of the
/// quantity it holds: "alpha" for a chart's x) and its number of points.
struct GridDimension {
  std::string column;
  std::string name;
  std::size_t size = 0;
};

/// The columns of a table of rows of type Row, declared once (see above).
template <class Row>
class TableOf {
 public:
  TableOf(std::initializer_list<ColumnOf<Row>> columns) : columns_(columns) {}
  explicit TableOf(std::vector<ColumnOf<Row>> columns) : columns_(std::move(columns)) {}

  /// A column put first (a sweep's swept parameter).
  TableOf& prepend(ColumnOf<Row> column) {
    columns_.insert(columns_.begin(), std::move(column));
    return *this;
  }
  /// Replaces the description of column `name` (std::logic_error when there is none: a programming error).
  TableOf& describe(std::string_view name, std::string description) {
    at(name).column.description = std::move(description);
    return *this;
  }
  /// Declares the rows to be every point of the grid spanned by `dimensions` (slowest first), in row-major order.
  TableOf& grid(std::vector<GridDimension> dimensions) {
    for (const GridDimension& d : dimensions) at(d.column);  // each names a column
    grid_ = std::move(dimensions);
    return *this;
  }

  /// The columns (header, sidecar), in order.
  std::vector<Column> columns() const {
    std::vector<Column> out;
    out.reserve(columns_.size());
    for (const ColumnOf<Row>& c : columns_) out.push_back(c.column);
    return out;
  }
  const std::vector<ColumnOf<Row>>& entries() const& { return columns_; }
  const std::vector<GridDimension>& grid() const& { return grid_; }
  std::size_t size() const { return columns_.size(); }

 private:
  std::vector<ColumnOf<Row>> columns_;
  std::vector<GridDimension> grid_;

  ColumnOf<Row>& at(std::string_view name) {
    for (ColumnOf<Row>& c : columns_)
      if (c.column.name == name) return c;
    throw std::logic_error("table has no column '" + std::string(name) + "'");
  }
};

/// The columns of a table, shared and read-only: a list made once (a table declared once per unit system,
/// SharedTable) is handed to each run and its caller without copying a string. A range of Column (size(),
/// operator[], begin()/end()); vector() gives the list itself.
class ColumnList {
 public:
  ColumnList() = default;
  ColumnList(std::vector<Column> columns)  // NOLINT(google-explicit-constructor): a list of columns is one
      : columns_(std::make_shared<const std::vector<Column>>(std::move(columns))) {}

  const std::vector<Column>& vector() const& { return columns_ ? *columns_ : none(); }
  std::size_t size() const { return vector().size(); }
  bool empty() const { return vector().empty(); }
  const Column& operator[](std::size_t i) const& { return vector()[i]; }
  auto begin() const& { return vector().begin(); }
  auto end() const& { return vector().end(); }

 private:
  std::shared_ptr<const std::vector<Column>> columns_;
  static const std::vector<Column>& none() {
    static const std::vector<Column> empty;
    return empty;
  }
};

/// A table declaration built once and shared by the runs that use it (a command's table in one unit system): its
/// accessors and its columns (ColumnList) are not copied per run. Read-only.
template <class Row>
class SharedTable {
 public:
  explicit SharedTable(TableOf<Row> table)
      : table_(std::make_shared<const TableOf<Row>>(std::move(table))), columns_(table_->columns()) {}
  const TableOf<Row>& table() const& { return *table_; }
  const ColumnList& columns() const& { return columns_; }

 private:
  std::shared_ptr<const TableOf<Row>> table_;
  ColumnList columns_;
};

/// Writes one cell (TableWriter::cell of its kind).
inline void write_cell(TableWriter& out, const Cell& cell) {
  std::visit([&out](const auto& v) { out.cell(v); }, cell);
}

/// Writes `row` as one row of `table` into `out` (a TableWriter opened with table.columns()).
template <class Row>
void write_row(TableWriter& out, const TableOf<Row>& table, const Row& row) {
  for (const ColumnOf<Row>& c : table.entries()) write_cell(out, c.value(row));
  out.end_row();
}

/// The record of a table declared as a grid, built as its rows are written: each row's values in the grid's
/// columns are checked against the row-major order (the coordinate of each dimension's point taken from the first
/// row at it). Memory: the coordinates, not the rows.
class GridRecord {
 public:
  GridRecord() = default;
  explicit GridRecord(std::vector<GridDimension> grid);
  bool empty() const { return grid_.empty(); }
  /// The current row's value in dimension `d` (std::logic_error when it is not the coordinate of its grid point:
  /// a programming error).
  void value(std::size_t d, double v);
  void end_row() { ++rows_; }
  /// {"dims": [names], "columns": [column of each], "shape": [sizes], "coords": {name: [values]}} (std::logic_error
  /// when the rows written are not the whole grid).
  nlohmann::json json() const;

 private:
  std::vector<GridDimension> grid_;
  std::vector<std::size_t> stride_;
  std::vector<std::vector<double>> coords_;
  std::size_t rows_ = 0;
};

}  // namespace afmkit::io
