#pragma once
// Units of the columns of force-curve files (docs/curve-files.md#units): each converted to SI at this one edge.
#include <optional>
#include <string_view>

namespace afmkit::io::curves::detail {

/// What a unit measures.
enum class Quantity { length, voltage, current, force, time };

/// A unit: its quantity and the factor to its SI unit (m, V, A, N, s).
struct Unit {
  Quantity quantity;
  double scale;
};

/// The unit named `text` ("nm", "um", "µm", "m", "pm", "V", "mV", "nA", "N", "nN", "pN", "s", "ms", …;
/// case-sensitive, as SI prefixes are), or nullopt when it is not one this reader knows.
std::optional<Unit> parse_unit(std::string_view text);

/// "length", "voltage", "current", "force", "time".
const char* to_string(Quantity quantity);

/// The units parse_unit knows, for messages: "m, mm, um, µm, nm, pm, V, mV, uV, A, uA, nA, pA, N, mN, uN, nN, pN, s, ms, us".
const char* known_units();

}  // namespace afmkit::io::curves::detail
