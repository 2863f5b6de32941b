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
#include "numpy_arrays.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

py::dict law_dict(const impact::ForceCurve& c) {
  std::vector<double> d, fa, fr;
  for (std::size_t i = 0; i < c.approach_gap.size(); ++i) {
    d.push_back(c.approach_gap[i] * 1e-9);
    fa.push_back(c.approach_force[i] * 1e-9);
    fr.push_back(c.retract_force[i] * 1e-9);
  }
  py::dict law;
  law["distance"] = array_of(d);
  law["approach_force"] = array_of(fa);
  law["retract_force"] = array_of(fr);
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
          const spectroscopy::FmCurve c{vector_of(distance, "distance"), vector_of(frequency_shift, "frequency_shift")};
          py::gil_scoped_release release;
          r = spectroscopy::reconstruct_fm(c, s, o);
        }
        py::dict d;
        d["method"] = r.method;
        d["distance"] = array_of(r.distance);
        d["frequency_shift"] = array_of(r.frequency_shift);
        d["force"] = array_of(r.force);
        d["energy"] = array_of(r.energy);
        d["force_uncertainty"] = array_of(r.force_uncertainty);
        d["round_trip_frequency_shift"] = array_of(r.round_trip_frequency_shift);
        d["residual"] = array_of(r.residual);
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
          const spectroscopy::AmCurve c{vector_of(separation, "separation"), vector_of(amplitude, "amplitude"), vector_of(phase, "phase")};
          py::gil_scoped_release release;
          r = spectroscopy::reconstruct_am(c, s, o);
        }
        py::dict d;
        d["method"] = r.method;
        d["separation"] = array_of(r.separation);
        d["amplitude"] = array_of(r.amplitude);
        d["phase"] = array_of(r.phase);
        d["dissipation"] = array_of(r.dissipation);
        d["gap"] = array_of(r.gap);
        d["equivalent_frequency_shift"] = array_of(r.omega);
        d["force"] = array_of(r.force);
        d["force_uncertainty"] = array_of(r.force_uncertainty);
        d["gap_dissipation"] = array_of(r.gap_dissipation);
        d["approach_force"] = array_of(r.approach_force);
        d["retract_force"] = array_of(r.retract_force);
        d["dropped"] = r.dropped;
        d["contact_gap"] = r.contact_gap;
        d["round_trip_amplitude_ratio"] = array_of(r.round_trip_amplitude_ratio);
        d["round_trip_phase"] = array_of(r.round_trip_phase);
        d["residual_amplitude_ratio"] = array_of(r.residual_amplitude_ratio);
        d["residual_phase"] = array_of(r.residual_phase);
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
