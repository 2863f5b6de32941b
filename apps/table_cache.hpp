#pragma once
// A command's table declared once per set of units: its columns (names, units, descriptions) and their accessors
// are the same for every run in the same units, so they are built at the first run in those units and shared by
// the runs after it (io::SharedTable: neither the declaration nor its columns are copied per run). Building the 21
// columns of `tapping orbit` cost ~3 % of a 1 ms run (bench/command_layer.py). The last few sets of units are kept
// (a physical run's units depend on its cantilever); safe to use from several threads (the Python module runs
// commands in the caller's threads).
//   auto tables = std::make_shared<TableCache<tapping::FoundOrbit, TappingUnits>>(orbit_table);  // at registration
//   out.open(tables->get(u));                                                                    // in each run
#include <cstddef>
#include <mutex>
#include <utility>
#include <vector>

#include "afmkit/io/table.hpp"

namespace afmkit::cli {

template <class Row, class Units>
class TableCache {
 public:
  using Make = io::TableOf<Row> (*)(const Units&);
  explicit TableCache(Make make) : make_(make) {}

  /// The table for `units` (Units::operator==), made by `make` the first time.
  io::SharedTable<Row> get(const Units& units) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [kept_units, table] : tables_)
      if (kept_units == units) return table;
    if (tables_.size() >= kKept) tables_.erase(tables_.begin());  // the oldest
    tables_.emplace_back(units, io::SharedTable<Row>(make_(units)));
    return tables_.back().second;
  }

 private:
  static constexpr std::size_t kKept = 4;
  Make make_;
  std::mutex mutex_;
  std::vector<std::pair<Units, io::SharedTable<Row>>> tables_;
};

}  // namespace afmkit::cli
