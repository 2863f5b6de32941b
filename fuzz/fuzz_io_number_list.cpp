// libFuzzer target: the number-list reader (afmkit/io/number_list.hpp). Invariants checked on every input: it
// either returns finite numbers or throws afmkit::InputError (nothing else); a returned list printed back as text
// (shortest round-trip form, one separator style) parses to the same values bit for bit; and every value is what
// the number parser gives for its own printed form.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/number_list.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<double> values;
  try {
    values = afmkit::io::parse_number_list(text, "fuzz");
  } catch (const afmkit::InputError&) {
    return 0;
  }
  for (double v : values)
    if (!std::isfinite(v)) std::abort();
  const std::vector<double> back = afmkit::io::parse_number_list(fmt::format("{}", fmt::join(values, "\n")), "back");
  if (back.size() != values.size()) std::abort();
  for (std::size_t i = 0; i < values.size(); ++i)
    if (std::memcmp(&back[i], &values[i], sizeof(double)) != 0) std::abort();
  return 0;
}
