// libFuzzer target: the text readers of force curves (afmkit/io/curves/read_curves.hpp: "text" and the presets).
// The first byte picks the format (and a decimal/separator choice), the rest is the file. Invariants
// (curves_invariants.hpp): either InputError or curves with finite SI values, equal channel lengths, non-empty
// segments, positive calibration, and the same result when parsed again.
#include <cstddef>
#include <cstdint>
#include <string>

#include "curves_invariants.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const formats[] = {"text", "jpk-txt", "asylum-txt", "nanoscope-txt", "ntmdt-txt",
                                        "afmworkshop-csv", "auto"};
  afmkit::io::curves::ReadOptions o;
  o.format = formats[data[0] % 7];
  if (data[0] & 0x80) o.decimal = "comma";
  if (data[0] & 0x40) o.height_direction = "towards";
  if (o.format == "text" && (data[0] & 0x20)) {  // units by option, columns by position
    o.height.position = 1;
    o.height.unit = "nm";
    o.deflection.position = 2;
    o.deflection.unit = "V";
  }
  curves_fuzz::check(std::string(reinterpret_cast<const char*>(data + 1), size - 1), ".txt", o);
  return 0;
}
