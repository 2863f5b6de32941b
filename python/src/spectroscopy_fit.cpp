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

/// The options of the fit that do not depend on the mode (the noise of each mode's channels set by the caller).
spectroscopy::FitOptions options_of(const std::string& law, const std::vector<std::string>& parameters,
                                    const std::map<std::string, double>& initial,
                                    const std::map<std::string, double>& fixed, const std::string& force_curve,
                                    bool allow_energy_gain, const std::string& direction, double huber,
                                    double fd_step, int max_evaluations, double tolerance,
                                    double integrator_tolerance, double shooting_tolerance,
                                    double correlation_limit, double condition_limit, double flat_column,
                                    bool parallel) {
  spectroscopy::FitOptions o;
  o.law = law;
  o.parameters = parameters;
  o.initial = initial;
  o.law_values = fixed;
  o.force_curve = force_curve;
  o.allow_energy_gain = allow_energy_gain;
  o.direction = direction_of(direction);
  o.huber = huber;
  o.fd_step = fd_step;
  o.max_evaluations = max_evaluations;
  o.tolerance = tolerance;
  o.integrator_tolerance = integrator_tolerance;
  o.shooting_tolerance = shooting_tolerance;
  o.correlation_limit = correlation_limit;
  o.condition_limit = condition_limit;
  o.flat_column = flat_column;
  o.parallel = parallel;
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

py::object optional_array(const std::vector<double>& v) {
  return v.empty() ? py::object(py::none()) : py::object(array_of(v));
}

py::dict fit(const Array& distance, const Array& amplitude, const std::optional<Array>& phase, const std::string& law,
             const std::vector<std::string>& parameters, const std::map<std::string, double>& initial,
             const std::map<std::string, double>& fixed, const std::string& force_curve, bool allow_energy_gain,
             double spring_constant, double resonance_frequency, double quality_factor, double free_amplitude,
             double drive_frequency, const std::string& direction, double amplitude_noise, double phase_noise,
             double huber, double fd_step, int max_evaluations, double tolerance, double integrator_tolerance,
             double shooting_tolerance, double correlation_limit, double condition_limit, double flat_column,
             bool parallel) {
  spectroscopy::FitCurve curve;
  curve.distance = vector_of(distance, "distance");
  curve.amplitude = vector_of(amplitude, "amplitude");
  if (phase) curve.phase = vector_of(*phase, "phase");
  spectroscopy::FitSettings s{spring_constant, resonance_frequency, quality_factor, free_amplitude, drive_frequency};
  spectroscopy::FitOptions o =
      options_of(law, parameters, initial, fixed, force_curve, allow_energy_gain, direction, huber, fd_step,
                 max_evaluations, tolerance, integrator_tolerance, shooting_tolerance, correlation_limit,
                 condition_limit, flat_column, parallel);
  o.amplitude_noise = amplitude_noise;
  o.phase_noise = phase_noise;
  SignalPoll poll;
  o.cancellation = poll.cancellation();
  spectroscopy::FitResult r;
  poll.run([&] { r = spectroscopy::fit_am_curve(curve, s, o); });

  py::dict out = common(r);
  out["amplitude"] = array_of(r.amplitude);
  out["phase"] = optional_array(r.phase);
  out["fitted_amplitude"] = array_of(r.fitted_amplitude);
  out["fitted_phase"] = array_of(r.fitted_phase);
  out["amplitude_noise"] = r.amplitude_noise;
  out["phase_noise"] = r.phase_noise;
  out["noise_estimated_amplitude"] = r.noise_estimated_amplitude;
  out["noise_estimated_phase"] = r.noise_estimated_phase;
  out["rms_amplitude"] = r.rms_amplitude;
  out["rms_phase"] = r.rms_phase;
  return out;
}

py::dict fit_fm(const Array& distance, const Array& frequency_shift, const std::optional<Array>& dissipation,
                const std::string& law, const std::vector<std::string>& parameters,
                const std::map<std::string, double>& initial, const std::map<std::string, double>& fixed,
                const std::string& force_curve, bool allow_energy_gain, double spring_constant,
                double resonance_frequency, double quality_factor, double amplitude, const std::string& direction,
                double frequency_shift_noise, double dissipation_noise, double huber, double fd_step,
                int max_evaluations, double tolerance, double integrator_tolerance, double shooting_tolerance,
                double correlation_limit, double condition_limit, double flat_column, bool parallel) {
  spectroscopy::FmFitCurve curve;
  curve.distance = vector_of(distance, "distance");
  curve.frequency_shift = vector_of(frequency_shift, "frequency_shift");
  if (dissipation) curve.dissipation = vector_of(*dissipation, "dissipation");
  spectroscopy::FmFitSettings s{spring_constant, resonance_frequency, quality_factor, amplitude};
  spectroscopy::FitOptions o =
      options_of(law, parameters, initial, fixed, force_curve, allow_energy_gain, direction, huber, fd_step,
                 max_evaluations, tolerance, integrator_tolerance, shooting_tolerance, correlation_limit,
                 condition_limit, flat_column, parallel);
  o.frequency_shift_noise = frequency_shift_noise;
  o.dissipation_noise = dissipation_noise;
  SignalPoll poll;
  o.cancellation = poll.cancellation();
  spectroscopy::FitResult r;
  poll.run([&] { r = spectroscopy::fit_fm_curve(curve, s, o); });

  py::dict out = common(r);
  out["frequency_shift"] = array_of(r.frequency_shift);
  out["fitted_frequency_shift"] = array_of(r.fitted_frequency_shift);
  out["dissipation"] = optional_array(r.dissipation);
  out["fitted_dissipation"] = optional_array(r.fitted_dissipation);
  out["frequency_shift_noise"] = r.frequency_shift_noise;
  out["dissipation_noise"] = r.dissipation_noise;
  out["noise_estimated_frequency_shift"] = r.noise_estimated_frequency_shift;
  out["noise_estimated_dissipation"] = r.noise_estimated_dissipation;
  out["rms_frequency_shift"] = r.rms_frequency_shift;
  out["rms_dissipation"] = r.rms_dissipation;
  return out;
}

py::dict predict_fm(const Array& distance, const std::string& law, const std::map<std::string, double>& values,
                    const std::map<std::string, double>& calibration, const std::string& force_curve,
                    bool allow_energy_gain, double spring_constant, double resonance_frequency,
                    double quality_factor, double amplitude, const std::string& direction) {
  spectroscopy::FmFitSettings s{spring_constant, resonance_frequency, quality_factor, amplitude};
  spectroscopy::FitOptions o;
  o.law = law;
  o.law_values = values;
  o.initial = calibration;
  o.force_curve = force_curve;
  o.allow_energy_gain = allow_energy_gain;
  o.direction = direction_of(direction);
  const std::vector<double> d = vector_of(distance, "distance");
  SignalPoll poll;
  o.cancellation = poll.cancellation();
  spectroscopy::FmPrediction p;
  poll.run([&] { p = spectroscopy::predict_fm_curve(d, s, o); });
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
  spectroscopy::FitSettings s{spring_constant, resonance_frequency, quality_factor, free_amplitude, drive_frequency};
  spectroscopy::FitOptions o;
  o.law = law;
  o.law_values = values;
  o.initial = calibration;
  o.force_curve = force_curve;
  o.allow_energy_gain = allow_energy_gain;
  o.direction = direction_of(direction);
  const std::vector<double> d = vector_of(distance, "distance");
  SignalPoll poll;
  o.cancellation = poll.cancellation();
  spectroscopy::AmPrediction p;
  poll.run([&] { p = spectroscopy::predict_am_curve(d, s, o); });
  py::dict out;
  out["amplitude"] = array_of(p.amplitude);
  out["phase"] = array_of(p.phase);
  out["contact"] = bools_of(p.contact);
  out["jumped"] = bools_of(p.jumped);
  return out;
}

}  // namespace

void bind_spectroscopy_fit(py::module_& m) {
  m.def("spectroscopy_fit", &fit, py::arg("distance"), py::arg("amplitude"), py::arg("phase"), py::arg("law"),
        py::arg("parameters"), py::arg("initial"), py::arg("fixed"), py::arg("force_curve"),
        py::arg("allow_energy_gain"), py::arg("spring_constant"), py::arg("resonance_frequency"),
        py::arg("quality_factor"), py::arg("free_amplitude"), py::arg("drive_frequency"), py::arg("direction"),
        py::arg("amplitude_noise"), py::arg("phase_noise"), py::arg("huber"), py::arg("fd_step"), py::arg("max_evaluations"),
        py::arg("tolerance"), py::arg("integrator_tolerance"), py::arg("shooting_tolerance"),
        py::arg("correlation_limit"), py::arg("condition_limit"), py::arg("flat_column"), py::arg("parallel"),
        "The law fit of `afmkit spectroscopy fit` (SI units): use afmkit.spectroscopy_fit.fit.");
  m.def("spectroscopy_predict", &predict, py::arg("distance"), py::arg("law"), py::arg("values"),
        py::arg("calibration"), py::arg("force_curve"), py::arg("allow_energy_gain"), py::arg("spring_constant"),
        py::arg("resonance_frequency"), py::arg("quality_factor"), py::arg("free_amplitude"),
        py::arg("drive_frequency"), py::arg("direction"),
        "The forward model of the fit (SI units): use afmkit.spectroscopy_fit.predict.");
  m.def("spectroscopy_fit_fm", &fit_fm, py::arg("distance"), py::arg("frequency_shift"), py::arg("dissipation"),
        py::arg("law"), py::arg("parameters"), py::arg("initial"), py::arg("fixed"), py::arg("force_curve"),
        py::arg("allow_energy_gain"), py::arg("spring_constant"), py::arg("resonance_frequency"),
        py::arg("quality_factor"), py::arg("amplitude"), py::arg("direction"), py::arg("frequency_shift_noise"),
        py::arg("dissipation_noise"), py::arg("huber"), py::arg("fd_step"), py::arg("max_evaluations"),
        py::arg("tolerance"), py::arg("integrator_tolerance"), py::arg("shooting_tolerance"),
        py::arg("correlation_limit"), py::arg("condition_limit"), py::arg("flat_column"), py::arg("parallel"),
        "The FM law fit of `afmkit spectroscopy fit` (SI units): use afmkit.spectroscopy_fit.fit_fm.");
  m.def("spectroscopy_predict_fm", &predict_fm, py::arg("distance"), py::arg("law"), py::arg("values"),
        py::arg("calibration"), py::arg("force_curve"), py::arg("allow_energy_gain"), py::arg("spring_constant"),
        py::arg("resonance_frequency"), py::arg("quality_factor"), py::arg("amplitude"), py::arg("direction"),
        "The FM forward model of the fit (SI units): use afmkit.spectroscopy_fit.predict_fm.");
}

}  // namespace afmkit::python
