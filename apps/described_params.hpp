#pragma once
// The command line's side of the library's options that describe themselves (afmkit/core/describe.hpp): one generic
// adapter instead of a hand-written copy per struct.
//   declare_fields(p, tapping::ShootingOptions{});   // its fields on a ParamSet: key, default, help, unit, range
//   tapping::ShootingOptions o;  read_fields(p, o);  // the resolved values back into the struct
// Each key is recorded as declared where the struct's describe() declares it (io::ParamSet::Description::
// declared_at), so a key shared by several commands has one declaration (tests/cli/test_declared_once.cpp).
#include <initializer_list>
#include "afmkit/core/source_location.hpp"
#include <string>
#include <vector>

#include "afmkit/core/describe.hpp"
#include "afmkit/core/units.hpp"
#include "afmkit/io/params.hpp"

namespace afmkit::cli {

/// The archive of declare_fields(): each field becomes a parameter of the current group, its value the default.
class FieldDeclarer {
 public:
  explicit FieldDeclarer(io::ParamSet& p) : p_(p) {}
  void real(const char* key, double value, const char* help, const char* unit, Range range,
            afmkit::SourceLocation where = afmkit::SourceLocation::current()) {
    p_.real(key, value, help, range, where).unit(unit);
  }
  template <class Int>
  void integer(const char* key, Int value, const char* help, long lo, long hi,
               afmkit::SourceLocation where = afmkit::SourceLocation::current()) {
    p_.integer(key, static_cast<long>(value), help, lo, hi, where);
  }
  template <class Enum>
  void choice(const char* key, Enum value, const char* help, std::initializer_list<Choice<Enum>> choices,
              afmkit::SourceLocation where = afmkit::SourceLocation::current()) {
    std::vector<std::string> names;
    std::string def;
    for (const Choice<Enum>& c : choices) {
      names.emplace_back(c.name);
      if (c.value == value) def = c.name;
    }
    p_.text(key, def, help, std::move(names), where);
  }

 private:
  io::ParamSet& p_;
};

/// The archive of read_fields(): each field takes its parameter's resolved value.
class FieldReader {
 public:
  explicit FieldReader(const io::ParamSet& p) : p_(p) {}
  void real(const char* key, double& field, const char*, const char*, Range,
            afmkit::SourceLocation = afmkit::SourceLocation::current()) const {
    field = p_.real(key);
  }
  template <class Int>
  void integer(const char* key, Int& field, const char*, long, long,
               afmkit::SourceLocation = afmkit::SourceLocation::current()) const {
    field = static_cast<Int>(p_.integer(key));  // the declared range fits Int
  }
  template <class Enum>
  void choice(const char* key, Enum& field, const char*, std::initializer_list<Choice<Enum>> choices,
              afmkit::SourceLocation = afmkit::SourceLocation::current()) const {
    const std::string& name = p_.text(key);
    for (const Choice<Enum>& c : choices)
      if (name == c.name) field = c.value;
  }

 private:
  const io::ParamSet& p_;
};

/// Declares every field `Options::describe` lists on `p` (in its order, in the current group), with the values of
/// `defaults` as defaults (usually `Options{}`: the library's own defaults).
template <class Options>
void declare_fields(io::ParamSet& p, const Options& defaults) {
  FieldDeclarer archive(p);
  Options::describe(archive, defaults);
}

/// Sets every described field of `options` from the resolved parameters of `p` (other fields are left as they are).
template <class Options>
void read_fields(const io::ParamSet& p, Options& options) {
  FieldReader archive(p);
  Options::describe(archive, options);
}

/// The numeric parameter `key` in SI: its value read in the unit it is declared in (ParamSet::unit, e.g. "nm") and
/// converted here, the one edge where a user's number becomes the library's (afmkit/core/units.hpp). A key declared
/// in a unit without an SI conversion is a programming error (std::logic_error).
inline double real_si(const io::ParamSet& p, const std::string& key) {
  return units::to_si(p.real(key), p.unit_of(key));
}

/// Records the value a run used for the numeric parameter `key` (ParamSet::record_used) from its SI value, in the
/// unit `key` is declared in: the way out of the same edge.
inline void record_used_si(io::ParamSet& p, const std::string& key, double value_in_si) {
  p.record_used(key, units::from_si(p.unit_of(key))(value_in_si));
}

}  // namespace afmkit::cli
