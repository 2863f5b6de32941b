// afmkit.control state-space realisations (docs/python.md#control-objects): the seed-2 controller from the
// measurement m to w = -u (A = A0 - b c_e^T, B = b, C = K c_r^T, D = 0; docs/theory-control.md#oscillator-bank) and the
// delay-free plant from u to y, as NumPy matrices in rad/s (python-control's ss(A, B, C, D) takes them), with the
// delay in s. The keywords are the control commands' (units of Omega and T, or their SI forms), read by the same code.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/settings.hpp"
#include "afmkit/control/state_space.hpp"
#include "afmkit/core/error.hpp"
#include "bindings.hpp"
#include "control_params.hpp"
#include "params_from_python.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

py::dict matrices(const control::StateSpace& s) {
  py::dict d;
  d["A"] = s.A;
  d["B"] = s.B;
  d["C"] = s.C;
  d["D"] = s.D;
  return d;
}

// The keys of `control tf` that are not the controller's and plant's (refused here like unknown ones).
std::vector<std::string> not_controller_keys() {
  io::ParamSet shared;
  cli::add_control_params(shared, cli::kMaxHarmonicsSpectra);
  std::set<std::string> keep;
  for (const auto& d : shared.describe()) keep.insert(d.key);
  std::vector<std::string> hidden;
  for (const auto& d : python_params(command_spec("control tf")).describe())
    if (!keep.count(d.key)) hidden.push_back(d.key);
  return hidden;
}

py::dict state_space(const py::dict& kwargs) {
  const io::ParamSet p = cli::resolve_si_inputs(
      params_from_python("control tf", "afmkit.control.state_space", kwargs, not_controller_keys()));
  const control::ControlSettings c = cli::control_settings_from(p);
  if (c.controller == control::ControllerKind::Infinite || c.controller == control::ControllerKind::Smith)
    throw InvalidParameter("controller", fmt::format("controller = {} has no finite state-space realisation: must be "
                                                     "single or bank (use the frequency response instead)",
                                                     control::to_string(c.controller)));
  if (c.harmonics > cli::kMaxHarmonicsSpectra)
    throw InvalidParameter("harmonics", fmt::format("harmonics = {} is out of range: must be an integer in [1, {}] "
                                                    "for a state-space realisation (dense (2N + 1) x (2N + 1) matrix)",
                                                    c.harmonics, cli::kMaxHarmonicsSpectra));
  const control::ControlSettingsSi si = control::to_si(c);
  const auto bank = std::get<control::OscillatorBank>(control::bank_from(c));
  py::dict out;
  out["controller"] = matrices(control::ss(bank));
  out["plant"] = matrices(control::ss(c.plant, si.plant_rate));
  out["delay"] = si.delay;
  out["rotation_frequency"] = si.rotation_frequency;
  return out;
}

// The resolved settings (Omega and T; rad/s and s) of the keywords, as JSON text: validation of a design.
std::string settings(const py::dict& kwargs) {
  const io::ParamSet p = cli::resolve_si_inputs(
      params_from_python("control tf", "afmkit.control.Controller", kwargs, not_controller_keys()));
  const control::ControlSettings c = cli::control_settings_from(p);
  return nlohmann::json{{"settings", cli::settings_json(c)}, {"settings_si", cli::settings_si_json(c)}}.dump();
}

}  // namespace

void bind_control_state_space(py::module_& m) {
  m.def("control_state_space", &state_space, py::arg("kwargs"),
        "The controller (m -> w = -u) and the delay-free plant (u -> y) as dicts of A, B, C, D (rad/s), the delay "
        "[s] and Omega [rad/s], from the control commands' keywords");
  m.def("control_settings", &settings, py::arg("kwargs"),
        "The resolved settings of the control commands' keywords as JSON text (settings: Omega, T; settings_si)");
}

}  // namespace afmkit::python
