// Force laws written in Python (afmkit.laws.Python; docs/force-laws.md#python) and the evaluation of any law as the
// commands use it (afmkit.laws.Law.force).
//
// A Python law is a ForceLawModel (include/afmkit/impact/force_law.hpp), the interface of every C++ law, so every
// command that takes a law takes it. The user's callables are vectorised NumPy functions of the gap in metres; the
// engine asks for one gap at a time, in sequence (each integrator stage depends on the previous one), so per-point
// calls into Python (about 1–5 µs each, under the GIL) would cost hundreds of times a built-in law. Instead
// python/afmkit/laws.py evaluates each callable in a few vectorised batches on an adaptive grid of Chebyshev pieces
// (degree 16, Lobatto points) over the law's domain, refining each piece until the interpolant matches the callable
// at the midpoints to 1e-12 of the largest force on its interval (docs/force-laws.md#python), and hands the pieces
// here: inside the domain the law is the piecewise Chebyshev series (Clenshaw; slopes from the derived series), with
// no Python and no GIL during a run. Pieces that could not be resolved next to a declared switching gap (an endpoint
// singularity such as √δ) and every gap outside the domain are evaluated by calling the callable itself, taking the
// GIL; an exception it raises, or a result that is not one finite number per gap, is the user's error
// (afmkit.InvalidParameter naming the callable), never a crash.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/force_law.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "bindings.hpp"
#include "numpy_arrays.hpp"
#include "python_law.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

constexpr double kNm = 1e-9;  // m per nm; also N per nN

/// Σ c_k T_k(t) by Clenshaw's recurrence.
double clenshaw(const double* c, int n, double t) {
  double b1 = 0.0, b2 = 0.0;
  for (int k = n; k >= 1; --k) {
    const double b0 = c[k] + 2.0 * t * b1 - b2;
    b2 = b1;
    b1 = b0;
  }
  return c[0] + t * b1 - b2;
}

}  // namespace

PythonBranch::PythonBranch(std::string label, py::object callable, double factor, BranchTable table)
    : label_(std::move(label)),
      callable_(std::make_shared<py::object>(std::move(callable))),
      factor_(factor),
      t_(std::move(table)) {
  const std::size_t pieces = t_.edges.empty() ? 0 : t_.edges.size() - 1;
  const auto n = static_cast<std::size_t>(t_.degree);
  if (t_.degree < 1 || t_.coefficients.size() != pieces * (n + 1) || t_.slopes.size() != pieces * n ||
      t_.u_low.size() != pieces || t_.u_high.size() != pieces || t_.signs.size() != pieces ||
      t_.anchors.size() != pieces)
    throw py::value_error("afmkit.laws.Python: inconsistent tabulation of " + label_ + " (internal)");
}

PythonBranch::~PythonBranch() {
  // the callable is a Python object: released with the GIL held (a law may be dropped on any thread)
  if (callable_ && Py_IsInitialized()) {
    py::gil_scoped_acquire gil;
    callable_.reset();
  }
}

double PythonBranch::call(double gap) const {
  py::gil_scoped_acquire gil;
  try {
    py::array_t<double> x(1);
    x.mutable_data()[0] = gap * kNm;
    const py::object result = (*callable_)(x);
    const py::array_t<double, py::array::forcecast> y = py::array_t<double, py::array::forcecast>::ensure(result);
    if (!y || y.ndim() != 1 || y.size() != 1)
      throw PythonLawError(fmt::format("afmkit.laws.Python: {} must return one number per distance (an array "
                                                "of the shape of its argument), not {} for 1 distance",
                                                label_, py::repr(result).cast<std::string>()));
    const double v = y.data()[0];
    if (!std::isfinite(v))
      throw PythonLawError(fmt::format("afmkit.laws.Python: {} returned {} at distance {:.17g} m: a force "
                                                "law must be finite wherever the tip goes",
                                                label_, v, gap * kNm));
    return v * factor_;
  } catch (py::error_already_set& e) {
    if (e.matches(PyExc_KeyboardInterrupt) || e.matches(PyExc_SystemExit)) throw;  // the caller's stop request
    const std::string type = py::str(e.type().attr("__name__"));
    const std::string message = py::str(e.value());
    throw PythonLawError(fmt::format("afmkit.laws.Python: {} raised {}: {} at distance {:.17g} m", label_, type,
                                     message, gap * kNm));
  }
}

std::ptrdiff_t PythonBranch::locate(double gap, double& t, double& u) const {
  if (t_.edges.size() < 2 || !(gap >= t_.edges.front() && gap <= t_.edges.back())) return -1;
  const std::size_t last = t_.edges.size() - 2;  // the last piece
  std::size_t i = hint_.load(std::memory_order_relaxed);
  if (!(i <= last && gap >= t_.edges[i] && (gap < t_.edges[i + 1] || (i == last && gap <= t_.edges[i + 1])))) {
    const auto it = std::upper_bound(t_.edges.begin(), t_.edges.end(), gap);
    i = std::min<std::size_t>(static_cast<std::size_t>(it - t_.edges.begin()) - 1, last);
    hint_.store(i, std::memory_order_relaxed);
  }
  const double sign = t_.signs[i];
  u = sign == 0.0 ? gap : std::sqrt(std::max(0.0, sign * (gap - t_.anchors[i])));
  t = (2.0 * u - t_.u_low[i] - t_.u_high[i]) / (t_.u_high[i] - t_.u_low[i]);
  return static_cast<std::ptrdiff_t>(i);
}

double PythonBranch::value(double gap) const {
  double t = 0.0, u = 0.0;
  const std::ptrdiff_t i = locate(gap, t, u);
  if (i >= 0) {
    const double* c = t_.coefficients.data() + static_cast<std::size_t>(i) * static_cast<std::size_t>(t_.degree + 1);
    if (!std::isnan(c[0])) return clenshaw(c, t_.degree, t);
  }
  return call(gap);  // outside the domain, or a piece evaluated directly
}

double PythonBranch::slope(double gap) const {
  double t = 0.0, u = 0.0;
  const std::ptrdiff_t i = locate(gap, t, u);
  if (i >= 0) {
    const double* c = t_.slopes.data() + static_cast<std::size_t>(i) * static_cast<std::size_t>(t_.degree);
    if (!std::isnan(c[0])) {
      const double sign = t_.signs[i];
      if (sign == 0.0) return clenshaw(c, t_.degree - 1, t);  // u = d
      // d = g ± u²: dF/dd = ±(dF/du)/(2u); at the gap itself (u → 0) the slope an instant away
      const double u_eff = std::max(u, 1e-9 * t_.u_high[i]);
      return sign * clenshaw(c, t_.degree - 1, (2.0 * u_eff - t_.u_low[i] - t_.u_high[i]) /
                                                   (t_.u_high[i] - t_.u_low[i])) / (2.0 * u_eff);
    }
  }
  const double h = 1e-6 * std::max(1.0, std::abs(gap));  // nm: central difference of the callable itself
  return (call(gap + h) - call(gap - h)) / (2.0 * h);
}

PythonLawModel::PythonLawModel(std::string name, std::shared_ptr<const PythonBranch> approach,
                               std::shared_ptr<const PythonBranch> departure, std::shared_ptr<const PythonBranch> damping,
                               std::vector<double> switching_gaps, double contact_gap)
    : name_(std::move(name)),
      approach_(std::move(approach)),
      departure_(departure ? std::move(departure) : approach_),
      damping_(std::move(damping)),
      switching_gaps_(std::move(switching_gaps)),
      contact_gap_(contact_gap),
      conservative_(departure_ == approach_) {}

double PythonLawModel::contact_gap() const {
  return std::isnan(contact_gap_) ? ForceLawModel::contact_gap() : contact_gap_;
}

namespace {

/// The values as SI arrays: approach and departure branches [N], damping [N·s/m], and H(d, ḋ) [N] when rates are
/// given (eq. 4 with the Kelvin–Voigt term; a contact-aware law in contact when `in_contact`).
py::dict evaluate(const impact::ForceLaw& law, const Array& distance, const py::object& velocity, bool in_contact) {
  const std::vector<double> d = vector_of(distance, "distance");
  std::vector<double> rate;
  if (!velocity.is_none()) {
    rate = vector_of(Array::ensure(velocity), "velocity");
    if (rate.size() == 1) rate.assign(d.size(), rate[0]);
    if (rate.size() != d.size())
      throw InvalidParameter("velocity", fmt::format("velocity has {} values and distance {}: one velocity per "
                                                     "distance, or one for all",
                                                     rate.size(), d.size()));
  }
  std::vector<double> a(d.size()), b(d.size()), c(d.size()), f(rate.empty() ? 0 : d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double gap = d[i] / kNm;
    a[i] = law.approach(gap) * kNm;
    b[i] = law.departure(gap) * kNm;
    c[i] = law.damping(gap);  // nN·s/nm = N·s/m
    if (!rate.empty()) f[i] = law.force(gap, rate[i] / kNm, in_contact) * kNm;
  }
  py::dict out;
  out["approach"] = array_of(a);
  out["departure"] = array_of(b);
  out["damping"] = array_of(c);
  if (!rate.empty()) out["force"] = array_of(f);
  out["switching_gaps"] = [&] {
    std::vector<double> g = law.switching_gaps();
    for (double& x : g) x *= kNm;
    return array_of(g);
  }();
  out["contact_gap"] = law.contact_gap() * kNm;
  out["release_gap"] = law.release_gap() * kNm;
  out["hysteresis"] = std::string(impact::hysteresis_name(law.hysteresis()));
  return out;
}

}  // namespace

void bind_python_law(py::module_& m) {
  py::class_<PythonLawModel, std::shared_ptr<PythonLawModel>>(
      m, "PythonLaw",
      "A force law written in Python as the commands use it (built by afmkit.laws.Python: tabulated branches in "
      "nm and nN, the callables beyond).")
      .def(py::init([](const std::string& name, const py::dict& approach, const py::object& departure,
                       const py::object& damping, std::vector<double> switching_gaps, double contact_gap) {
             auto branch = [](const py::object& o) -> std::shared_ptr<const PythonBranch> {
               if (o.is_none()) return nullptr;
               const py::dict b = o.cast<py::dict>();
               BranchTable t;
               t.edges = b["edges"].cast<std::vector<double>>();
               t.coefficients = b["coefficients"].cast<std::vector<double>>();
               t.slopes = b["slopes"].cast<std::vector<double>>();
               t.u_low = b["u_low"].cast<std::vector<double>>();
               t.u_high = b["u_high"].cast<std::vector<double>>();
               t.signs = b["signs"].cast<std::vector<double>>();
               t.anchors = b["anchors"].cast<std::vector<double>>();
               t.degree = b["degree"].cast<int>();
               return std::make_shared<const PythonBranch>(b["label"].cast<std::string>(),
                                                           py::reinterpret_borrow<py::object>(b["callable"]),
                                                           b["factor"].cast<double>(), std::move(t));
             };
             std::sort(switching_gaps.begin(), switching_gaps.end());
             return std::make_shared<PythonLawModel>(name, branch(approach), branch(departure), branch(damping),
                                                     std::move(switching_gaps), contact_gap);
           }),
           py::arg("name"), py::arg("approach"), py::arg("departure"), py::arg("damping"), py::arg("switching_gaps"),
           py::arg("contact_gap"))
      .def_property_readonly("name", &PythonLawModel::name);
  m.def(
      "law_values",
      [](const py::object& law, const std::string& name, const std::map<std::string, double>& values,
         const std::string& force_curve, const std::string& hysteresis, bool allow_energy_gain, const Array& distance,
         const py::object& velocity, bool in_contact) {
        impact::LawArguments args;
        args.values = values;
        args.force_curve = force_curve;
        args.hysteresis = hysteresis;
        args.allow_energy_gain = allow_energy_gain;
        if (!law.is_none()) args.model = law.cast<std::shared_ptr<PythonLawModel>>();
        const impact::ForceLaw built = impact::LawRegistry::builtin().build(name, args);
        try {
          return evaluate(built, distance, velocity, in_contact);
        } catch (const PythonLawError& e) {
          throw InvalidParameter("law", e.what());
        }
      },
      py::arg("law"), py::arg("name"), py::arg("values"), py::arg("force_curve"), py::arg("hysteresis"),
      py::arg("allow_energy_gain"), py::arg("distance"), py::arg("velocity"), py::arg("in_contact"),
      "A law of the registry (`law`: the PythonLaw of law = python, else None) evaluated at SI distances [m] (and "
      "velocities [m/s]) as the commands use it: approach, departure [N], damping [N s/m], force [N], switching and "
      "contact gaps [m].");
}

}  // namespace afmkit::python
