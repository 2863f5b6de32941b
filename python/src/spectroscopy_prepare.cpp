// afmkit.spectroscopy.prepare on NumPy arrays: the curve given as arrays (SI units) instead of a file, prepared by
// the same code, parameters and messages as `afmkit spectroscopy prepare` (apps/spectroscopy_prepare.hpp).
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/curves/raw_curve.hpp"
#include "afmkit/io/output.hpp"
#include "bindings.hpp"
#include "interrupts.hpp"
#include "params_from_python.hpp"
#include "spectroscopy_prepare.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

std::vector<double> channel(const py::object& o) {
  if (o.is_none()) return {};
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(o);
  if (!a || a.ndim() != 1) throw InvalidParameter("height", "every channel must be a one-dimensional array of numbers");
  return {a.data(), a.data() + a.size()};
}

io::curves::SegmentKind kind_of(const std::string& k) {
  using io::curves::SegmentKind;
  if (k == "approach") return SegmentKind::approach;
  if (k == "retract") return SegmentKind::retract;
  if (k == "pause") return SegmentKind::pause;
  return SegmentKind::unknown;
}

/// curves: a list of curves, each a list of segments (kind, height, deflection, deflection_volts, force), arrays in
/// SI units or None; kwargs: the command's keys. Returns the results, parameters and rows as JSON text.
py::dict prepare_arrays(const py::list& curves, const py::dict& kwargs) {
  const io::ParamSet p =
      params_from_python("spectroscopy prepare", "afmkit.spectroscopy.prepare", kwargs, cli::prepare_file_keys());
  std::vector<io::curves::RawCurve> raw;
  std::size_t index = 0;
  for (const auto& c : curves) {
    io::curves::RawCurve curve;
    curve.origin = curves.size() > 1 ? "arrays (curve " + std::to_string(++index) + ")" : "arrays";
    curve.metadata.format = "arrays";
    for (const auto& s : c.cast<py::list>()) {
      const auto t = s.cast<py::tuple>();
      io::curves::Segment seg;
      seg.kind = kind_of(t[0].cast<std::string>());
      seg.height = channel(t[1]);
      seg.deflection = channel(t[2]);
      seg.deflection_volts = channel(t[3]);
      seg.force = channel(t[4]);
      curve.segments.push_back(std::move(seg));
    }
    raw.push_back(std::move(curve));
  }
  cli::Captured captured;
  SignalPoll interrupts;
  captured.cancellation = interrupts.cancellation();
  interrupts.run([&] { cli::run_prepare_curves(p, raw, &captured); });
  py::dict out;
  out["results"] = io::json_text(captured.results);
  nlohmann::json params = captured.parameters;
  params.erase("json");
  for (const std::string& key : cli::prepare_file_keys()) params.erase(key);  // not keywords of prepare(arrays)
  out["params"] = io::json_text(params);
  out["rows"] = captured.rows.dump();
  return out;
}

}  // namespace

void bind_spectroscopy_prepare(py::module_& m) {
  m.def("spectroscopy_prepare_arrays", &prepare_arrays, py::arg("curves"), py::arg("kwargs"),
        "afmkit.spectroscopy.prepare on arrays (python/afmkit/spectroscopy.py is the public face).");
}

}  // namespace afmkit::python
