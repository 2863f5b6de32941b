#include "afmkit/io/number.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>

namespace afmkit::io {

namespace {
std::string_view without_plus(std::string_view text) {
  if (text.size() > 1 && text.front() == '+' && text[1] != '-' && text[1] != '+') text.remove_prefix(1);
  return text;
}
}  // namespace

std::optional<double> parse_real(std::string_view text) {
  text = without_plus(text);
  if (text.empty()) return std::nullopt;
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::optional<long> parse_integer(std::string_view text) {
  const std::string_view t = without_plus(text);
  if (t.empty()) return std::nullopt;
  long value = 0;
  const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (error == std::errc() && end == t.data() + t.size()) return value;
  if (error == std::errc::result_out_of_range) return std::nullopt;
  const std::optional<double> real = parse_real(t);
  // 2^63 is exactly representable; every double below it in magnitude with an integral value fits a long.
  constexpr double limit = 9223372036854775808.0;
  if (!real || !std::isfinite(*real) || *real != std::floor(*real) || !(*real < limit) || !(*real >= -limit))
    return std::nullopt;
  return static_cast<long>(*real);
}

}  // namespace afmkit::io
