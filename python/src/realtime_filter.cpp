// afmkit.control.RealtimeFilter: the streaming first-harmonic rejection filter (include/afmkit/control/
// realtime_filter.hpp) on NumPy buffers. Keyword arguments are those of `afmkit control export` (the same filter
// the C core runs): rotation_frequency [rad/s], harmonics, alpha and beta [Ω], gain [Ω], rejected, sample_rate
// [samples/s], input_limit.
#include <optional>
#include <span>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/control/settings.hpp"
#include "afmkit/core/error.hpp"
#include "bindings.hpp"
#include "command.hpp"
#include "control_params.hpp"
#include "params_from_python.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

control::RealtimeFilter make_filter(const py::kwargs& kwargs) {
  io::ParamSet p = params_from_python("control export", "afmkit.control.RealtimeFilter", kwargs,
                                      {"output", "json", "format", "precision", "target_memory", "test_vectors"});
  const control::ControlSettings c = cli::control_settings_from(p);
  if (c.controller != control::ControllerKind::Bank)
    throw InvalidParameter("controller", "controller must be bank for the real-time filter");
  const control::ControlSettingsSi si = control::to_si(c);
  const double rate = p.real("sample_rate");
  if (!(rate > 0.0))
    throw InvalidParameter("sample_rate", "sample_rate is required: must be > N*Omega/pi samples/s (Nyquist) and finite");
  const auto bank = control::OscillatorBank::with_couplings(si.rotation_frequency, c.harmonics, si.alpha, si.beta,
                                                            si.gain, c.rejected);
  control::RealtimeFilter f(bank, rate);
  if (p.real("input_limit") != 0.0) f.set_input_limit(p.real("input_limit"));  // 0: the filter's default
  return f;
}

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

}  // namespace

void bind_realtime_filter(py::module_& m) {
  py::class_<control::RealtimeFilter>(m, "RealtimeFilter", R"doc(
The real-time first-harmonic rejection filter: one output sample per measured sample, O(N) per sample, exact
zero-order-hold discretisation of the oscillator bank (seed 2, eqs. 15 and 20). Keyword arguments as the TOML keys
of `afmkit control export`: rotation_frequency [rad/s], harmonics N, alpha, beta, gain [units of Omega], rejected,
sample_rate [samples/s] (required, > N*Omega/pi), input_limit. The output u is the control signal; in the loop
the plant's input is u/K (K = gain*Omega), and the measured signal m loses its first harmonic while keeping the
others (docs/embedding.md).
)doc")
      .def(py::init([](const py::kwargs& kwargs) { return make_filter(kwargs); }))
      .def("step", &control::RealtimeFilter::step, py::arg("measured"), "Output u_n for one measured sample m_n.")
      .def(
          "step_block",
          [](control::RealtimeFilter& f, const Array& measured, std::optional<py::array> out_arg) {
            if (measured.ndim() != 1) throw py::value_error("step_block: measured must be a 1-D array");
            // `out` is used as given (never converted: a converted copy would silently take the results)
            py::array out = out_arg ? *out_arg : py::array_t<double>(measured.size());
            if (!out.dtype().is(py::dtype::of<double>()) || out.ndim() != 1 || out.size() != measured.size() ||
                !(out.flags() & py::array::c_style) || !out.writeable())
              throw py::value_error("step_block: out must be a writable contiguous float64 array of the same size "
                                    "as measured");
            {
              py::gil_scoped_release release;
              f.step_block(std::span<const double>(measured.data(), static_cast<std::size_t>(measured.size())),
                           std::span<double>(static_cast<double*>(out.mutable_data()), static_cast<std::size_t>(out.size())));
            }
            return out;
          },
          py::arg("measured"), py::arg("out") = py::none(),
          "step() for every sample of a 1-D array (vectorised, same bits as step()); returns the outputs (in `out` "
          "when given: no allocation per block).")
      .def("reset", &control::RealtimeFilter::reset, "Zero state and counters.")
      .def(
          "save_state", [](const control::RealtimeFilter& f) { return py::array_t<double>(py::cast(f.save_state())); },
          "The whole state as a float64 array (restore_state takes it back).")
      .def(
          "restore_state",
          [](control::RealtimeFilter& f, const Array& state) {
            f.restore_state(std::span<const double>(state.data(), static_cast<std::size_t>(state.size())));
          },
          py::arg("state"))
      .def_property_readonly("skipped_samples", &control::RealtimeFilter::skipped_samples,
                             "Samples skipped (NaN, inf or beyond input_limit).")
      .def_property_readonly("uses_wide_vectors", &control::RealtimeFilter::uses_wide_vectors);
}

}  // namespace afmkit::python
