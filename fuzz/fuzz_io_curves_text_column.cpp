// libFuzzer target: one numeric column of a delimited text file (afmkit/io/curves/text_column.hpp; what
// `afmkit control simulate --signal-file F --signal-column C` reads). The first byte gives the length (0-15) of the
// column choice that follows it (a name, a 1-based position of any length, or empty); the rest is the file.
// Invariants: either InputError, or a non-empty column of finite numbers, the same when parsed again.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/io/curves/text_column.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t length = data[0] % 16;
  if (size < 1 + length) return 0;
  const std::string column(reinterpret_cast<const char*>(data + 1), length);
  const std::string text(reinterpret_cast<const char*>(data + 1 + length), size - 1 - length);
  std::vector<double> values;
  try {
    values = afmkit::io::curves::parse_text_column(text, "fuzz.csv", column);
  } catch (const afmkit::InputError&) {
    return 0;
  }
  if (values.empty()) std::abort();
  for (double v : values)
    if (!std::isfinite(v)) std::abort();
  const std::vector<double> again = afmkit::io::curves::parse_text_column(text, "fuzz.csv", column);
  if (again.size() != values.size() || std::memcmp(again.data(), values.data(), values.size() * sizeof(double)) != 0)
    std::abort();
  return 0;
}
