#pragma once
// Options that describe themselves (the model: Drake's `Serialize(Archive*)`). An options struct of the library
// declares each field the user may set ONCE, in a static member template
//
//   template <class Archive, class Self>
//   static void describe(Archive& a, Self& o) {   // Self: the struct, const or not
//     a.real("shooting_tolerance", o.tolerance, "Newton convergence of periodic orbits |P(y) - y| / |y|",
//            "dimensionless", Range::open(0.0, 1.0));
//     a.integer("max_newton_iterations", o.max_iterations, "Newton iterations per shooting solve", 1, 1000);
//     Nested::describe(a, o.nested);               // a member struct: its own fields
//   }
//
// giving the key (the TOML key, flag and Python keyword), the help, the unit (docs/units.md) and the allowed range;
// the default is the member's initializer. An archive is any type with these members (all take the declaring call's
// afmkit::SourceLocation as a defaulted last argument, so that a front end can tell where a key is declared):
//   real(key, double& field, help, unit, Range)
//   integer(key, int-or-long& field, help, long lo, long hi)
//   choice(key, Enum& field, help, std::initializer_list<Choice<Enum>>)    (a text with a closed list of values)
// The library itself uses check_fields() (validated constructors: the declared range is the one checked); the
// command line declares the fields on its parameter sets and reads them back (apps/described_params.hpp), so that
// a default, a range or a help text lives in one place.
#include <initializer_list>
#include "afmkit/core/source_location.hpp"
#include <string>

#include "afmkit/core/error.hpp"
#include "afmkit/core/range.hpp"

namespace afmkit {

/// One value of a choice field: its name (as given in TOML, flags and Python) and the enumerator.
template <class Enum>
struct Choice {
  const char* name;
  Enum value;
};

namespace detail {
[[noreturn]] void throw_out_of_range(const char* key, double value, const Range& range);
[[noreturn]] void throw_out_of_range(const char* key, long value, long lo, long hi);
}  // namespace detail

/// The archive of check_fields(): throws InvalidParameter naming the key ("<key> = <value> is out of range: must be
/// <range>") for the first field outside its declared range. Cheap when all fields are valid (no strings built).
class FieldChecker {
 public:
  void real(const char* key, double value, const char*, const char*, Range range,
            afmkit::SourceLocation = afmkit::SourceLocation::current()) const {
    if (!range.contains(value)) detail::throw_out_of_range(key, value, range);
  }
  template <class Int>
  void integer(const char* key, Int value, const char*, long lo, long hi,
               afmkit::SourceLocation = afmkit::SourceLocation::current()) const {
    if (static_cast<long>(value) < lo || static_cast<long>(value) > hi)
      detail::throw_out_of_range(key, static_cast<long>(value), lo, hi);
  }
  template <class Enum>
  void choice(const char*, Enum, const char*, std::initializer_list<Choice<Enum>>,
              afmkit::SourceLocation = afmkit::SourceLocation::current()) const {}
};

/// Checks every described field of `options` against its declared range (InvalidParameter naming the key).
template <class Options>
void check_fields(const Options& options) {
  FieldChecker checker;
  Options::describe(checker, options);
}

}  // namespace afmkit
