// SI-prefixed quantities for summaries (quantity.hpp).
#include "afmkit/io/quantity.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include <fmt/format.h>

namespace afmkit::io {

namespace {

struct Prefix {
  std::string_view text;
  int exponent;  // power of 1000
};
// From atto to tera; "u" and "μ" (Greek mu) are read but never written ("µ", the micro sign, is).
constexpr std::array<Prefix, 11> written{{{"a", -6}, {"f", -5}, {"p", -4}, {"n", -3}, {"\xC2\xB5", -2}, {"m", -1}, {"", 0},
                                          {"k", 1}, {"M", 2}, {"G", 3}, {"T", 4}}};
constexpr std::array<Prefix, 13> readable{{{"a", -6}, {"f", -5}, {"p", -4}, {"n", -3}, {"\xC2\xB5", -2},
                                           {"\xCE\xBC", -2}, {"u", -2}, {"m", -1}, {"", 0}, {"k", 1}, {"M", 2},
                                           {"G", 3}, {"T", 4}}};
constexpr std::array<std::string_view, 6> bases{"m/s", "Hz", "m", "s", "N", "J"};

/// The base unit and the power of 1000 of `unit`'s prefix, if it is one this function knows.
std::optional<std::pair<std::string_view, int>> split_unit(std::string_view unit) {
  for (std::string_view base : bases) {
    if (unit.size() < base.size() || unit.substr(unit.size() - base.size()) != base) continue;
    const std::string_view prefix = unit.substr(0, unit.size() - base.size());
    for (const Prefix& p : readable)
      if (p.text == prefix) return std::pair{base, p.exponent};
  }
  return std::nullopt;
}

}  // namespace

std::string quantity(double value, std::string_view unit, int digits) {
  digits = std::clamp(digits, 1, 17);
  if (std::isnan(value)) return fmt::format("nan {}", unit);  // one spelling, never "-nan"
  if (std::isinf(value)) return fmt::format("{} {}", value > 0 ? "inf" : "-inf", unit);
  const auto parts = split_unit(unit);
  if (!parts || value == 0.0) return fmt::format("{:.{}g} {}", value, digits, unit);
  const auto base = parts->first;  // (a structured binding cannot be captured by clang 14's lambdas)
  const int from = parts->second;
  // the exponent of 1000 that puts |value| · 1000^from in [1, 1000), after rounding to `digits`
  const double magnitude = std::abs(value);
  int k = static_cast<int>(std::floor(std::log10(magnitude) / 3.0)) + from;
  k = std::clamp(k, written.front().exponent, written.back().exponent);
  auto mantissa = [&](int e) { return value * std::pow(1000.0, from - e); };
  double m = mantissa(k);
  // rounding may carry to 1000 (999.96 → "1000" at 4 digits): then the next prefix
  const double rounded = std::stod(fmt::format("{:.{}g}", std::abs(m), digits));
  if (rounded >= 1000.0 && k < written.back().exponent) m = mantissa(++k);
  const Prefix& p = written[static_cast<std::size_t>(k - written.front().exponent)];
  return fmt::format("{:.{}g} {}{}", m, digits, p.text, base);
}

bool si_unit(std::string_view unit) { return split_unit(unit).has_value(); }

namespace {
/// `value` to `digits` significant digits, undefined values spelled as in docs/conventions.md#undefined-values.
std::string number(double value, int digits) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return fmt::format("{:.{}g}", value, std::clamp(digits, 1, 17));
}
}  // namespace

std::string normalised(double value, std::string_view unit, int digits, std::string_view physical) {
  return physical.empty() ? fmt::format("{} (normalised, units of {})", number(value, digits), unit)
                          : fmt::format("{} (normalised, units of {}; {})", number(value, digits), unit, physical);
}

std::string summary_value(double value, std::string_view unit, int digits) {
  return si_unit(unit) ? quantity(value, unit, digits) : normalised(value, unit, digits);
}

std::string summary_values(const std::vector<double>& values, std::string_view unit, int digits) {
  if (values.empty()) return "none";
  std::string out;
  const bool si = si_unit(unit);
  for (std::size_t i = 0; i < values.size(); ++i)
    out += (i ? ", " : "") + (si ? quantity(values[i], unit, digits) : number(values[i], digits));
  return si ? out : fmt::format("{} (normalised, units of {})", out, unit);
}

}  // namespace afmkit::io
