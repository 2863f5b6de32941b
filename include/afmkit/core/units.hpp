#pragma once
// Units at one edge (docs/units.md). The library computes in SI (or, for the tapping model, in its normalised
// units); users read and write numbers in the units the parameters and columns declare ("nm", "kHz", "aJ", "L").
// A value crosses between the two in exactly one place:
//   * in:  a parameter declared with unit "nm" is read as SI by one function (cli::real_si: to_si(value, unit));
//   * out: a column, a results entry or a summary number is declared with a Unit, which both names the unit and
//          converts the program's value into it (io::ColumnOf, cli::UnitTagged).
// A command therefore never multiplies by 1e-9 or by a model scale itself.
#include <numbers>
#include <stdexcept>
#include <string>
#include <string_view>

namespace afmkit::units {

/// The unit a number is shown in and how a value of the program (SI, or the model's unit) becomes it:
/// value * multiply / divide. Two factors, so that a compound unit (a velocity L/t = length / time) converts
/// a value exactly as the product and quotient of its parts (no rounding of a pre-computed ratio).
struct Unit {
  std::string name;
  double multiply = 1.0;
  double divide = 1.0;

  double operator()(double value) const { return value * multiply / divide; }
  /// A value given in this unit, back in the program's (the inverse: value * divide / multiply).
  double internal(double value) const { return value * divide / multiply; }
  /// This unit per unit `per` ("nm/s" of "nm" and "s"): value * multiply / per.multiply (the units' own divisors
  /// must be 1).
  Unit per(const Unit& time) const {
    if (divide != 1.0 || time.divide != 1.0) throw std::logic_error("Unit::per of a unit with a divisor");
    return {name + "/" + time.name, multiply, time.multiply};
  }
  /// The same name and factors.
  friend bool operator==(const Unit&, const Unit&) = default;
};

/// The unit of numbers shown as they are computed (dimensionless, counts, rad, and SI values shown in SI).
inline Unit as_is(std::string name) { return {std::move(name), 1.0, 1.0}; }

/// A named unit of the SI (with its prefix) or a common multiple: the factor to SI and the one from SI, each the
/// exact literal the conversion uses (1e-9 and 1e9 for nm: 1/1e-9 is not 1e9 in floating point). from_si = 0: a
/// value leaves SI divided by to_si (deg: rad / (π/180), which gives back the degrees given more often than
/// rad * 180 / π does).
struct SiUnit {
  std::string_view name;
  double to_si;
  double from_si;
};

inline constexpr SiUnit kSiUnits[] = {
    {"m", 1.0, 1.0},     {"mm", 1e-3, 1e3},   {"um", 1e-6, 1e6},    {"µm", 1e-6, 1e6},     {"nm", 1e-9, 1e9},
    {"pm", 1e-12, 1e12}, {"s", 1.0, 1.0},     {"ms", 1e-3, 1e3},    {"us", 1e-6, 1e6},     {"µs", 1e-6, 1e6},
    {"Hz", 1.0, 1.0},    {"kHz", 1e3, 1e-3},  {"MHz", 1e6, 1e-6},   {"N", 1.0, 1.0},       {"nN", 1e-9, 1e9},
    {"pN", 1e-12, 1e12}, {"J", 1.0, 1.0},     {"aJ", 1e-18, 1e18},  {"zJ", 1e-21, 1e21},   {"Pa", 1.0, 1.0},
    {"kPa", 1e3, 1e-3},  {"MPa", 1e6, 1e-6},  {"GPa", 1e9, 1e-9},   {"N/m", 1.0, 1.0},     {"nm/s", 1e-9, 1e9},
    {"m/s", 1.0, 1.0},   {"m/V", 1.0, 1.0},   {"nm/V", 1e-9, 1e9},  {"rad", 1.0, 1.0},     {"kg", 1.0, 1.0},
    {"dimensionless", 1.0, 1.0},              {"deg", std::numbers::pi / 180.0, 0.0},
    {"eV", 1.602176634e-19, 0.0},  // the elementary charge times 1 V (exact in the SI since 2019)
};

/// The named unit `name` (std::logic_error when it is not in kSiUnits: a declaration naming an unknown unit is a
/// programming error, found by the first run that reads it, or by the compiler in a constant expression).
constexpr const SiUnit& si_unit(std::string_view name) {
  for (const SiUnit& u : kSiUnits)
    if (u.name == name) return u;
  throw std::logic_error("no SI conversion for the unit '" + std::string(name) + "' (afmkit/core/units.hpp)");
}

/// `value` given in `unit`, in SI (the one conversion of a user's number on its way in).
inline double to_si(double value, std::string_view unit) { return value * si_unit(unit).to_si; }

/// The Unit that shows an SI value in `name` ("nm": value * 1e9).
inline Unit from_si(std::string_view name) {
  const SiUnit& u = si_unit(name);
  if (u.from_si == 0.0) return {std::string(name), 1.0, u.to_si};
  return {std::string(name), u.from_si, 1.0};
}

/// Degrees from radians: value / (π/180).
inline Unit degrees_from_radians() { return from_si("deg"); }

}  // namespace afmkit::units
