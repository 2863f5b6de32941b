// afmkit.spectroscopy_fit.fit / fit_fm: the law fit of `afmkit spectroscopy fit` (AM and FM curves) on NumPy arrays
// in SI units (include/afmkit/spectroscopy/fit.hpp; the Python face is python/afmkit/spectroscopy_fit.py).
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "afmkit/core/error.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "bindings.hpp"
#include "described_fields.hpp"
#include "interrupts.hpp"
#include "numpy_arrays.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

py::array_t<bool> bools_of(const std::vector<bool>& v) {
  py::array_t<bool> a(static_cast<py::ssize_t>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) a.mutable_data()[i] = v[i];
  return a;
}

spectroscopy::CurveDirection direction_of(const std::string& direction) {
  if (direction != "approach" && direction != "retract")
    throw InvalidParameter("direction", "direction = '" + direction + "' is not allowed: must be approach or retract");
  return direction == "retract" ? spectroscopy::CurveDirection::retract : spectroscopy::CurveDirection::approach;
}

/// The options of the fit that do not depend on the mode, from the dict of afmkit.spectroscopy_fit._options (the
/// noise of each mode's channels set by the caller).
spectroscopy::FitOptions options_of(const py::dict& d) {
  auto get = [&](const char* key) { return d[key]; };
  spectroscopy::FitOptions o;
  o.law = get("law").cast<std::string>();
  o.parameters = get("parameters").cast<std::vector<std::string>>();
  o.initial = get("initial").cast<std::map<std::string, double>>();
  o.law_values = get("fixed").cast<std::map<std::string, double>>();
  o.force_curve = get("force_curve").cast<std::string>();
  o.allow_energy_gain = get("allow_energy_gain").cast<bool>();
  o.direction = direction_of(get("direction").cast<std::string>());
  read_fields(d, o);  // huber … flat_column: FitOptions::describe
  o.parallel = get("parallel").cast<bool>();
  return o;
}

/// run(o) (a fit or a prediction), interruptible by Ctrl-C (SignalPoll).
template <class Run>
auto interruptible(spectroscopy::FitOptions o, Run&& run) {
  SignalPoll poll;
  o.cancellation = poll.cancellation();
  decltype(run(o)) r;
  poll.run([&] { r = run(o); });
  return r;
}

/// The options of a prediction: the law and its values, the calibration, the direction (nothing is fitted).
spectroscopy::FitOptions prediction_options(const std::string& law, const std::map<std::string, double>& values,
                                            const std::map<std::string, double>& calibration,
                                            const std::string& force_curve, bool allow_energy_gain,
                                            const std::string& direction) {
  spectroscopy::FitOptions o;
  o.law = law;
  o.law_values = values;
  o.initial = calibration;
  o.force_curve = force_curve;
  o.allow_energy_gain = allow_energy_gain;
  o.direction = direction_of(direction);
  return o;
}

/// What every fit reports: status, estimates and their statistics, the evaluation counts.
py::dict common(const spectroscopy::FitResult& r) {
  py::dict out;
  out["mode"] = spectroscopy::fit_mode_name(r.mode);
  out["status"] = spectroscopy::fit_status_name(r.status);
  out["solver_status"] = r.solver_status;
  std::vector<std::string> names, units, transforms;
  std::vector<double> initial_values;
  for (const auto& p : r.parameters) {
    names.push_back(p.name);
    units.push_back(p.unit);
    transforms.push_back(spectroscopy::transform_name(p.transform));
    initial_values.push_back(p.initial);
  }
  out["names"] = names;
  out["units"] = units;
  out["transforms"] = transforms;
  out["initial"] = array_of(initial_values);
  out["estimates"] = array_of(r.estimates);
  out["standard_errors"] = array_of(r.standard_errors);
  const std::size_t n = r.parameters.size();
  py::array_t<double> corr({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(n)});
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) corr.mutable_at(a, b) = r.correlation[a][b];
  out["correlation"] = corr;
  out["identifiable"] = bools_of(r.identifiable);
  out["warnings"] = r.warnings;
  out["condition_number"] = r.condition_number;
  out["distance"] = array_of(r.distance);
  out["contact"] = bools_of(r.contact);
  out["jumped"] = bools_of(r.jumped);
  out["cost"] = r.cost;
  out["reduced_chi2"] = r.reduced_chi2;
  out["iterations"] = r.iterations;
  out["curve_evaluations"] = r.curve_evaluations;
  out["orbit_evaluations"] = r.orbit_evaluations;
  out["failed_evaluations"] = r.failed_evaluations;
  out["seconds"] = r.seconds;
  out["law_values"] = r.law_values;
  return out;
}

/// One measured channel of a fit (amplitude, phase, frequency_shift, dissipation): the measured and fitted arrays
/// (None when empty: not measured, not modelled), the σ used, whether it was estimated, the RMS residual.
void channel(py::dict& out, const std::string& name, const std::vector<double>& measured,
             const std::vector<double>& fitted, double noise, bool estimated, double rms) {
  out[py::str(name)] = measured.empty() ? py::object(py::none()) : py::object(array_of(measured));
  out[py::str("fitted_" + name)] = fitted.empty() ? py::object(py::none()) : py::object(array_of(fitted));
  out[py::str(name + "_noise")] = noise;
  out[py::str("noise_estimated_" + name)] = estimated;
  out[py::str("rms_" + name)] = rms;
}

py::dict fit(const Array& distance, const Array& amplitude, const std::optional<Array>& phase,
             double spring_constant, double resonance_frequency, double quality_factor, double free_amplitude,
             double drive_frequency, double amplitude_noise, double phase_noise, const py::dict& options) {
  spectroscopy::FitCurve curve;
  curve.distance = vector_of(distance, "distance");
  curve.amplitude = vector_of(amplitude, "amplitude");
  if (phase) curve.phase = vector_of(*phase, "phase");
  const spectroscopy::FitSettings s{spring_constant, resonance_frequency, quality_factor, free_amplitude,
                                    drive_frequency};
  spectroscopy::FitOptions o = options_of(options);
  o.amplitude_noise = amplitude_noise;
  o.phase_noise = phase_noise;
  const spectroscopy::FitResult r =
      interruptible(o, [&](const spectroscopy::FitOptions& x) { return spectroscopy::fit_am_curve(curve, s, x); });

  py::dict out = common(r);
  channel(out, "amplitude", r.amplitude, r.fitted_amplitude, r.amplitude_noise, r.noise_estimated_amplitude,
          r.rms_amplitude);
  channel(out, "phase", r.phase, r.fitted_phase, r.phase_noise, r.noise_estimated_phase, r.rms_phase);
  return out;
}

py::dict fit_fm(const Array& distance, const Array& frequency_shift, const std::optional<Array>& dissipation,
                double spring_constant, double resonance_frequency, double quality_factor, double amplitude,
                double frequency_shift_noise, double dissipation_noise, const py::dict& options) {
  spectroscopy::FmFitCurve curve;
  curve.distance = vector_of(distance, "distance");
  curve.frequency_shift = vector_of(frequency_shift, "frequency_shift");
  if (dissipation) curve.dissipation = vector_of(*dissipation, "dissipation");
  const spectroscopy::FmFitSettings s{spring_constant, resonance_frequency, quality_factor, amplitude};
  spectroscopy::FitOptions o = options_of(options);
  o.frequency_shift_noise = frequency_shift_noise;
  o.dissipation_noise = dissipation_noise;
  const spectroscopy::FitResult r =
      interruptible(o, [&](const spectroscopy::FitOptions& x) { return spectroscopy::fit_fm_curve(curve, s, x); });

  py::dict out = common(r);
  channel(out, "frequency_shift", r.frequency_shift, r.fitted_frequency_shift, r.frequency_shift_noise,
          r.noise_estimated_frequency_shift, r.rms_frequency_shift);
  channel(out, "dissipation", r.dissipation, r.fitted_dissipation, r.dissipation_noise,
          r.noise_estimated_dissipation, r.rms_dissipation);
  return out;
}

py::dict predict_fm(const Array& distance, const std::string& law, const std::map<std::string, double>& values,
                    const std::map<std::string, double>& calibration, const std::string& force_curve,
                    bool allow_energy_gain, double spring_constant, double resonance_frequency,
                    double quality_factor, double amplitude, const std::string& direction) {
  const spectroscopy::FmFitSettings s{spring_constant, resonance_frequency, quality_factor, amplitude};
  const std::vector<double> d = vector_of(distance, "distance");
  const spectroscopy::FmPrediction p =
      interruptible(prediction_options(law, values, calibration, force_curve, allow_energy_gain, direction),
                    [&](const spectroscopy::FitOptions& o) { return spectroscopy::predict_fm_curve(d, s, o); });
  py::dict out;
  out["frequency_shift"] = array_of(p.frequency_shift);
  out["dissipation"] = array_of(p.dissipation);
  out["contact"] = bools_of(p.contact);
  out["jumped"] = bools_of(p.jumped);
  return out;
}

py::dict predict(const Array& distance, const std::string& law, const std::map<std::string, double>& values,
                 const std::map<std::string, double>& calibration, const std::string& force_curve,
                 bool allow_energy_gain, double spring_constant, double resonance_frequency, double quality_factor,
                 double free_amplitude, double drive_frequency, const std::string& direction) {
  const spectroscopy::FitSettings s{spring_constant, resonance_frequency, quality_factor, free_amplitude,
                                    drive_frequency};
  const std::vector<double> d = vector_of(distance, "distance");
  const spectroscopy::AmPrediction p =
      interruptible(prediction_options(law, values, calibration, force_curve, allow_energy_gain, direction),
                    [&](const spectroscopy::FitOptions& o) { return spectroscopy::predict_am_curve(d, s, o); });
  py::dict out;
  out["amplitude"] = array_of(p.amplitude);
  out["phase"] = array_of(p.phase);
  out["contact"] = bools_of(p.contact);
  out["jumped"] = bools_of(p.jumped);
  return out;
}

}  // namespace

void bind_spectroscopy_fit(py::module_& m) {
  m.def("spectroscopy_fit", &fit, py::arg("distance"), py::arg("amplitude"), py::arg("phase"),
        py::arg("spring_constant"), py::arg("resonance_frequency"), py::arg("quality_factor"),
        py::arg("free_amplitude"), py::arg("drive_frequency"), py::arg("amplitude_noise"), py::arg("phase_noise"),
        py::arg("options"), "The law fit of `afmkit spectroscopy fit` (SI units): use afmkit.spectroscopy_fit.fit.");
  m.def("spectroscopy_fit_solver_defaults", [] { return field_defaults(spectroscopy::FitOptions{}); },
        "The fit's solver settings (huber … flat_column) and their defaults, as spectroscopy::FitOptions declares "
        "them.");
  m.def("spectroscopy_predict", &predict, py::arg("distance"), py::arg("law"), py::arg("values"),
        py::arg("calibration"), py::arg("force_curve"), py::arg("allow_energy_gain"), py::arg("spring_constant"),
        py::arg("resonance_frequency"), py::arg("quality_factor"), py::arg("free_amplitude"),
        py::arg("drive_frequency"), py::arg("direction"),
        "The forward model of the fit (SI units): use afmkit.spectroscopy_fit.predict.");
  m.def("spectroscopy_fit_fm", &fit_fm, py::arg("distance"), py::arg("frequency_shift"), py::arg("dissipation"),
        py::arg("spring_constant"), py::arg("resonance_frequency"), py::arg("quality_factor"), py::arg("amplitude"),
        py::arg("frequency_shift_noise"), py::arg("dissipation_noise"), py::arg("options"),
        "The FM law fit of `afmkit spectroscopy fit` (SI units): use afmkit.spectroscopy_fit.fit_fm.");
  m.def("spectroscopy_predict_fm", &predict_fm, py::arg("distance"), py::arg("law"), py::arg("values"),
        py::arg("calibration"), py::arg("force_curve"), py::arg("allow_energy_gain"), py::arg("spring_constant"),
        py::arg("resonance_frequency"), py::arg("quality_factor"), py::arg("amplitude"), py::arg("direction"),
        "The FM forward model of the fit (SI units): use afmkit.spectroscopy_fit.predict_fm.");
}

}  // namespace afmkit::python
