// The force-law registry for Python (python/afmkit/laws.py builds the law classes from `laws()`): each built-in law,
// the keys it reads (unit, default, range, help; the key a default follows), and whether it needs a force-curve file.
#include <pybind11/pybind11.h>

#include <algorithm>

#include "afmkit/impact/law_registry.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "bindings.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

py::list laws() {
  const impact::LawRegistry registry = impact::LawRegistry::builtin();
  py::list out;
  for (const std::string& name : registry.names()) {
    const impact::LawSpec& spec = registry.find(name);
    py::list keys;
    for (const impact::LawKey& k : registry.keys()) {
      if (std::find(spec.keys.begin(), spec.keys.end(), k.key) == spec.keys.end()) continue;
      py::dict d;
      d["key"] = k.key;
      d["unit"] = k.unit;
      d["si_unit"] = spectroscopy::law_si_unit(k.unit);     // the unit of the fit's SI values
      d["si_factor"] = spectroscopy::law_unit_to_si(k.unit);  // value in `unit` × si_factor = value in si_unit
      d["default"] = k.default_value;
      d["help"] = k.help;
      d["lower"] = k.lower;
      d["upper"] = k.upper;
      d["lower_open"] = k.lower_open;
      d["follows"] = k.follows;
      d["only_if_given"] = k.only_if_given;
      d["replaces"] = k.replaces;
      keys.append(d);
    }
    py::dict law;
    law["name"] = spec.name;
    law["summary"] = spec.summary;
    law["keys"] = keys;
    law["needs_force_curve"] = spec.needs_force_curve;
    law["piecewise_linear"] = spec.piecewise_linear;
    out.append(law);
  }
  return out;
}

}  // namespace

void bind_laws(py::module_& m) {
  m.def("laws", &laws,
        "The built-in force laws (docs/force-laws.md): name, summary, the keys each reads (unit, its SI unit and factor, default, range, "
        "help, followed key), whether it reads a force-curve file and whether it is piecewise linear (any "
        "consistent units).");
}

}  // namespace afmkit::python
