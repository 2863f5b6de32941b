#include "afmkit/io/output.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <stdexcept>

#include <unistd.h>

#include <fmt/compile.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/version.hpp"
#include "afmkit/io/params.hpp"
#include "signals_held.hpp"

namespace afmkit::io {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t flush_threshold = 1 << 16;  // bytes buffered before a write

// Temporaries being written, for the signal handler (SIGINT, SIGTERM, SIGHUP): fixed slots of fixed-size names so
// that the handler only reads them and calls unlink (async-signal-safe). Process-wide by nature: a signal is.
// While outputs are being moved into place (signals_held.hpp) the handler only notes the signal; the commit
// delivers it when they are in place.
constexpr int temporary_slots = 64;
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
  return -1;  // more than 64 outputs open at once: not cleaned on a signal (a later run removes them)
}

void release_temporary(int slot) {
  if (slot >= 0) slot_used[slot].store(false);
}

extern "C" void remove_temporaries_and_reraise(int signal_number) {
  if (detail::defer_signal(signal_number)) return;  // outputs are being moved into place: they complete first
  for (int i = 0; i < temporary_slots; ++i)
    if (slot_used[i].load()) ::unlink(slot_name[i]);
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

std::string host_name() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "host";
  std::string host(name);
  for (char& c : host)
    if (c == '/' || static_cast<unsigned char>(c) < 0x20) c = '_';
  return host;
}

/// Removes the temporaries of `target` left by afmkit processes of this host that no longer exist (killed by
/// SIGKILL, or by a power cut): `<target>.tmp.<pid>.<host>.<tag>` and the older `<target>.tmp.<pid>`.
void remove_stale_temporaries(const fs::path& target) {
  std::error_code ec;
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = target.filename().string() + ".tmp.";
  static const std::string host = host_name();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    std::size_t digits = 0;
    while (digits < rest.size() && std::isdigit(static_cast<unsigned char>(rest[digits]))) ++digits;
    if (digits == 0 || digits > 9) continue;
    if (digits < rest.size()) {  // .<host>.<tag>: only this host's pids can be checked
      const std::size_t tag = rest.rfind('.');
      if (rest[digits] != '.' || tag <= digits || rest.substr(digits + 1, tag - digits - 1) != host) continue;
    }
    const long pid = std::stol(rest.substr(0, digits));
    if (pid <= 0 || pid == ::getpid() || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    if (fs::is_regular_file(fs::symlink_status(it->path(), ec))) fs::remove(it->path(), ec);
  }
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
  if (path.find('\0') != std::string::npos)
    throw InputError("output path holds a NUL character: a path cannot contain one");
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

/// Why writing failed, in words: the C library's reason, and for a full disk or a read-only file system the remedy.
std::string reason(int error) {
  if (error == ENOSPC || error == EDQUOT)
    return fmt::format("{} (free space, or write to another disk)", std::strerror(error));
  if (error == EROFS) return fmt::format("{} (write to a writable folder)", std::strerror(error));
  return std::strerror(error == 0 ? EIO : error);
}

/// Creates the unique temporary of `target` (mode 0666 less the umask, as a file created by fopen); returns the
/// open stream and sets `name`. InputError naming `path` on failure.
std::FILE* open_temporary(const std::string& path, const std::string& target, std::string& name, int& slot) {
  create_parent(fs::path(target));
  remove_stale_temporaries(fs::path(target));
  static const std::string host = host_name();
  std::string pattern = fmt::format("{}.tmp.{}.{}.XXXXXX", target, ::getpid(), host);
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0) throw InputError(fmt::format("cannot write output file '{}': {}", path, reason(errno)));
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(fd, 0666 & ~mask);
  name = pattern;
  slot = register_temporary(name);
  std::FILE* f = ::fdopen(fd, "wb");
  if (!f) {
    const int error = errno;
    ::close(fd);
    ::unlink(name.c_str());
    release_temporary(slot);
    throw InputError(fmt::format("cannot write output file '{}': {}", path, reason(error)));
  }
  return f;
}

/// Flushes, syncs to disk and closes `file`; 0, or the errno of the first failure.
int sync_and_close(std::FILE* file) {
  int error = 0;
  if (std::fflush(file) != 0) error = errno;
  if (::fsync(::fileno(file)) != 0 && error == 0 && errno != EINVAL) error = errno;
  if (std::fclose(file) != 0 && error == 0) error = errno;
  return error;
}

void remove_staged(OutputSet::Staged& s) noexcept {
  ::unlink(s.temporary.c_str());
  release_temporary(s.slot);
  s.slot = -1;
}

/// Writes `content` to a synced temporary next to the target of `path`.
OutputSet::Staged write_temporary(const std::string& path, const std::string& content) {
  OutputSet::Staged t;
  t.path = path;
  t.target = output_target(path);
  std::FILE* f = open_temporary(path, t.target, t.temporary, t.slot);
  int error = std::fwrite(content.data(), 1, content.size(), f) == content.size() ? 0 : errno;
  const int closed = sync_and_close(f);
  if (error == 0) error = closed;
  if (error != 0) {
    remove_staged(t);
    throw InputError(fmt::format("error while writing output file '{}': {}", path, reason(error)));
  }
  return t;
}

/// The folders of `staged`, each opened and locked (flock, exclusive) once, unlocked at destruction: two afmkit
/// processes (or threads) committing into the same folder take turns. A folder is known by its device and inode,
/// not by how its path is spelt ("/abs/dir" and "." from inside it, "a/../a"): a second lock on a second opening of
/// a folder this run already holds would wait for itself forever. Locked in (device, inode) order, the same in
/// every process. A file system without locks: no lock.
class FolderLocks {
 public:
  explicit FolderLocks(const std::vector<OutputSet::Staged>& staged) {
    std::vector<std::string> folders;
    for (const auto& s : staged) {
      const fs::path p(s.target);
      folders.push_back(p.has_parent_path() ? p.parent_path().string() : ".");
    }
    std::sort(folders.begin(), folders.end());
    folders.erase(std::unique(folders.begin(), folders.end()), folders.end());
    struct Opened {
      dev_t device;
      ino_t inode;
      int fd;
    };
    std::vector<Opened> opened;
    for (const std::string& f : folders) {
      const int fd = ::open(f.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
      if (fd < 0) continue;
      struct stat st {};
      const bool known = ::fstat(fd, &st) == 0;
      if (!known || std::any_of(opened.begin(), opened.end(), [&](const Opened& o) {
            return o.device == st.st_dev && o.inode == st.st_ino;
          })) {
        ::close(fd);  // the same folder by another path (or not to be identified): locked once
        continue;
      }
      opened.push_back({st.st_dev, st.st_ino, fd});
    }
    std::sort(opened.begin(), opened.end(), [](const Opened& a, const Opened& b) {
      return a.device != b.device ? a.device < b.device : a.inode < b.inode;
    });
    for (const Opened& o : opened) {
      while (::flock(o.fd, LOCK_EX) != 0 && errno == EINTR) {
      }
      fds_.push_back(o.fd);
    }
  }
  ~FolderLocks() {
    for (int fd : fds_) ::close(fd);  // closing releases the lock
  }
  FolderLocks(const FolderLocks&) = delete;
  FolderLocks& operator=(const FolderLocks&) = delete;

 private:
  std::vector<int> fds_;
};

}  // namespace

OutputSet::~OutputSet() { discard(); }

void OutputSet::discard() noexcept {
  for (Staged& s : staged_) remove_staged(s);
  staged_.clear();
}

void OutputSet::add(const std::string& path, const std::string& content) {
  staged_.push_back(write_temporary(path, content));
}

void OutputSet::commit() {
  if (staged_.empty()) return;
  std::vector<std::string> backups(staged_.size());  // hard links to the files replaced, to put them back
  std::size_t moved = 0;
  int error = 0;
  {
    FolderLocks locks(staged_);
    detail::SignalsHeld guard;  // all in place, or none, before a signal is acted on
    for (std::size_t i = 0; i < staged_.size(); ++i) {
      const Staged& s = staged_[i];
      const std::string backup = s.temporary + "-old";
      if (::link(s.target.c_str(), backup.c_str()) == 0) backups[i] = backup;
    }
    for (; moved < staged_.size(); ++moved)
      if (::rename(staged_[moved].temporary.c_str(), staged_[moved].target.c_str()) != 0) {
        error = errno;
        break;
      }
    if (error != 0) {
      for (std::size_t i = moved; i-- > 0;) {  // the files moved so far: the old file back, or none
        if (!backups[i].empty()) ::rename(backups[i].c_str(), staged_[i].target.c_str()), backups[i].clear();
        else ::unlink(staged_[i].target.c_str());
      }
    }
    for (const std::string& b : backups)
      if (!b.empty()) ::unlink(b.c_str());
    for (std::size_t i = 0; i < moved; ++i) {
      release_temporary(staged_[i].slot);
      staged_[i].slot = -1;
    }
  }
  if (error != 0) {
    const std::string failed = staged_[moved].path;
    discard();  // the temporaries not moved (those moved are gone: put back or removed above)
    throw InputError(fmt::format("cannot move output into place at '{}': {}", failed, reason(error)));
  }
  staged_.clear();
}

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
std::string json_text(nlohmann::json&& value) { return finite_json(std::move(value)).dump(2); }

TableWriter::TableWriter(std::string path, std::vector<Column> columns)
    : path_(std::move(path)), columns_(std::move(columns)) {
  if (columns_.empty()) throw std::logic_error("TableWriter: a table needs at least one column");
  for (const Column& c : columns_)
    if (c.name.empty() || c.unit.empty() || c.description.empty())
      throw std::logic_error(fmt::format("TableWriter: column '{}' of '{}' needs a name, a unit and a description",
                                         c.name, path_));
  target_ = output_target(path_);
  output_target(path_ + ".json");  // refuse a bad sidecar path before any work
  file_ = open_temporary(path_, target_, temporary_, slot_);
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
  // the shortest representation that reads back exactly, as "{}" gives it: compiled, straight into the buffer
  // (no format string parsed per cell, no intermediate buffer: a 10^6-row table in half the time)
  fmt::format_to(fmt::appender(buffer_), FMT_COMPILE("{}"), value);
  return *this;
}

TableWriter& TableWriter::cell(long value) {
  separator();
  fmt::format_to(fmt::appender(buffer_), FMT_COMPILE("{}"), value);
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
    const int error = errno;
    discard();
    throw InputError(fmt::format("error while writing output file '{}': {}", path_, reason(error)));
  }
  buffer_.clear();
}

void TableWriter::commit(const nlohmann::json& sidecar) {
  OutputSet set;
  stage(sidecar, set);
  set.commit();
}

void TableWriter::stage(const nlohmann::json& sidecar, OutputSet& set) {
  if (cells_in_row_) throw std::logic_error(fmt::format("TableWriter: unfinished row in '{}'", path_));
  flush();
  const int error = sync_and_close(file_);
  file_ = nullptr;
  if (error != 0) {
    discard();
    throw InputError(fmt::format("error while writing output file '{}': {}", path_, reason(error)));
  }
  // Both files are complete and synced on disk before either is moved into place (by the set, together).
  OutputSet::Staged meta;
  try {
    nlohmann::json described = sidecar;
    described["columns"] = columns_json(columns_);
    meta = write_temporary(path_ + ".json", json_text(std::move(described)) + "\n");  // no second copy
  } catch (...) {
    discard();
    throw;
  }
  committed_ = true;
  set.adopt({path_, target_, temporary_, slot_});
  slot_ = -1;
  set.adopt(std::move(meta));
}

void write_file_atomic(const std::string& path, const std::string& content) {
  OutputSet set;
  set.add(path, content);
  set.commit();
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
