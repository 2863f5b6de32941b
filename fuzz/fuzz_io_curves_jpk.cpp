// libFuzzer target: the JPK .jpk-force reader (zip archive through libzip; afmkit/io/curves/read_curves.hpp).
// Invariants (curves_invariants.hpp): either InputError or curves with finite SI values, equal channel lengths,
// non-empty segments, positive calibration, and the same result when parsed again. Entry sizes are checked
// before allocation, so -rss_limit_mb catches any size the reader would believe.
#include <cstddef>
#include <cstdint>
#include <string>

#include "curves_invariants.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  afmkit::io::curves::ReadOptions o;
  o.format = "jpk-force";
  curves_fuzz::check(std::string(reinterpret_cast<const char*>(data), size), ".jpk-force", o);
  return 0;
}
