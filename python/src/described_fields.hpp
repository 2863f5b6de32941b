#pragma once
// Python's side of the library's options that describe themselves (afmkit/core/describe.hpp), as
// apps/described_params.hpp is the command line's: a struct's described fields read from a dict of keywords, and its
// defaults as a dict, so that a Python function takes its defaults from the struct's one declaration (and the
// library checks the declared ranges: InvalidParameter naming the key).
#include <initializer_list>
#include "afmkit/core/source_location.hpp"
#include <string>

#include <pybind11/pybind11.h>

#include "afmkit/core/describe.hpp"
#include "afmkit/core/error.hpp"

namespace afmkit::python {

/// The archive of read_fields(): a field takes the dict's value when the dict has its key, else keeps its own.
class DictFieldReader {
 public:
  explicit DictFieldReader(const pybind11::dict& d) : d_(d) {}
  void real(const char* key, double& field, const char*, const char*, Range,
            afmkit::SourceLocation = afmkit::SourceLocation::current()) const {
    if (d_.contains(key)) field = d_[key].cast<double>();
  }
  template <class Int>
  void integer(const char* key, Int& field, const char*, long, long,
               afmkit::SourceLocation = afmkit::SourceLocation::current()) const {
    if (d_.contains(key)) field = d_[key].cast<Int>();
  }
  template <class Enum>
  void choice(const char* key, Enum& field, const char*, std::initializer_list<Choice<Enum>> choices,
              afmkit::SourceLocation = afmkit::SourceLocation::current()) const {
    if (!d_.contains(key)) return;
    const auto name = d_[key].cast<std::string>();
    std::string names;
    for (const Choice<Enum>& c : choices) {
      if (name == c.name) {
        field = c.value;
        return;
      }
      names += (names.empty() ? "" : ", ") + std::string(c.name);
    }
    throw InvalidParameter(key, std::string(key) + " = '" + name + "' is not allowed: must be one of " + names);
  }

 private:
  const pybind11::dict& d_;
};

/// The archive of field_defaults(): key -> value (a choice by its name).
class DictFieldWriter {
 public:
  explicit DictFieldWriter(pybind11::dict& d) : d_(d) {}
  void real(const char* key, double value, const char*, const char*, Range,
            afmkit::SourceLocation = afmkit::SourceLocation::current()) {
    d_[key] = value;
  }
  template <class Int>
  void integer(const char* key, Int value, const char*, long, long,
               afmkit::SourceLocation = afmkit::SourceLocation::current()) {
    d_[key] = value;
  }
  template <class Enum>
  void choice(const char* key, Enum value, const char*, std::initializer_list<Choice<Enum>> choices,
              afmkit::SourceLocation = afmkit::SourceLocation::current()) {
    for (const Choice<Enum>& c : choices)
      if (c.value == value) d_[key] = std::string(c.name);
  }

 private:
  pybind11::dict& d_;
};

/// Sets the described fields of `options` that `d` has a key for.
template <class Options>
void read_fields(const pybind11::dict& d, Options& options) {
  DictFieldReader archive(d);
  Options::describe(archive, options);
}

/// The described fields of `options` (usually Options{}: the library's defaults) as a dict.
template <class Options>
pybind11::dict field_defaults(const Options& options) {
  pybind11::dict d;
  DictFieldWriter archive(d);
  Options::describe(archive, options);
  return d;
}

}  // namespace afmkit::python
