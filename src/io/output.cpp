#include "afmkit/io/output.hpp"

#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <stdexcept>

#include <unistd.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/version.hpp"
#include "afmkit/io/params.hpp"

namespace afmkit::io {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t flush_threshold = 1 << 16;  // bytes buffered before a write

// Temporaries being written, for the signal handler (SIGINT, SIGTERM, SIGHUP): fixed slots of fixed-size names so
// that the handler only reads them and calls unlink (async-signal-safe). Process-wide by nature: a signal is.
constexpr int temporary_slots = 32;
constexpr std::size_t temporary_name_size = 4096;
std::atomic<bool> slot_used[temporary_slots];
char slot_name[temporary_slots][temporary_name_size];

int register_temporary(const std::string& name) {
  if (name.size() >= temporary_name_size) return -1;
  for (int i = 0; i < temporary_slots; ++i) {
    bool expected = false;
    if (!slot_used[i].load() && slot_used[i].compare_exchange_strong(expected, true)) {
      std::memcpy(slot_name[i], name.c_str(), name.size() + 1);
      std::atomic_signal_fence(std::memory_order_seq_cst);
      return i;
    }
  }
  return -1;  // more than 32 outputs open at once: not cleaned on a signal (still removed on normal exit paths)
}

void release_temporary(int slot) {
  if (slot >= 0) slot_used[slot].store(false);
}

extern "C" void remove_temporaries_and_reraise(int signal_number) {
  for (int i = 0; i < temporary_slots; ++i)
    if (slot_used[i].load()) ::unlink(slot_name[i]);
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

void create_parent(const fs::path& p) {
  if (!p.has_parent_path()) return;
  std::error_code ec;
  fs::create_directories(p.parent_path(), ec);
  if (ec) throw InputError(fmt::format("cannot create directory '{}': {}", p.parent_path().string(), ec.message()));
}

/// The file an output path names: a symbolic link is followed (its target is replaced, the link stays); an
/// existing path that is not a regular file (device, FIFO, directory, socket) is refused.
std::string output_target(const std::string& path) {
  if (path.empty()) throw InputError("output path is empty: give a file path");
  std::error_code ec;
  fs::path p(path);
  for (int hops = 0; fs::is_symlink(fs::symlink_status(p, ec)); ++hops) {
    const fs::path next = fs::read_symlink(p, ec);
    if (ec || hops == 40) throw InputError(fmt::format("cannot follow the symbolic link '{}'", path));
    p = next.is_absolute() ? next : p.parent_path() / next;
  }
  const fs::file_status st = fs::status(p, ec);
  if (fs::exists(st) && !fs::is_regular_file(st))
    throw InputError(fmt::format("output '{}' is not a regular file (a device, FIFO or directory): give a file path",
                                 path));
  return p.string();
}

std::string temporary_name(const std::string& target) { return fmt::format("{}.tmp.{}", target, ::getpid()); }

void move_into_place(const std::string& from, const std::string& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) {
    fs::remove(from, ec);
    throw InputError(fmt::format("cannot move output into place at '{}'", to));
  }
}

/// Flushes, syncs to disk and closes `file`; false on any failure.
bool sync_and_close(std::FILE* file) {
  bool ok = std::fflush(file) == 0;
  ok = ::fsync(::fileno(file)) == 0 && ok;
  return std::fclose(file) == 0 && ok;
}

/// A complete temporary file next to its target, registered for removal on a signal until released.
struct Temporary {
  std::string target, name;
  int slot = -1;
  void remove() noexcept {
    std::error_code ec;
    fs::remove(name, ec);
    release_temporary(slot);
    slot = -1;
  }
  void move_into_place() {
    ::afmkit::io::move_into_place(name, target);
    release_temporary(slot);
    slot = -1;
  }
};

/// Writes `content` to a synced temporary file next to the target of `path`.
Temporary write_temporary(const std::string& path, const std::string& content) {
  Temporary t;
  t.target = output_target(path);
  create_parent(fs::path(t.target));
  t.name = temporary_name(t.target);
  t.slot = register_temporary(t.name);
  std::FILE* f = std::fopen(t.name.c_str(), "wb");
  if (!f) {
    release_temporary(t.slot);
    throw InputError(fmt::format("cannot write output file '{}': {}", path, std::strerror(errno)));
  }
  const bool written = std::fwrite(content.data(), 1, content.size(), f) == content.size();
  if (!sync_and_close(f) || !written) {
    t.remove();
    throw InputError(fmt::format("error while writing output file '{}'", path));
  }
  return t;
}

}  // namespace

void remove_temporaries_on_signal() {
  for (int s : {SIGINT, SIGTERM, SIGHUP}) std::signal(s, remove_temporaries_and_reraise);
}

nlohmann::json columns_json(const std::vector<Column>& columns) {
  nlohmann::json j = nlohmann::json::array();
  for (const Column& c : columns) j.push_back({{"name", c.name}, {"unit", c.unit}, {"description", c.description}});
  return j;
}

nlohmann::json finite_json(nlohmann::json value) {
  if (value.is_number_float()) {
    const double v = value.get<double>();
    if (std::isnan(v)) return nullptr;
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  } else if (value.is_structured()) {
    for (auto& item : value) item = finite_json(std::move(item));
  }
  return value;
}

std::string json_text(const nlohmann::json& value) { return finite_json(value).dump(2); }

TableWriter::TableWriter(std::string path, std::vector<Column> columns)
    : path_(std::move(path)), columns_(std::move(columns)) {
  if (columns_.empty()) throw std::logic_error("TableWriter: a table needs at least one column");
  for (const Column& c : columns_)
    if (c.name.empty() || c.unit.empty() || c.description.empty())
      throw std::logic_error(fmt::format("TableWriter: column '{}' of '{}' needs a name, a unit and a description",
                                         c.name, path_));
  target_ = output_target(path_);
  output_target(path_ + ".json");  // refuse a bad sidecar path before any work
  temporary_ = temporary_name(target_);
  create_parent(fs::path(target_));
  slot_ = register_temporary(temporary_);
  file_ = std::fopen(temporary_.c_str(), "wb");
  if (!file_) {
    release_temporary(slot_);
    throw InputError(fmt::format("cannot write output file '{}': {}", path_, std::strerror(errno)));
  }
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    if (i) buffer_.push_back(',');
    buffer_.append(std::string_view(columns_[i].name));
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
  release_temporary(slot_);
  slot_ = -1;
}

void TableWriter::separator() {
  if (cells_in_row_ == columns_.size())
    throw std::logic_error(fmt::format("TableWriter: more than {} cells in a row of '{}'", columns_.size(), path_));
  if (cells_in_row_++) buffer_.push_back(',');
}

TableWriter& TableWriter::cell(double value) {
  separator();
  // docs/conventions.md#undefined-values: one spelling, `nan` (fmt writes a negative NaN as "-nan")
  if (std::isnan(value)) {
    buffer_.append(std::string_view("nan"));
    return *this;
  }
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
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) {
    buffer_.append(text);
    return *this;
  }
  buffer_.push_back('"');  // RFC 4180: quoted, inner quotes doubled
  for (const char c : text) {
    if (c == '"') buffer_.push_back('"');
    buffer_.push_back(c);
  }
  buffer_.push_back('"');
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
  const bool ok = sync_and_close(file_);
  file_ = nullptr;
  if (!ok) {
    discard();
    throw InputError(fmt::format("error while writing output file '{}'", path_));
  }
  // Both files are complete and synced on disk before either is moved into place.
  Temporary meta;
  try {
    nlohmann::json described = sidecar;
    described["columns"] = columns_json(columns_);
    meta = write_temporary(path_ + ".json", json_text(described) + "\n");
  } catch (...) {
    discard();
    throw;
  }
  committed_ = true;
  try {
    ::afmkit::io::move_into_place(temporary_, target_);
  } catch (...) {
    meta.remove();
    release_temporary(slot_);
    throw;
  }
  release_temporary(slot_);
  slot_ = -1;
  meta.move_into_place();
}

void write_file_atomic(const std::string& path, const std::string& content) {
  write_temporary(path, content).move_into_place();
}

nlohmann::json make_sidecar(const std::string& command, const nlohmann::json& parameters,
                            const nlohmann::json& results, const nlohmann::json& parameter_units) {
  nlohmann::json j;
  j["program"] = "afmkit";
  j["version"] = afmkit::version;
  j["command"] = command;
  j["parameters"] = parameters;
  if (!parameter_units.empty()) j["parameter_units"] = parameter_units;
  if (!results.empty()) j["results"] = results;
  return j;
}

nlohmann::json make_sidecar(const std::string& command, const ParamSet& parameters, const nlohmann::json& results) {
  return make_sidecar(command, parameters.to_json(), results, parameters.units_json());
}

void require_writable_folder(const std::string& parameter, const std::string& shown, const std::string& dir) {
  auto refuse = [&](const std::string& why) {
    throw InvalidParameter(parameter, fmt::format("{} '{}' cannot be written: {}: must be a writable folder",
                                                  parameter, shown, why));
  };
  if (dir.empty()) refuse("empty");
  std::error_code ec;
  fs::path existing = dir;
  while (!existing.empty() && !fs::exists(existing, ec)) existing = existing.parent_path();
  if (existing.empty()) existing = ".";
  if (!fs::is_directory(existing, ec)) refuse(fmt::format("'{}' is not a folder", existing.string()));
  if (::access(existing.c_str(), W_OK | X_OK) != 0)
    refuse(fmt::format("'{}': {}", existing.string(), std::strerror(errno)));
}

}  // namespace afmkit::io
