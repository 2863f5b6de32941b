#pragma once
// One way to print a physical quantity in a summary line: the SI prefix chosen by magnitude, so that a 245 nm
// radius reads "245 nm", not "0.000245 mm" (docs/units.md#summaries). Machine-readable outputs (CSV tables,
// sidecars, --json) keep their declared units; this is only for text meant to be read.
#include <string>
#include <string_view>

namespace afmkit::io {

/// `value`, expressed in `unit`, written as "<mantissa> <prefix><base>" with the SI prefix (a, f, p, n, µ, m,
/// none, k, M, G, T) that puts the mantissa in [1, 1000), rounded to `digits` significant digits (1 … 17). `unit` is a
/// base unit m, s, Hz, N, J or m/s, optionally with one of those prefixes ("nm", "kHz", "nN", "aJ", "nm/s",
/// "us" / "µs"). Beyond the prefixes the mantissa leaves [1, 1000) (1e-20 m: "0.01 am").
/// 0 is "0 <unit>"; undefined values follow docs/conventions.md#undefined-values: "nan <unit>", "inf <unit>",
/// "-inf <unit>". A unit outside that list is printed as given, the value unchanged ("{:.<digits>g} <unit>").
std::string quantity(double value, std::string_view unit, int digits = 4);

}  // namespace afmkit::io
