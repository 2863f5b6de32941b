#pragma once
// Validation helpers for value-type constructors: each throws afmkit::InvalidParameter with a message
// "<name> = <value> is out of range: must be <range>".
#include <string>

namespace afmkit::validate {

/// value must be a finite number
double finite(const std::string& name, double value);
/// value > 0 (and finite)
double positive(const std::string& name, double value);
/// value >= 0 (and finite)
double non_negative(const std::string& name, double value);
/// lo <= value <= hi (closed interval; finite)
double in_range(const std::string& name, double value, double lo, double hi);
/// integer lo <= value <= hi
long in_range(const std::string& name, long value, long lo, long hi);
/// Throw InvalidParameter(name, "<name> = <value> is out of range: must be <requirement>") if !ok.
void require(bool ok, const std::string& name, double value, const std::string& requirement);

}  // namespace afmkit::validate
