// Force reconstruction on NumPy arrays (python/afmkit/spectroscopy_reconstruct.py is the public face;
// docs/reconstruction.md): the library's reconstruct_fm / reconstruct_am, SI units in and out.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <limits>

#include "afmkit/core/error.hpp"
#include "afmkit/spectroscopy/reconstruct_am.hpp"
#include "afmkit/spectroscopy/reconstruct_fm.hpp"
#include "afmkit/spectroscopy/reconstruct_law.hpp"
#include "bindings.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<double> vec(const Array& a, const char* name) {
  if (a.ndim() != 1) throw InvalidParameter(name, std::string(name) + " must be a one-dimensional array");
  return {a.data(), a.data() + a.size()};
}

py::array_t<double> arr(const std::vector<double>& v) { return py::array_t<double>(v.size(), v.data()); }

py::dict law_dict(const impact::ForceCurve& c) {
  std::vector<double> d, fa, fr;
  for (std::size_t i = 0; i < c.approach_gap.size(); ++i) {
    d.push_back(c.approach_gap[i] * 1e-9);
    fa.push_back(c.approach_force[i] * 1e-9);
    fr.push_back(c.retract_force[i] * 1e-9);
  }
  py::dict law;
  law["distance"] = arr(d);
  law["approach_force"] = arr(fa);
  law["retract_force"] = arr(fr);
  return law;
}
}  // namespace

void bind_spectroscopy_reconstruct(py::module_& m) {
  m.def(
      "_reconstruct_fm",
      [](const Array& distance, const Array& frequency_shift, double k, double f0, double amplitude,
         const std::string& method, const std::string& tail, int noise_realisations, std::uint64_t seed,
         bool round_trip, const std::string& round_trip_model, int round_trip_points, double quality_factor) {
        const spectroscopy::FmSettings s(k, f0, amplitude);
        spectroscopy::FmOptions o;
        o.method = spectroscopy::fm_method_from(method);
        o.tail = spectroscopy::tail_model_from(tail);
        o.noise_realisations = noise_realisations;
        o.seed = seed;
        o.round_trip = round_trip;
        if (round_trip_model != "exact" && round_trip_model != "first_order")
          throw InvalidParameter("round_trip_model", "round_trip_model = '" + round_trip_model +
                                                         "' must be one of: exact, first_order");
        o.exact_round_trip = round_trip_model == "exact";
        o.round_trip_points = round_trip_points;
        o.quality_factor = quality_factor;
        spectroscopy::FmReconstruction r;
        {
          const spectroscopy::FmCurve c{vec(distance, "distance"), vec(frequency_shift, "frequency_shift")};
          py::gil_scoped_release release;
          r = spectroscopy::reconstruct_fm(c, s, o);
        }
        py::dict d;
        d["method"] = r.method;
        d["distance"] = arr(r.distance);
        d["frequency_shift"] = arr(r.frequency_shift);
        d["force"] = arr(r.force);
        d["energy"] = arr(r.energy);
        d["force_uncertainty"] = arr(r.force_uncertainty);
        d["round_trip_frequency_shift"] = arr(r.round_trip_frequency_shift);
        d["residual"] = arr(r.residual);
        d["residual_rms"] = r.residual_rms;
        d["residual_max"] = r.residual_max;
        d["noise"] = r.noise;
        d["interaction_length"] = r.interaction_length;
        d["tail"] = r.tail.active ? "exponential" : "zero";
        d["tail_decay_length"] = r.tail.active ? r.tail.decay_length : std::numeric_limits<double>::quiet_NaN();
        d["tail_sensitivity"] = r.tail_sensitivity;
        d["round_trip_model"] = r.round_trip_model;
        d["notes"] = r.notes;
        d["law"] = law_dict(r.law);
        d["law_text"] = spectroscopy::table_law_text(r.law, "force reconstructed by afmkit (FM, " + r.method + ")");
        return d;
      },
      py::arg("distance"), py::arg("frequency_shift"), py::arg("spring_constant"), py::arg("resonance_frequency"),
      py::arg("amplitude"), py::arg("method"), py::arg("tail"), py::arg("noise_realisations"), py::arg("seed"),
      py::arg("round_trip"), py::arg("round_trip_model"), py::arg("round_trip_points"), py::arg("quality_factor"));
  m.def(
      "_reconstruct_am",
      [](const Array& separation, const Array& amplitude, const Array& phase, double k, double f0, double q,
         double a0, double drive_frequency, const std::string& method, const std::string& tail,
         int round_trip_points, bool round_trip) {
        const spectroscopy::AmSettings s(k, f0, q, a0, drive_frequency);
        spectroscopy::AmOptions o;
        o.method = spectroscopy::am_method_from(method);
        o.tail = spectroscopy::tail_model_from(tail);
        o.round_trip_points = round_trip_points;
        o.round_trip = round_trip;
        spectroscopy::AmReconstruction r;
        {
          const spectroscopy::AmCurve c{vec(separation, "separation"), vec(amplitude, "amplitude"), vec(phase, "phase")};
          py::gil_scoped_release release;
          r = spectroscopy::reconstruct_am(c, s, o);
        }
        py::dict d;
        d["method"] = r.method;
        d["separation"] = arr(r.separation);
        d["amplitude"] = arr(r.amplitude);
        d["phase"] = arr(r.phase);
        d["dissipation"] = arr(r.dissipation);
        d["gap"] = arr(r.gap);
        d["equivalent_frequency_shift"] = arr(r.omega);
        d["force"] = arr(r.force);
        d["force_uncertainty"] = arr(r.force_uncertainty);
        d["gap_dissipation"] = arr(r.gap_dissipation);
        d["approach_force"] = arr(r.approach_force);
        d["retract_force"] = arr(r.retract_force);
        d["dropped"] = r.dropped;
        d["contact_gap"] = r.contact_gap;
        d["round_trip_amplitude_ratio"] = arr(r.round_trip_amplitude_ratio);
        d["round_trip_phase"] = arr(r.round_trip_phase);
        d["residual_amplitude_ratio"] = arr(r.residual_amplitude_ratio);
        d["residual_phase"] = arr(r.residual_phase);
        d["rms_amplitude_ratio"] = r.rms_amplitude_ratio;
        d["rms_phase"] = r.rms_phase;
        d["round_trip_model"] = r.round_trip_model;
        d["notes"] = r.notes;
        d["law"] = law_dict(r.law);
        d["law_text"] = spectroscopy::table_law_text(r.law, "force reconstructed by afmkit (AM, " + r.method + ")");
        return d;
      },
      py::arg("separation"), py::arg("amplitude"), py::arg("phase"), py::arg("spring_constant"),
      py::arg("resonance_frequency"), py::arg("quality_factor"), py::arg("free_amplitude"),
      py::arg("drive_frequency"), py::arg("method"), py::arg("tail"), py::arg("round_trip_points"),
      py::arg("round_trip"));
}

}  // namespace afmkit::python
