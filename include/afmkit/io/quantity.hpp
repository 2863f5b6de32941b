#pragma once
// One way to print a physical quantity in a summary line: the SI prefix chosen by magnitude, so that a 245 nm
// radius reads "245 nm", not "0.000245 mm" (docs/units.md#summaries). Machine-readable outputs (CSV tables,
// sidecars, --json) keep their declared units; this is only for text meant to be read.
#include <string>
#include <string_view>
#include <vector>

namespace afmkit::io {

/// `value`, expressed in `unit`, written as "<mantissa> <prefix><base>" with the SI prefix (a, f, p, n, µ, m,
/// none, k, M, G, T) that puts the mantissa in [1, 1000), rounded to `digits` significant digits (1 … 17). `unit` is a
/// base unit m, s, Hz, N, J or m/s, optionally with one of those prefixes ("nm", "kHz", "nN", "aJ", "nm/s",
/// "us" / "µs"). Beyond the prefixes the mantissa leaves [1, 1000) (1e-20 m: "0.01 am").
/// 0 is "0 <unit>"; undefined values follow docs/conventions.md#undefined-values: "nan <unit>", "inf <unit>",
/// "-inf <unit>". A unit outside that list is printed as given, the value unchanged ("{:.<digits>g} <unit>").
std::string quantity(double value, std::string_view unit, int digits = 4);

/// Whether quantity() knows `unit` (an SI base unit of its list, with or without a prefix).
bool si_unit(std::string_view unit);

/// A number of a normalised model — the tapping model's L, t, L/t^2, L^2/t^2 (docs/units.md), the control commands'
/// Omega and T — said plainly to be one: "0.35 (normalised, units of L)". Undefined values as quantity().
/// `physical` (when not empty) is the same value in physical units, added: "0.31 (normalised, units of T; 3.1 ms)".
std::string normalised(double value, std::string_view unit, int digits = 4, std::string_view physical = {});

/// A length, time, frequency, force or energy of a summary line in the unit its command reports it in: quantity()
/// when `unit` is an SI unit, else (a normalised unit) normalised(). Numbers without a dimension (counts, ratios,
/// phases in rad) are not for this function.
std::string summary_value(double value, std::string_view unit, int digits = 4);

/// A list of such values: "0.2 nm, 450 pm" (SI) or "0.2, 0.45 (normalised, units of L)"; "none" when empty.
std::string summary_values(const std::vector<double>& values, std::string_view unit, int digits = 4);

}  // namespace afmkit::io
