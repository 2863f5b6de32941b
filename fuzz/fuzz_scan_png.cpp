// libFuzzer target: the 16-bit greyscale PNG reader (afmkit/scan/png16.hpp, libpng with setjmp error handling).
// Invariants checked on every input: it either returns a width × height image or throws afmkit::InputError (nothing
// else, no crash or leak on libpng's error path); the image encoded again and decoded gives the same pixels.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/png16.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  afmkit::scan::Grey16 image;
  try {
    image = afmkit::scan::parse_png16(bytes, "fuzz");
  } catch (const afmkit::InputError&) {
    return 0;
  }
  if (image.width < 1 || image.height < 1 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height))
    std::abort();
  const afmkit::scan::Grey16 back = afmkit::scan::parse_png16(afmkit::scan::format_png16(image), "back");
  if (back.width != image.width || back.height != image.height || back.pixels != image.pixels) std::abort();
  return 0;
}
