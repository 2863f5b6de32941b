#pragma once
// Writing a Zarr (version 2) store: the labelled-array layout of parameter studies (docs/study.md#the-store), which
// xarray opens with xr.open_zarr. A group of arrays, each a folder with `.zarray` (shape, chunks, dtype, fill
// value; no compressor) and `.zattrs` (`_ARRAY_DIMENSIONS` naming its axes, `units`, …), its chunks raw
// little-endian C-order files named by chunk index ("3", "0.2"; edge chunks padded to the full chunk shape), and
// the consolidated metadata `.zmetadata`.
//
// The store is built in memory and written by commit(): into a temporary folder beside the target, then renamed
// into place with SIGINT/SIGTERM/SIGHUP held back, so a store is complete or absent, never half-written. An
// existing target is replaced only when it is an afmkit store (its root attributes carry afmkit_study_format);
// anything else there is refused.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace afmkit::io {

class ZarrStoreWriter {
 public:
  /// Checks the target now (before any computation): `parameter` names it in errors. InvalidParameter when `path`
  /// is empty, is a file, or is a folder that is not an afmkit store, or its parent cannot be created or written.
  ZarrStoreWriter(std::string path, std::string parameter);

  /// Root attribute (the group's `.zattrs`).
  void attribute(const std::string& key, nlohmann::json value);
  /// A coordinate: a 1-D float64 array `name` over the axis `name`, one chunk, no fill value (so that no
  /// coordinate value, 0.0 included, reads back as missing).
  void coordinate(const std::string& name, const std::vector<double>& values, nlohmann::json attrs);
  /// A float64 variable over `dims` (sizes `shape`), values in C order, cut into `chunks`; fill value NaN
  /// (docs/conventions.md: NaN is "undefined").
  void variable(const std::string& name, const std::vector<std::string>& dims, const std::vector<std::size_t>& shape,
                const std::vector<std::size_t>& chunks, const std::vector<double>& values, nlohmann::json attrs);
  /// An integer variable stored as `dtype` ("<i1", "<i4"), fill value 0.
  void integer_variable(const std::string& name, const std::vector<std::string>& dims,
                        const std::vector<std::size_t>& shape, const std::vector<std::size_t>& chunks,
                        const std::vector<std::int64_t>& values, const std::string& dtype, nlohmann::json attrs);
  /// Writes the store (see above). InputError when the file system refuses (the target is left as it was).
  void commit();

  const std::string& path() const& { return path_; }

 private:
  struct Array {
    std::string name;
    nlohmann::json zarray, zattrs;
    std::vector<std::size_t> shape, chunks;
    std::size_t item = 8;
    std::vector<unsigned char> data;  // C order, little endian, item bytes each
    std::vector<unsigned char> fill;  // one item
  };
  void add(Array a);
  std::string path_, parameter_;
  nlohmann::json attrs_ = nlohmann::json::object();
  std::vector<Array> arrays_;
};

}  // namespace afmkit::io
