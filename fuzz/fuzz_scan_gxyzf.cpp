// libFuzzer target: the Gwyddion XYZ Field reader (afmkit/scan/gxyzf.hpp). Invariants checked on every input: it
// either returns a valid point cloud or throws afmkit::InputError (nothing else); written back it is the same file
// content: read again, every coordinate and value is the same bit for bit, with the same titles and units.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/gxyzf.hpp"

namespace {
bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  std::optional<afmkit::scan::XyzField> field;
  try {
    field.emplace(afmkit::scan::parse_gxyzf(bytes, "fuzz"));
  } catch (const afmkit::InputError&) {
    return 0;
  }
  const afmkit::scan::XyzField back = afmkit::scan::parse_gxyzf(afmkit::scan::format_gxyzf(*field), "back");
  if (!same_bits(back.x(), field->x()) || !same_bits(back.y(), field->y())) std::abort();
  if (back.xy_unit() != field->xy_unit() || back.channels().size() != field->channels().size()) std::abort();
  for (std::size_t c = 0; c < back.channels().size(); ++c) {
    const auto& a = back.channels()[c];
    const auto& b = field->channels()[c];
    if (a.title != b.title || a.unit != b.unit || !same_bits(a.values, b.values)) std::abort();
  }
  return 0;
}
