#pragma once
// The cantilever's keys, declared once for every command that takes them (tests/cli/test_declared_once.cpp): the
// tapping commands (physical units), spectroscopy prepare, fit and reconstruct. The key and its unit are declared
// here, the range of a value it is given with by the library (afmkit/tapping/cantilever_limits.hpp, in SI: the
// library's settings check the same range); each command says how it takes the key (its default, required, or the
// input file's) and its help (what the key means there: AM only, FM only, required for AM curves, …).
#include <string>

#include "afmkit/io/params.hpp"

namespace afmkit::cli {

enum class CantileverKey {
  spring_constant,      // k, N/m, in (0, 1e6]
  resonance_frequency,  // f0, kHz, in (0, 1e7]
  quality_factor,       // Q, dimensionless, in (0, 1e9]
  free_amplitude,       // A0 at the drive frequency, a length, in (0, 1e6]
  amplitude             // FM: the oscillation amplitude A held by the amplitude loop, a length, in (0, 1e6]
};

/// How a command takes a cantilever key.
struct CantileverDefault {
  enum class Kind {
    value,     // a default, in the key's range (0, upper]
    required,  // 0 until given (--help: "required"); in [0, upper] here, the command refuses 0 naming the key
    the_files  // the input file's unless given (--help: "the file's"); any number here, the reader checks it
  };
  Kind kind = Kind::value;
  double value = 0.0;
  static CantileverDefault of(double value) { return {Kind::value, value}; }
  static CantileverDefault required() { return {Kind::required, 0.0}; }
  static CantileverDefault the_files() { return {Kind::the_files, 0.0}; }
};

/// Declares `key` on `p` (in the current group) as the command takes it, with the command's `help`. `length_unit`:
/// the unit of the lengths (free_amplitude, amplitude): nm, or the tapping commands' "nm (physical) or L
/// (normalised)".
void add_cantilever_param(io::ParamSet& p, CantileverKey key, CantileverDefault how, const std::string& help,
                          const char* length_unit = "nm");

}  // namespace afmkit::cli
