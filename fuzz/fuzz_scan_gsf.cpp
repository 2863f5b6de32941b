// libFuzzer target: the Gwyddion Simple Field reader (afmkit/scan/gsf.hpp). Invariants checked on every input: it
// either returns a valid HeightMap or throws afmkit::InputError (nothing else); the map written back (data file and
// mask file) and read back gives the same grid, units, title, validity and, bit for bit, the same valid values.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/gsf.hpp"

namespace {
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  std::optional<afmkit::scan::GsfField> parsed;
  try {
    parsed.emplace(afmkit::scan::parse_gsf(bytes, "fuzz"));
  } catch (const afmkit::InputError&) {
    return 0;
  }
  const afmkit::scan::HeightMap& m = parsed->map;
  const std::string again = afmkit::scan::format_gsf(m, parsed->title);
  const std::string mask = afmkit::scan::format_gsf_mask(m, parsed->title);
  const afmkit::scan::GsfField back = afmkit::scan::parse_gsf_with_mask(again, "again", mask, "mask");
  const afmkit::scan::HeightMap& b = back.map;
  if (b.x_resolution() != m.x_resolution() || b.y_resolution() != m.y_resolution()) std::abort();
  if (!same_bits(b.x_size(), m.x_size()) || !same_bits(b.y_size(), m.y_size())) std::abort();
  if (!same_bits(b.x_offset(), m.x_offset()) || !same_bits(b.y_offset(), m.y_offset())) std::abort();
  if (b.z_unit() != m.z_unit() || back.title != parsed->title) std::abort();
  for (long j = 0; j < m.y_resolution(); ++j)
    for (long i = 0; i < m.x_resolution(); ++i) {
      if (b.valid(i, j) != m.valid(i, j)) std::abort();
      if (m.valid(i, j) && !same_bits(b(i, j), m(i, j))) std::abort();
    }
  return 0;
}
