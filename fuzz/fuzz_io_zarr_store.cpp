// libFuzzer target: what the Zarr store writer reads of an existing folder at its target (afmkit/io/zarr_store.hpp):
// the root `.zattrs`, to decide whether the folder is an afmkit store (replaced) or anything else (refused). Input =
// the text of that `.zattrs`. Invariants: the writer is constructed exactly when the text is a JSON object with
// the key afmkit_study_format, and otherwise refuses with afmkit::InvalidParameter naming `store`. Nothing else
// (no crash, no other exception, no sanitizer report).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/zarr_store.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fs = std::filesystem;
  static const fs::path dir = fs::temp_directory_path() / ("afmkit-fuzz-zarr-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    std::ofstream out(dir / ".zattrs", std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  const std::string text(reinterpret_cast<const char*>(data), size);
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  const bool afmkit_store = j.is_object() && j.contains("afmkit_study_format");
  try {
    afmkit::io::ZarrStoreWriter writer(dir.string(), "store");
    if (!afmkit_store) std::abort();
  } catch (const afmkit::InvalidParameter& e) {
    if (afmkit_store || e.parameter() != "store") std::abort();
  }
  return 0;
}
