// libFuzzer target: the number parser of flag values (afmkit/io/number.hpp). Invariants checked on every
// input: a parsed real agrees bit for bit with the C library's strtod on the same text (the independent
// reference) and survives a print/parse round trip; a parsed integer is exactly the real value of its text.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "afmkit/io/number.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto real = afmkit::io::parse_real(text);
  const auto integer = afmkit::io::parse_integer(text);
  if (real && !std::isnan(*real)) {
    // strtod accepts more (leading spaces, hex); whenever ours accepts, both must agree exactly.
    char* end = nullptr;
    const double reference = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size() || std::memcmp(&reference, &*real, sizeof reference) != 0) std::abort();
    const auto back = afmkit::io::parse_real(fmt::format("{}", *real));
    if (!back || std::memcmp(&*back, &*real, sizeof *back) != 0) std::abort();
  }
  if (integer) {
    if (!real && text.find_first_not_of("+-0123456789") != std::string::npos) std::abort();
    if (real && std::abs(*real) < 9007199254740992.0 && static_cast<double>(*integer) != *real) std::abort();
    const auto back = afmkit::io::parse_integer(fmt::format("{}", *integer));
    if (!back || *back != *integer) std::abort();
  }
  return 0;
}
