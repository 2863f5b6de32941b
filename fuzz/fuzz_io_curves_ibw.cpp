// libFuzzer target: the Asylum .ibw reader (Igor binary wave v5; afmkit/io/curves/read_curves.hpp). Invariants
// (curves_invariants.hpp): either InputError or curves with finite SI values, equal channel lengths, non-empty
// segments, positive calibration, and the same result when parsed again. The header checksum is not a barrier
// for the fuzzer: inputs whose first byte is odd get their checksum fixed, so the fields behind it are reached.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "curves_invariants.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  if ((data[0] & 1) && bytes.size() >= 384) {
    const bool little = bytes[0] != 0;
    bytes[2] = bytes[3] = 0;
    std::uint16_t sum = 0;
    for (std::size_t i = 0; i < 384; i += 2) {
      const auto a = static_cast<unsigned char>(bytes[i]), b = static_cast<unsigned char>(bytes[i + 1]);
      sum = static_cast<std::uint16_t>(sum + (little ? (a | b << 8) : (a << 8 | b)));
    }
    const auto fix = static_cast<std::uint16_t>(-sum);
    bytes[2] = static_cast<char>(little ? fix & 0xff : fix >> 8);
    bytes[3] = static_cast<char>(little ? fix >> 8 : fix & 0xff);
  }
  afmkit::io::curves::ReadOptions o;
  o.format = "ibw";
  curves_fuzz::check(bytes, ".ibw", o);
  return 0;
}
