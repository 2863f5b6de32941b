// afmkit.control.RealtimeFilter: the streaming first-harmonic rejection filter (include/afmkit/control/
// realtime_filter.hpp) on NumPy buffers. Keyword arguments are those of `afmkit control export` (the same filter
// the C core runs): rotation_frequency [rad/s], harmonics, alpha and beta [Ω], gain [Ω], rejected, sample_rate
// [samples/s], input_limit.
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

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

/// The filter as Python holds it: the filter and a lock. Every method takes the lock, so a filter shared by threads
/// is never corrupted (its outputs then follow the order in which the calls took the lock); step_block waits for
/// it without the GIL.
struct Filter {
  explicit Filter(control::RealtimeFilter f) : filter(std::move(f)) {}
  control::RealtimeFilter filter;
  std::mutex mutex;
};

/// `self` of a method. pybind11 hands a method of an object that Python created without running __init__
/// (RealtimeFilter.__new__(RealtimeFilter), a subclass whose __init__ does not call the base one) uninitialised
/// memory; such an object is refused here by the holder's flag before anything is read.
Filter& checked(const py::object& self) {
  const py::type type = py::type::of<Filter>();
  if (!py::isinstance(self, type))
    throw py::type_error("afmkit.control.RealtimeFilter method called on a " +
                         std::string(py::str(py::type::of(self).attr("__name__"))));
  auto* inst = reinterpret_cast<py::detail::instance*>(self.ptr());
  py::detail::value_and_holder vh = inst->get_value_and_holder(py::detail::get_type_info(typeid(Filter)));
  if (!vh || !vh.holder_constructed())
    throw py::type_error("afmkit.control.RealtimeFilter: this object was not initialised (created by __new__ without "
                         "__init__); create it as RealtimeFilter(rotation_frequency=..., sample_rate=..., ...)");
  return *vh.value_ptr<Filter>();  // constructed: the holder owns the value
}

/// Takes the filter's lock; when another thread holds it, waits with the GIL released (that thread may need it).
std::unique_lock<std::mutex> lock(Filter& f) {
  std::unique_lock<std::mutex> held(f.mutex, std::try_to_lock);
  if (!held.owns_lock()) {
    py::gil_scoped_release release;
    held.lock();
  }
  return held;
}

/// Whether the byte ranges of two arrays overlap.
bool overlap(const py::array& a, const py::array& b) {
  const auto* a0 = static_cast<const char*>(a.data());
  const auto* b0 = static_cast<const char*>(b.data());
  return a.nbytes() > 0 && b.nbytes() > 0 && a0 < b0 + b.nbytes() && b0 < a0 + a.nbytes();
}

}  // namespace

void bind_realtime_filter(py::module_& m) {
  py::class_<Filter>(m, "RealtimeFilter", R"doc(
The real-time first-harmonic rejection filter: one output sample per measured sample, O(N) per sample, exact
zero-order-hold discretisation of the oscillator bank (seed 2, eqs. 15 and 20). Keyword arguments as the TOML keys
of `afmkit control export`: rotation_frequency [rad/s], harmonics N, alpha, beta, gain [units of Omega], rejected,
sample_rate [samples/s] (required, > N*Omega/pi), input_limit. The output u is the control signal; in the loop
the plant's input is u/K (K = gain*Omega), and the measured signal m loses its first harmonic while keeping the
others (docs/embedding.md).

Threads: every method takes the filter's lock, so a filter shared by threads stays consistent, but one filter is
one signal: two streams need two filters. step_block(measured, out=...) with `out` overlapping `measured` (other
than the very same array) reads a copy of `measured` first, as NumPy does.
)doc")
      .def(py::init([](const py::kwargs& kwargs) { return std::make_unique<Filter>(make_filter(kwargs)); }))
      .def(
          "step",
          [](const py::object& self, double measured) {
            Filter& f = checked(self);
            const auto held = lock(f);
            return f.filter.step(measured);
          },
          py::arg("measured"), "Output u_n for one measured sample m_n.")
      .def(
          "step_block",
          [](const py::object& self, const Array& measured, std::optional<py::array> out_arg) {
            Filter& f = checked(self);
            if (measured.ndim() != 1) throw py::value_error("step_block: measured must be a 1-D array");
            // `out` is used as given (never converted: a converted copy would silently take the results)
            py::array out = out_arg ? *out_arg : py::array_t<double>(measured.size());
            if (!out.dtype().is(py::dtype::of<double>()) || out.ndim() != 1 || out.size() != measured.size() ||
                !(out.flags() & py::array::c_style) || !out.writeable())
              throw py::value_error("step_block: out must be a writable contiguous float64 array of the same size "
                                    "as measured");
            // The filter runs in place only on the very same memory; a partial overlap would overwrite samples
            // before they are read, so the input is copied first (the result of step() on the original samples).
            std::vector<double> copy;
            const double* in = measured.data();
            if (overlap(measured, out) && measured.data() != out.data()) {
              copy.assign(in, in + measured.size());
              in = copy.data();
            }
            {
              py::gil_scoped_release release;
              const std::lock_guard<std::mutex> held(f.mutex);
              f.filter.step_block(std::span<const double>(in, static_cast<std::size_t>(measured.size())),
                                  std::span<double>(static_cast<double*>(out.mutable_data()),
                                                    static_cast<std::size_t>(out.size())));
            }
            return out;
          },
          py::arg("measured"), py::arg("out") = py::none(),
          "step() for every sample of a 1-D array (vectorised, same bits as step()); returns the outputs (in `out` "
          "when given: no allocation per block; `out` may be `measured` itself, and an `out` that overlaps it "
          "otherwise gets the outputs of the original samples).")
      .def(
          "reset",
          [](const py::object& self) {
            Filter& f = checked(self);
            const auto held = lock(f);
            f.filter.reset();
          },
          "Zero state and counters.")
      .def(
          "save_state",
          [](const py::object& self) {
            Filter& f = checked(self);
            const auto held = lock(f);
            return py::array_t<double>(py::cast(f.filter.save_state()));
          },
          "The whole state as a float64 array (restore_state takes it back).")
      .def(
          "restore_state",
          [](const py::object& self, const Array& state) {
            Filter& f = checked(self);
            if (state.ndim() != 1) throw InvalidParameter("state", "state must be a 1-D array (from save_state)");
            const auto held = lock(f);
            f.filter.restore_state(std::span<const double>(state.data(), static_cast<std::size_t>(state.size())));
          },
          py::arg("state"),
          "Restores a state from save_state(); a buffer that no filter saved (sizes, counters, coordinates beyond "
          "1e270) raises InvalidParameter and leaves the filter unchanged.")
      .def_property_readonly(
          "skipped_samples",
          [](const py::object& self) {
            Filter& f = checked(self);
            const auto held = lock(f);
            return f.filter.skipped_samples();
          },
          "Samples skipped (NaN, inf or beyond input_limit).")
      .def_property_readonly("uses_wide_vectors", [](const py::object& self) { return checked(self).filter.uses_wide_vectors(); });
}

}  // namespace afmkit::python
