// _afmkit.evaluate_points: one chunk of a parameter study (python/afmkit/study/) computed in C++ — the points'
// parameters set, the command run and the outputs extracted without the interpreter (no Python per point).
//
// An output is a selector on what the command computed (study_selector.hpp, docs/study.md#outputs).
// A point whose computation fails numerically (no convergence) gets NaN in every output and is counted.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/params.hpp"
#include "bindings.hpp"
#include "interrupts.hpp"
#include "command.hpp"
#include "params_from_python.hpp"
#include "study_selector.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using study::Selector;

/// The result of one chunk: outputs[point, output] and the number of points that failed numerically.
struct ChunkResult {
  py::array_t<double> outputs;
  long failed = 0;
};

ChunkResult evaluate_points(const std::string& path, const py::dict& base, const std::vector<std::string>& names,
                            const py::array_t<double, py::array::c_style | py::array::forcecast>& values,
                            const std::vector<std::string>& outputs, std::vector<std::string>* units = nullptr) {
  std::string fn = "afmkit.study(" + path + ")";
  const cli::CommandSpec& spec = command_spec(path);
  const io::ParamSet prepared = params_from_python(path, fn, base);
  if (values.ndim() != 2 || values.shape(1) != static_cast<py::ssize_t>(names.size()))
    throw py::value_error("evaluate_points: values must be an array of shape (points, axes)");
  std::vector<bool> integer;  // per axis: an integer parameter (else real)
  const auto described = prepared.describe();
  for (const std::string& n : names) {
    const auto it = std::find_if(described.begin(), described.end(), [&](const auto& d) { return d.key == n; });
    if (it == described.end() || (it->kind != "real" && it->kind != "integer"))
      throw InvalidParameter("axes", "axes: '" + n + "' is not a numeric parameter of afmkit " + path);
    integer.push_back(it->kind == "integer");
  }
  std::vector<Selector> selectors;
  for (const std::string& o : outputs) selectors.push_back(study::parse_selector(o));
  if (selectors.empty()) throw InvalidParameter("outputs", "outputs: at least one output is needed");
  const bool rows = std::any_of(selectors.begin(), selectors.end(), [](const Selector& s) {
    return s.aggregate != study::Aggregate::none;
  });

  const auto n = static_cast<std::size_t>(values.shape(0));
  ChunkResult out;
  out.outputs = py::array_t<double>({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(selectors.size())});
  double* o = out.outputs.mutable_data();
  const double* v = values.data();
  SignalPoll interrupts;  // Ctrl-C stops the chunk at the next point (or inside a long point) with KeyboardInterrupt
  interrupts.run([&] {
    bool bound = false;
    for (std::size_t i = 0; i < n; ++i) {
      interrupts.cancellation().check();
      io::ParamSet p = prepared;
      for (std::size_t j = 0; j < names.size(); ++j) {
        const double x = v[i * names.size() + j];
        if (integer[j]) {
          if (!(std::isfinite(x) && x == std::floor(x) && std::abs(x) < 9.0e15))
            throw InvalidParameter(names[j], "axes: " + names[j] + " = " + std::to_string(x) + " is not an integer");
          p.set_value(names[j], static_cast<long>(x));
        } else {
          p.set_value(names[j], x);
        }
      }
      cli::Captured captured;
      captured.want_rows = rows;
      captured.cancellation = interrupts.cancellation();
      try {
        spec.run(p, &captured);
      } catch (const NumericalFailure&) {
        ++out.failed;
        for (std::size_t k = 0; k < selectors.size(); ++k) o[i * selectors.size() + k] = kNaN;
        continue;
      }
      if (!bound) {
        study::bind_selectors(selectors, captured);
        bound = true;
        if (units) {  // output_units: the first point that computes is enough
          for (const Selector& s : selectors) units->push_back(s.unit);
          break;
        }
      }
      for (std::size_t k = 0; k < selectors.size(); ++k)
        o[i * selectors.size() + k] = study::extract(selectors[k], captured);
    }
  });
  return out;
}

}  // namespace

void bind_study(py::module_& m) {
  m.def(
      "evaluate_points",
      [](const std::string& path, const py::dict& base, const std::vector<std::string>& names,
         const py::array_t<double, py::array::c_style | py::array::forcecast>& values,
         const std::vector<std::string>& outputs) {
        ChunkResult r = evaluate_points(path, base, names, values, outputs);
        return py::make_tuple(r.outputs, r.failed);
      },
      py::arg("path"), py::arg("base"), py::arg("names"), py::arg("values"), py::arg("outputs"),
      "One chunk of a study: command `path` with parameters `base` (TOML keys), at each row of `values` (columns: "
      "the parameters `names`), returning (outputs[point, output] as float64, points that failed numerically).");
  m.def(
      "output_units",
      [](const std::string& path, const py::dict& base, const std::vector<std::string>& names,
         const py::array_t<double, py::array::c_style | py::array::forcecast>& values,
         const std::vector<std::string>& outputs) {
        std::vector<std::string> units;
        evaluate_points(path, base, names, values, outputs, &units);
        if (units.empty()) units.assign(outputs.size(), "");  // no point computed: units unknown
        return units;
      },
      py::arg("path"), py::arg("base"), py::arg("names"), py::arg("values"), py::arg("outputs"),
      "The unit of each study output (docs/study.md#outputs), from the first row of `values` whose computation "
      "succeeds; checks the selectors as evaluate_points does.");
}

}  // namespace afmkit::python
