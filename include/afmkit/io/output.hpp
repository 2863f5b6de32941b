#pragma once
// Output files: CSV tables with a header row, a JSON sidecar (<file>.json) holding the command, the
// parameters and the afmkit version, all written atomically (temporary file + rename), so a failed or
// interrupted run never leaves a half-written output.
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

namespace afmkit::io {

/// A column-named table; each cell is a number, an integer, a string or a boolean (written 0/1).
class Table {
 public:
  using Cell = std::variant<double, long, std::string, bool>;
  explicit Table(std::vector<std::string> columns);
  void add_row(std::vector<Cell> row);  ///< throws std::logic_error if the width differs
  const std::vector<std::string>& columns() const { return columns_; }
  const std::vector<std::vector<Cell>>& rows() const { return rows_; }
  std::size_t size() const { return rows_.size(); }
  std::string to_csv() const;  ///< shortest round-trip representation of doubles

 private:
  std::vector<std::string> columns_;
  std::vector<std::vector<Cell>> rows_;
};

/// Write `content` to `path` atomically; creates parent directories. Throws afmkit::InputError on failure.
void write_file_atomic(const std::string& path, const std::string& content);

/// Metadata of a run, written as the sidecar `<csv path>.json`.
nlohmann::json make_sidecar(const std::string& command, const nlohmann::json& parameters,
                            const nlohmann::json& results = nlohmann::json::object());

/// Write table to `csv_path` and the sidecar next to it (`csv_path + ".json"`).
void write_table(const std::string& csv_path, const Table& table, const nlohmann::json& sidecar);

}  // namespace afmkit::io
