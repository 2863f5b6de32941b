// libFuzzer target: the ASCII matrix reader (afmkit/scan/ascii_matrix.hpp). Invariants checked on every input: it
// either returns a rows × columns matrix of finite numbers or throws afmkit::InputError (nothing else); the matrix
// printed back (shortest round-trip form, one row per line) parses to the same shape and the same values bit for
// bit.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/ascii_matrix.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  afmkit::scan::AsciiMatrix m;
  try {
    m = afmkit::scan::parse_ascii_matrix(text, "fuzz");
  } catch (const afmkit::InputError&) {
    return 0;
  }
  if (m.rows < 1 || m.columns < 1 || m.values.size() != static_cast<std::size_t>(m.rows * m.columns)) std::abort();
  std::string printed;
  for (long j = 0; j < m.rows; ++j) {
    for (long i = 0; i < m.columns; ++i) {
      const double v = m.values[static_cast<std::size_t>(j * m.columns + i)];
      if (!std::isfinite(v)) std::abort();
      if (i > 0) printed += ", ";
      printed += fmt::format("{}", v);
    }
    printed += '\n';
  }
  const afmkit::scan::AsciiMatrix back = afmkit::scan::parse_ascii_matrix(printed, "back");
  if (back.rows != m.rows || back.columns != m.columns) std::abort();
  if (std::memcmp(back.values.data(), m.values.data(), m.values.size() * sizeof(double)) != 0) std::abort();
  return 0;
}
