#include "units.hpp"

#include <array>
#include <string_view>

namespace afmkit::io::curves::detail {

namespace {

struct Entry {
  std::string_view name;
  Unit unit;
};

// "u", the micro sign U+00B5 and the Greek mu U+03BC all mean micro.
constexpr std::array<Entry, 32> kUnits{{
    {"m", {Quantity::length, 1.0}},          {"mm", {Quantity::length, 1e-3}},
    {"um", {Quantity::length, 1e-6}},        {"\xC2\xB5m", {Quantity::length, 1e-6}},
    {"\xCE\xBCm", {Quantity::length, 1e-6}}, {"nm", {Quantity::length, 1e-9}},
    {"pm", {Quantity::length, 1e-12}},       {"V", {Quantity::voltage, 1.0}},
    {"mV", {Quantity::voltage, 1e-3}},       {"uV", {Quantity::voltage, 1e-6}},
    {"\xC2\xB5V", {Quantity::voltage, 1e-6}}, {"A", {Quantity::current, 1.0}},
    {"mA", {Quantity::current, 1e-3}},       {"uA", {Quantity::current, 1e-6}},
    {"\xC2\xB5"
     "A",
     {Quantity::current, 1e-6}},
    {"nA", {Quantity::current, 1e-9}},       {"pA", {Quantity::current, 1e-12}},
    {"N", {Quantity::force, 1.0}},           {"mN", {Quantity::force, 1e-3}},
    {"uN", {Quantity::force, 1e-6}},         {"\xC2\xB5N", {Quantity::force, 1e-6}},
    {"\xCE\xBCN", {Quantity::force, 1e-6}},  {"nN", {Quantity::force, 1e-9}},
    {"pN", {Quantity::force, 1e-12}},        {"s", {Quantity::time, 1.0}},
    {"sec", {Quantity::time, 1.0}},          {"ms", {Quantity::time, 1e-3}},
    {"us", {Quantity::time, 1e-6}},          {"\xC2\xB5s", {Quantity::time, 1e-6}},
    {"\xCE\xBCs", {Quantity::time, 1e-6}},   {"microns", {Quantity::length, 1e-6}},
    {"micron", {Quantity::length, 1e-6}},
}};

}  // namespace

std::optional<Unit> parse_unit(std::string_view text) {
  for (const Entry& e : kUnits)
    if (e.name == text) return e.unit;
  return std::nullopt;
}

const char* to_string(Quantity quantity) {
  switch (quantity) {
    case Quantity::length: return "length";
    case Quantity::voltage: return "voltage";
    case Quantity::current: return "current";
    case Quantity::force: return "force";
    case Quantity::time: return "time";
  }
  return "?";
}

const char* known_units() {
  return "m, mm, um (or \xC2\xB5m), nm, pm; V, mV, uV; A, mA, uA, nA, pA; N, mN, uN, nN, pN; s, ms, us";
}

}  // namespace afmkit::io::curves::detail
