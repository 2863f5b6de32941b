// Which file parameters are read and which are written, and the check that no output replaces an input or another
// output (params.hpp: ParamSet::writes, ParamSet::check_files).
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/params.hpp"

namespace afmkit::io {

namespace {

namespace fs = std::filesystem;

/// A path as the file system would resolve it: absolute, symbolic links of its existing part followed, "." and ".."
/// removed. The path itself when that fails.
fs::path resolved(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return ec ? fs::path(path).lexically_normal() : p;
}

/// Whether `a` and `b` name the same file: the same device and inode when both exist (symbolic and hard links
/// included), else the same resolved path.
bool same_file(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  if (::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0)
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  return resolved(a) == resolved(b);
}

/// Whether `path` is the folder `folder` or lies inside it.
bool inside(const std::string& path, const std::string& folder) {
  if (same_file(path, folder)) return true;
  const fs::path p = resolved(path), f = resolved(folder);
  auto pi = p.begin();
  for (auto fi = f.begin(); fi != f.end(); ++fi, ++pi) {
    if (fi->empty()) continue;  // a trailing separator
    if (pi == p.end() || *pi != *fi) return false;
  }
  return true;
}

struct Named {
  std::string key;    // the parameter ("config" for --config)
  std::string value;  // as given
  WrittenPath path;   // what is read or written
};

std::string shown(const Named& n) {
  return n.path.path == n.value ? fmt::format("{} = '{}'", n.key, n.value)
                                : fmt::format("{} = '{}' (which writes '{}')", n.key, n.value, n.path.path);
}

/// What an existing path is, in words ("a folder", "a FIFO (named pipe)", …), for a path that cannot be written.
std::string kind_of(const fs::file_status& st) {
  switch (st.type()) {
    case fs::file_type::directory: return "a folder";
    case fs::file_type::fifo: return "a FIFO (named pipe)";
    case fs::file_type::character: return "a character device";
    case fs::file_type::block: return "a block device";
    case fs::file_type::socket: return "a socket";
    case fs::file_type::regular: return "a file";
    default: return "not a regular file";
  }
}

/// Refuses a file output that cannot be written where it is named, before anything is computed: its path is an
/// existing folder, FIFO, device or socket (links followed), or its nearest existing parent is not a folder. (A
/// folder output — a Zarr store, the report's figures — is checked by its writer, also before computing.)
void require_writable_kind(const Named& out) {
  if (out.path.folder) return;
  std::error_code ec;
  const fs::path p(out.path.path);
  const fs::file_status st = fs::status(p, ec);
  if (fs::exists(st)) {
    if (!fs::is_regular_file(st))
      throw InvalidParameter(out.key, fmt::format("output '{}' is not a regular file ({}; {}): give a file path",
                                                  out.path.path, kind_of(st), shown(out)));
    return;
  }
  for (fs::path parent = fs::absolute(p, ec).parent_path(); !parent.empty(); parent = parent.parent_path()) {
    const fs::file_status ps = fs::status(parent, ec);
    if (fs::exists(ps)) {
      if (!fs::is_directory(ps))
        throw InvalidParameter(out.key, fmt::format("{}: its folder '{}' is {}, not a folder: give a path in a "
                                                    "folder",
                                                    shown(out), parent.string(), kind_of(ps)));
      return;
    }
    if (parent == parent.parent_path()) return;
  }
}

}  // namespace

std::vector<WrittenPath> table_and_sidecar(const std::string& path) { return {{path}, {path + ".json"}}; }

ParamSet& ParamSet::writes(WrittenPaths paths) {
  if (last_ == kNone || !entries_[last_].is_file)
    throw std::logic_error("ParamSet::writes: the last declared parameter is not a file");
  entries_[last_].written = true;
  entries_[last_].written_paths = std::move(paths);
  return *this;
}

void ParamSet::check_files() const {
  // no path given (a front end that writes no file: the Python module's defaults): nothing to compare or check
  // (files_: the file parameters' indices in declaration order; a key declared again as another kind is no file)
  const auto given = [this](std::uint32_t at) {
    const Entry& e = entries_[at];
    return e.is_file && !std::get<std::string>(e.value).empty();
  };
  if (config_path_.empty() && std::none_of(files_.begin(), files_.end(), given)) return;
  std::vector<Named> inputs, outputs;
  if (!config_path_.empty()) inputs.push_back({"config", config_path_, {config_path_}});
  for (const std::uint32_t at : files_) {
    const Entry& e = entries_[at];
    const std::string& key = e.key;
    if (!e.is_file) continue;
    const std::string& value = std::get<std::string>(e.value);
    if (value.empty()) continue;
    if (!e.written) {
      inputs.push_back({key, value, {value}});
      continue;
    }
    for (WrittenPath& w : e.written_paths ? e.written_paths(value) : std::vector<WrittenPath>{{value}})
      outputs.push_back({key, value, std::move(w)});
  }
  for (std::size_t o = 0; o < outputs.size(); ++o) {
    const Named& out = outputs[o];
    auto clash = [&](const Named& in) {
      return out.path.folder ? inside(in.path.path, out.path.path) : same_file(out.path.path, in.path.path);
    };
    for (const Named& in : inputs)
      if (clash(in))
        throw InvalidParameter(out.key, fmt::format("{} would replace the file read as {}: an output must not be an "
                                                    "input (through a link neither): choose another path",
                                                    shown(out), shown(in)));
    for (std::size_t other = 0; other < o; ++other) {
      const Named& in = outputs[other];
      if (in.key == out.key) continue;  // the parts of one output are distinct by construction
      if (clash(in) || (in.path.folder && inside(out.path.path, in.path.path)))
        throw InvalidParameter(out.key, fmt::format("{} and {} name the same file: each output needs its own path",
                                                    shown(out), shown(in)));
    }
  }
  for (const Named& out : outputs) require_writable_kind(out);  // after the clashes, which say more
}

}  // namespace afmkit::io
