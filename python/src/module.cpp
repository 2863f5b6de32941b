// The compiled part of the Python package afmkit (python/afmkit/__init__.py is the public face; docs/python.md).
#include <pybind11/pybind11.h>

#include "afmkit/core/version.hpp"
#include "bindings.hpp"

PYBIND11_MODULE(_afmkit, m) {
  m.doc() = "afmkit compiled core: the commands of the afmkit program and the real-time filter";
  m.attr("__version__") = std::string(afmkit::version);
  afmkit::python::bind_errors(m);
  afmkit::python::bind_commands(m);
  afmkit::python::bind_realtime_filter(m);
  afmkit::python::bind_study(m);
  afmkit::python::bind_spectroscopy_prepare(m);
  afmkit::python::bind_spectroscopy_fit(m);
  afmkit::python::bind_spectroscopy_reconstruct(m);
  afmkit::python::bind_laws(m);
  afmkit::python::bind_python_law(m);
  afmkit::python::bind_control_state_space(m);
}
