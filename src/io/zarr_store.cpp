// Writing a Zarr v2 store (zarr_store.hpp).
#include "afmkit/io/zarr_store.hpp"

#include <signal.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <system_error>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"
#include "afmkit/io/output.hpp"
#include "signals_held.hpp"

namespace afmkit::io {

namespace {

namespace fs = std::filesystem;
static_assert(std::endian::native == std::endian::little, "Zarr chunks are written in the machine's byte order");

/// Whether `dir` is a store afmkit wrote (root .zattrs carrying afmkit_study_format).
bool is_afmkit_store(const fs::path& dir) {
  std::string text;
  try {  // a FIFO or a huge file there is not an afmkit store's attributes
    text = files::read_input_file((dir / ".zattrs").string(), "store attributes", 16u << 20);
  } catch (const InputError&) {
    return false;
  }
  const nlohmann::json attrs = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  return attrs.is_object() && attrs.contains("afmkit_study_format");
}

void write_file(const fs::path& file, const void* data, std::size_t size) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) throw InputError(fmt::format("cannot write '{}': {}", file.string(), std::strerror(errno)));
}

void write_json(const fs::path& file, const nlohmann::json& j) {
  const std::string text = j.dump(4);
  write_file(file, text.data(), text.size());
}

/// Cleans up after an earlier commit to `target` by a process that no longer exists (killed by SIGKILL, a power
/// cut): its new store's folder `.<name>.tmp.<pid>` is removed, and its moved-aside old store `.<name>.old.<pid>` is
/// put back when the target is missing (else removed).
void remove_stale_commits(const fs::path& target) {
  std::error_code ec;
  const std::string name = target.filename().string();
  for (const char* kind : {".tmp.", ".old."}) {
    const std::string prefix = "." + name + kind;
    for (fs::directory_iterator it(target.parent_path(), ec), end; !ec && it != end; it.increment(ec)) {
      const std::string entry = it->path().filename().string();
      if (entry.size() <= prefix.size() || entry.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string digits = entry.substr(prefix.size());
      if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
      const long pid = std::stol(digits);
      if (pid <= 0 || pid == ::getpid() || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
      std::error_code ignored;
      if (std::string(kind) == ".old." && !fs::exists(target, ignored)) fs::rename(it->path(), target, ignored);
      else fs::remove_all(it->path(), ignored);
    }
  }
}

nlohmann::json zarray_json(const std::vector<std::size_t>& shape, const std::vector<std::size_t>& chunks,
                           const std::string& dtype, nlohmann::json fill) {
  return {{"zarr_format", 2}, {"shape", shape},     {"chunks", chunks},   {"dtype", dtype},
          {"compressor", nullptr}, {"fill_value", std::move(fill)}, {"filters", nullptr}, {"order", "C"}};
}

}  // namespace

ZarrStoreWriter::ZarrStoreWriter(std::string path, std::string parameter)
    : path_(std::move(path)), parameter_(std::move(parameter)) {
  auto refuse = [&](const std::string& why) {
    throw InvalidParameter(parameter_, fmt::format("{} '{}' cannot be written: {}", parameter_, path_, why));
  };
  if (path_.empty()) refuse("empty: must be the path of a Zarr store (a folder)");
  std::error_code ec;
  const fs::path target = fs::absolute(path_, ec);
  if (fs::exists(target, ec)) {
    if (!fs::is_directory(target, ec)) refuse("it exists and is not a folder");
    if (!is_afmkit_store(target)) refuse("it exists and is not an afmkit store (it is never replaced: remove it or "
                                         "choose another path)");
  }
  require_writable_folder(parameter_, path_, target.parent_path().string());
}

void ZarrStoreWriter::attribute(const std::string& key, nlohmann::json value) { attrs_[key] = std::move(value); }

void ZarrStoreWriter::add(Array a) {
  std::size_t n = 1;
  for (std::size_t k = 0; k < a.shape.size(); ++k) {
    if (a.chunks.size() != a.shape.size() || a.chunks[k] == 0)
      throw std::logic_error("ZarrStoreWriter: array '" + a.name + "': chunks must be > 0, one per dimension");
    n *= a.shape[k];
  }
  if (a.data.size() != n * a.item)
    throw std::logic_error("ZarrStoreWriter: array '" + a.name + "': values do not match its shape");
  for (const Array& b : arrays_)
    if (b.name == a.name) throw std::logic_error("ZarrStoreWriter: array '" + a.name + "' given twice");
  arrays_.push_back(std::move(a));
}

void ZarrStoreWriter::coordinate(const std::string& name, const std::vector<double>& values, nlohmann::json attrs) {
  Array a{name, zarray_json({values.size()}, {std::max<std::size_t>(values.size(), 1)}, "<f8", nullptr),
          std::move(attrs), {values.size()}, {std::max<std::size_t>(values.size(), 1)}, 8, {}, {}};
  a.zattrs["_ARRAY_DIMENSIONS"] = {name};
  a.data.resize(values.size() * 8);
  if (!values.empty()) std::memcpy(a.data.data(), values.data(), a.data.size());
  a.fill.assign(8, 0);
  add(std::move(a));
}

void ZarrStoreWriter::variable(const std::string& name, const std::vector<std::string>& dims,
                               const std::vector<std::size_t>& shape, const std::vector<std::size_t>& chunks,
                               const std::vector<double>& values, nlohmann::json attrs) {
  Array a{name, zarray_json(shape, chunks, "<f8", "NaN"), std::move(attrs), shape, chunks, 8, {}, {}};
  a.zattrs["_ARRAY_DIMENSIONS"] = dims;
  a.data.resize(values.size() * 8);
  if (!values.empty()) std::memcpy(a.data.data(), values.data(), a.data.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  a.fill.resize(8);
  std::memcpy(a.fill.data(), &nan, 8);
  add(std::move(a));
}

void ZarrStoreWriter::integer_variable(const std::string& name, const std::vector<std::string>& dims,
                                       const std::vector<std::size_t>& shape, const std::vector<std::size_t>& chunks,
                                       const std::vector<std::int64_t>& values, const std::string& dtype,
                                       nlohmann::json attrs) {
  std::size_t item = 0;
  if (dtype == "<i1") item = 1;
  else if (dtype == "<i4") item = 4;
  else if (dtype == "<i8") item = 8;
  else throw std::logic_error("ZarrStoreWriter: integer dtype must be <i1, <i4 or <i8");
  Array a{name, zarray_json(shape, chunks, dtype, 0), std::move(attrs), shape, chunks, item, {}, {}};
  a.zattrs["_ARRAY_DIMENSIONS"] = dims;
  a.data.resize(values.size() * item);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::int64_t v = values[i];  // little endian: the low bytes first
    std::memcpy(a.data.data() + i * item, &v, item);
  }
  a.fill.assign(item, 0);
  add(std::move(a));
}

void ZarrStoreWriter::commit() {
  std::error_code ec;
  const fs::path target = fs::absolute(path_, ec);
  fs::create_directories(target.parent_path(), ec);
  if (ec) throw InputError(fmt::format("{} '{}': cannot create its folder: {}", parameter_, path_, ec.message()));
  const fs::path tmp = target.parent_path() / fmt::format(".{}.tmp.{}", target.filename().string(), ::getpid());
  const fs::path old = target.parent_path() / fmt::format(".{}.old.{}", target.filename().string(), ::getpid());
  detail::SignalsHeld held;  // complete or absent: an interrupt is delivered once the store is in place
  remove_stale_commits(target);
  try {
    fs::remove_all(tmp);
    fs::create_directory(tmp);
    nlohmann::json meta = nlohmann::json::object();
    meta[".zgroup"] = {{"zarr_format", 2}};
    meta[".zattrs"] = attrs_;
    write_json(tmp / ".zgroup", meta[".zgroup"]);
    write_json(tmp / ".zattrs", attrs_);
    for (const Array& a : arrays_) {
      const fs::path dir = tmp / a.name;
      fs::create_directory(dir);
      write_json(dir / ".zarray", a.zarray);
      write_json(dir / ".zattrs", a.zattrs);
      meta[a.name + "/.zarray"] = a.zarray;
      meta[a.name + "/.zattrs"] = a.zattrs;
      const std::size_t dims = a.shape.size();
      std::vector<std::size_t> grid(dims), strides(dims, 1);
      std::size_t chunk_items = 1, total = 1;
      for (std::size_t k = 0; k < dims; ++k) {
        grid[k] = (a.shape[k] + a.chunks[k] - 1) / a.chunks[k];
        chunk_items *= a.chunks[k];
        total *= grid[k];
      }
      for (std::size_t k = dims; k-- > 1;) strides[k - 1] = strides[k] * a.shape[k];
      if (a.data.empty()) total = 0;
      std::vector<unsigned char> chunk(chunk_items * a.item);
      std::vector<std::size_t> index(dims, 0), local(dims, 0);
      for (std::size_t c = 0; c < total; ++c) {
        for (std::size_t k = dims, rest = c; k-- > 0;) {  // chunk c's position in the chunk grid (C order)
          index[k] = rest % grid[k];
          rest /= grid[k];
        }
        for (std::size_t i = 0; i < chunk_items; ++i) {  // each item of the chunk: inside the array, or fill
          bool inside = true;
          std::size_t flat = 0;
          for (std::size_t k = dims, rest = i; k-- > 0;) {
            local[k] = rest % a.chunks[k];
            rest /= a.chunks[k];
            const std::size_t at = index[k] * a.chunks[k] + local[k];
            inside = inside && at < a.shape[k];
            flat += at * strides[k];
          }
          std::memcpy(chunk.data() + i * a.item, inside ? a.data.data() + flat * a.item : a.fill.data(), a.item);
        }
        std::string key;
        for (std::size_t k = 0; k < dims; ++k) {
          if (k) key += '.';
          key += std::to_string(index[k]);
        }
        write_file(dir / key, chunk.data(), chunk.size());
      }
    }
    write_json(tmp / ".zmetadata", {{"metadata", meta}, {"zarr_consolidated_format", 1}});
    const bool replacing = fs::exists(target);
    if (replacing) fs::rename(target, old);
    fs::rename(tmp, target);
    if (replacing) fs::remove_all(old);
  } catch (...) {  // the target as it was: the new store's folder removed, a replaced store put back
    fs::remove_all(tmp, ec);
    if (fs::exists(old, ec) && !fs::exists(target, ec)) fs::rename(old, target, ec);
    try {
      throw;
    } catch (const fs::filesystem_error& e) {
      throw InputError(fmt::format("{} '{}' cannot be written: {}", parameter_, path_, e.code().message()));
    }
  }
}

}  // namespace afmkit::io
