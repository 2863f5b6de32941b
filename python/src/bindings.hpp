#pragma once
// The parts of the compiled module _afmkit (module.cpp assembles them).
#include <pybind11/pybind11.h>

namespace afmkit::python {

void bind_errors(pybind11::module_& m);           // errors.cpp: InvalidParameter, InputError, NumericalFailure
void bind_commands(pybind11::module_& m);         // commands.cpp: every command as run(path, kwargs)
void bind_realtime_filter(pybind11::module_& m);  // realtime_filter.cpp: the streaming filter on NumPy buffers
void bind_study(pybind11::module_& m);            // study_batch.cpp: one chunk of a parameter study, in C++
void bind_spectroscopy_prepare(pybind11::module_& m);  // spectroscopy_prepare.cpp: prepare() on NumPy arrays
void bind_spectroscopy_fit(pybind11::module_& m); // spectroscopy_fit.cpp: the law fit on NumPy arrays
void bind_spectroscopy_reconstruct(pybind11::module_& m);  // spectroscopy_reconstruct.cpp: force reconstruction
void bind_laws(pybind11::module_& m);              // laws.cpp: the force-law registry (afmkit.laws)
void bind_python_law(pybind11::module_& m);        // python_law.cpp: laws written in Python; any law's values
void bind_control_state_space(pybind11::module_& m);  // control_state_space.cpp: A, B, C, D of controller, plant

}  // namespace afmkit::python
