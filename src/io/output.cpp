#include "afmkit/io/output.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <unistd.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/version.hpp"

namespace afmkit::io {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t flush_threshold = 1 << 16;  // bytes buffered before a write

void create_parent(const fs::path& p) {
  if (!p.has_parent_path()) return;
  std::error_code ec;
  fs::create_directories(p.parent_path(), ec);
  if (ec) throw InputError(fmt::format("cannot create directory '{}': {}", p.parent_path().string(), ec.message()));
}

std::string temporary_name(const std::string& path) { return fmt::format("{}.tmp.{}", path, ::getpid()); }

void move_into_place(const std::string& from, const std::string& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) {
    fs::remove(from, ec);
    throw InputError(fmt::format("cannot move output into place at '{}'", to));
  }
}

/// Writes `content` to a temporary file next to `path`; returns its name.
std::string write_temporary(const std::string& path, const std::string& content) {
  create_parent(fs::path(path));
  const std::string tmp = temporary_name(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(fmt::format("cannot write output file '{}'", path));
    out << content;
    out.flush();
    if (!out) {
      out.close();
      std::error_code ec;
      fs::remove(tmp, ec);
      throw InputError(fmt::format("error while writing output file '{}'", path));
    }
  }
  return tmp;
}

}  // namespace

TableWriter::TableWriter(std::string path, std::vector<std::string> columns)
    : path_(std::move(path)), temporary_(temporary_name(path_)), columns_(std::move(columns)) {
  if (columns_.empty()) throw std::logic_error("TableWriter: a table needs at least one column");
  create_parent(fs::path(path_));
  file_ = std::fopen(temporary_.c_str(), "wb");
  if (!file_) throw InputError(fmt::format("cannot write output file '{}': {}", path_, std::strerror(errno)));
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    if (i) buffer_.push_back(',');
    buffer_.append(std::string_view(columns_[i]));
  }
  buffer_.push_back('\n');
}

TableWriter::~TableWriter() {
  if (!committed_) discard();
}

void TableWriter::discard() noexcept {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  std::error_code ec;
  fs::remove(temporary_, ec);
}

void TableWriter::separator() {
  if (cells_in_row_ == columns_.size())
    throw std::logic_error(fmt::format("TableWriter: more than {} cells in a row of '{}'", columns_.size(), path_));
  if (cells_in_row_++) buffer_.push_back(',');
}

TableWriter& TableWriter::cell(double value) {
  separator();
  fmt::format_to(std::back_inserter(buffer_), "{}", value);
  return *this;
}

TableWriter& TableWriter::cell(long value) {
  separator();
  fmt::format_to(std::back_inserter(buffer_), "{}", value);
  return *this;
}

TableWriter& TableWriter::cell(bool value) {
  separator();
  buffer_.push_back(value ? '1' : '0');
  return *this;
}

TableWriter& TableWriter::cell(std::string_view text) {
  separator();
  buffer_.append(text);
  return *this;
}

void TableWriter::end_row() {
  if (cells_in_row_ != columns_.size())
    throw std::logic_error(
        fmt::format("TableWriter: {} cells for {} columns in '{}'", cells_in_row_, columns_.size(), path_));
  buffer_.push_back('\n');
  cells_in_row_ = 0;
  ++rows_;
  if (buffer_.size() >= flush_threshold) flush();
}

void TableWriter::flush() {
  if (!file_) throw std::logic_error("TableWriter: write after commit");
  if (buffer_.size() && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    const std::string reason = std::strerror(errno);
    discard();
    throw InputError(fmt::format("error while writing output file '{}': {}", path_, reason));
  }
  buffer_.clear();
}

void TableWriter::commit(const nlohmann::json& sidecar) {
  if (cells_in_row_) throw std::logic_error(fmt::format("TableWriter: unfinished row in '{}'", path_));
  flush();
  const bool failed = std::fflush(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (failed || close_failed) {
    discard();
    throw InputError(fmt::format("error while writing output file '{}'", path_));
  }
  // Both files are complete on disk before either is moved into place.
  std::string meta_temporary;
  try {
    meta_temporary = write_temporary(path_ + ".json", sidecar.dump(2) + "\n");
  } catch (...) {
    discard();
    throw;
  }
  committed_ = true;
  move_into_place(temporary_, path_);
  move_into_place(meta_temporary, path_ + ".json");
}

void write_file_atomic(const std::string& path, const std::string& content) {
  move_into_place(write_temporary(path, content), path);
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

}  // namespace afmkit::io
