#pragma once
// `tapping orbit` run in-process as the Python module runs it (nothing printed), at a ~1 ms setting (Q = 2, one
// period multiple, 48 seeds): the tests of what the command layer does per run (issue 26, bench/command_layer.py).
#include <stdexcept>
#include <string>
#include <vector>

#include "afmkit/io/params.hpp"
#include "command.hpp"

namespace afmkit_test {

inline const afmkit::cli::CommandSpec& orbit_command_spec() {
  static const std::vector<afmkit::cli::CommandSpec> specs = afmkit::cli::command_specs();
  for (const auto& s : specs)
    if (s.path == "tapping orbit") return s;
  throw std::logic_error("no command tapping orbit");
}

/// The parameters of such a run. `output`: the table file ("" none); `units`: the units key, given when not empty
/// (separation 10 nm in physical units, 5 L otherwise).
inline afmkit::io::ParamSet orbit_params_as_python(const std::string& output = "", const std::string& units = "") {
  afmkit::io::ParamSet p;
  orbit_command_spec().declare(p);
  p.set_default("output", output);
  p.set_default("json", "true");  // as the Python module runs it: no summary lines printed
  p.resolve();
  if (!units.empty()) p.set_value("units", units);
  p.set_value("quality_factor", 2.0);
  p.set_value("max_period_multiple", 1L);
  p.set_value("separation", units == "physical" ? 10.0 : 5.0);
  return p;
}

}  // namespace afmkit_test
