// afmkit's errors as Python exceptions: InvalidParameter and InputError derive from ValueError (bad input, the
// command line's exit status 2), NumericalFailure from RuntimeError (status 1). The message is the command line's.
#include <pybind11/pybind11.h>

#include "afmkit/core/error.hpp"
#include "bindings.hpp"

namespace py = pybind11;

namespace afmkit::python {

void bind_errors(py::module_& m) {
  static py::exception<InvalidParameter> invalid(m, "InvalidParameter", PyExc_ValueError);
  static py::exception<InputError> input(m, "InputError", PyExc_ValueError);
  static py::exception<NumericalFailure> numerical(m, "NumericalFailure", PyExc_RuntimeError);
  invalid.doc() = "A parameter is out of its allowed range or of the wrong kind; .parameter names it.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InvalidParameter& e) {
      py::object err = py::reinterpret_borrow<py::object>(invalid)(e.what());
      err.attr("parameter") = e.parameter();
      PyErr_SetObject(invalid.ptr(), err.ptr());
    } catch (const InputError& e) {
      input(e.what());
    } catch (const NumericalFailure& e) {
      numerical(e.what());
    }
  });
}

}  // namespace afmkit::python
