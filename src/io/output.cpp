#include "afmkit/io/output.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>
#include <unistd.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/version.hpp"

namespace afmkit::io {

Table::Table(std::vector<std::string> columns) : columns_(std::move(columns)) {}

void Table::add_row(std::vector<Cell> row) {
  if (row.size() != columns_.size())
    throw std::logic_error(fmt::format("Table::add_row: {} cells for {} columns", row.size(), columns_.size()));
  rows_.push_back(std::move(row));
}

std::string Table::to_csv() const {
  std::string out;
  for (std::size_t i = 0; i < columns_.size(); ++i) out += (i ? "," : "") + columns_[i];
  out += '\n';
  for (const auto& row : rows_) {
    for (std::size_t i = 0; i < row.size(); ++i) {
      if (i) out += ',';
      std::visit(
          [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, bool>) out += v ? "1" : "0";
            else if constexpr (std::is_same_v<T, std::string>) out += v;
            else out += fmt::format("{}", v);
          },
          row[i]);
    }
    out += '\n';
  }
  return out;
}

void write_file_atomic(const std::string& path, const std::string& content) {
  namespace fs = std::filesystem;
  fs::path p(path);
  std::error_code ec;
  if (p.has_parent_path()) {
    fs::create_directories(p.parent_path(), ec);
    if (ec) throw InputError(fmt::format("cannot create directory '{}': {}", p.parent_path().string(), ec.message()));
  }
  fs::path tmp = p;
  tmp += fmt::format(".tmp.{}", ::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(fmt::format("cannot write output file '{}'", path));
    out << content;
    out.flush();
    if (!out) {
      out.close();
      fs::remove(tmp, ec);
      throw InputError(fmt::format("error while writing output file '{}'", path));
    }
  }
  fs::rename(tmp, p, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(fmt::format("cannot move output into place at '{}'", path));
  }
}

nlohmann::json make_sidecar(const std::string& command, const nlohmann::json& parameters,
                            const nlohmann::json& results) {
  nlohmann::json j;
  j["program"] = "afmkit";
  j["version"] = afmkit::version;
  j["command"] = command;
  j["parameters"] = parameters;
  if (!results.empty()) j["results"] = results;
  return j;
}

void write_table(const std::string& csv_path, const Table& table, const nlohmann::json& sidecar) {
  // Render both first, then write: nothing is written if rendering fails.
  std::string csv = table.to_csv();
  std::string meta = sidecar.dump(2) + "\n";
  write_file_atomic(csv_path, csv);
  write_file_atomic(csv_path + ".json", meta);
}

}  // namespace afmkit::io
