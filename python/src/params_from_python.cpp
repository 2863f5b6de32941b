// Keyword arguments → io::ParamSet (params_from_python.hpp).
#include "params_from_python.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <variant>
#include <vector>

#include <pybind11/stl.h>

#include "afmkit/core/error.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

/// Every command but those that are Python already or write a store rather than a table: `report` (from Python
/// afmkit.report.build), `study run` (afmkit.study.run) and `tapping grid` (a study of tapping.orbit, afmkit.study).
std::vector<cli::CommandSpec> python_commands() {
  std::vector<cli::CommandSpec> out = cli::command_specs();
  std::erase_if(out, [](const cli::CommandSpec& s) {
    return s.path == "report" || s.path == "study run" || s.path == "tapping grid";
  });
  return out;
}

/// A Python str as UTF-8. A str that cannot be encoded (a lone surrogate, e.g. from a file name decoded with
/// surrogateescape) is the caller's error: InvalidParameter naming `key` (ValueError), never a numerical failure.
std::string utf8(const std::string& key, const py::handle& s) {
  Py_ssize_t size = 0;
  const char* data = PyUnicode_AsUTF8AndSize(s.ptr(), &size);
  if (data == nullptr) {
    std::string where;
    if (PyErr_ExceptionMatches(PyExc_UnicodeEncodeError)) {
      PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;
      PyErr_Fetch(&type, &value, &traceback);
      Py_ssize_t start = 0;
      if (value != nullptr && PyUnicodeEncodeError_GetStart(value, &start) == 0)
        where = " (character " + std::to_string(start) + ")";
      Py_XDECREF(type);
      Py_XDECREF(value);
      Py_XDECREF(traceback);
    }
    PyErr_Clear();
    throw InvalidParameter(key, key + " is not valid Unicode text" + where +
                                    ": a lone surrogate cannot be encoded as UTF-8; must be UTF-8 text");
  }
  return std::string(data, static_cast<std::size_t>(size));
}

/// A path argument: str (UTF-8, as utf8()), bytes (as given) or os.PathLike of either.
std::string path_text(const std::string& key, const py::handle& obj) {
  py::object v = py::reinterpret_borrow<py::object>(obj);
  if (!py::isinstance<py::str>(v) && !py::isinstance<py::bytes>(v) && py::hasattr(v, "__fspath__"))
    v = v.attr("__fspath__")();
  if (py::isinstance<py::bytes>(v)) return v.cast<std::string>();
  return utf8(key, v);
}

/// A Python value as the parameter's type; TypeError naming the parameter otherwise.
io::ParamSet::Value value_from_python(const std::string& name, const io::ParamSet::Description& d,
                                      const py::handle& obj) {
  auto fail = [&](const char* want) {
    throw py::type_error(name + "(): " + d.key + " must be " + want + ", not " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))));
  };
  // a plain float, int, bool or str has neither dtype nor ndim (asking costs an AttributeError each)
  const auto plain = [](const py::handle& x) {
    return PyFloat_CheckExact(x.ptr()) || PyLong_CheckExact(x.ptr()) || PyBool_Check(x.ptr()) ||
           PyUnicode_CheckExact(x.ptr());
  };
  const bool is_bool = py::isinstance<py::bool_>(obj) ||
                       (!plain(obj) && py::hasattr(obj, "dtype") &&
                        py::str(obj.attr("dtype").attr("kind")).cast<std::string>() == "b");
  if (d.kind == "flag") {
    if (!is_bool) fail("True or False");
    return py::bool_(py::reinterpret_borrow<py::object>(obj)).cast<bool>();
  }
  if (d.kind == "text" || d.kind == "file") {
    if (d.kind == "file" && py::hasattr(obj, "__fspath__")) return path_text(d.key, obj);
    if (!py::isinstance<py::str>(obj)) fail(d.kind == "file" ? "a path (str or os.PathLike)" : "a str");
    return utf8(d.key, obj);
  }
  auto number = [&](const py::handle& x) -> double {
    const bool b = py::isinstance<py::bool_>(x) ||
                   (!plain(x) && py::hasattr(x, "dtype") &&
                    py::str(x.attr("dtype").attr("kind")).cast<std::string>() == "b");
    const bool array = !plain(x) && py::hasattr(x, "ndim") && py::int_(x.attr("ndim")).cast<int>() != 0;  // not a scalar
    const char* want = d.kind == "reals" ? "a sequence of real numbers" : "a real number";
    if (b || array || py::isinstance<py::str>(x) || !PyNumber_Check(x.ptr()) || PyComplex_Check(x.ptr())) fail(want);
    const double v = PyFloat_AsDouble(x.ptr());
    if (v == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      fail(want);
    }
    return v;
  };
  // an int beyond the range of long: out of range (every integer parameter's range is far inside it)
  auto whole = [&](const py::handle& x) -> long {
    int overflow = 0;
    const py::int_ i(py::reinterpret_borrow<py::object>(x));
    const long v = PyLong_AsLongAndOverflow(i.ptr(), &overflow);
    if (overflow != 0)
      throw InvalidParameter(d.key, d.key + " = " + py::repr(i).cast<std::string>() + " is out of range: must be " +
                                        (d.allowed.starts_with("integer") ? "an " : "") + d.allowed);
    return v;
  };
  const bool scalar = plain(obj) || !py::hasattr(obj, "ndim") || py::int_(obj.attr("ndim")).cast<int>() == 0;  // not an array
  if (d.kind == "integer") {
    if (is_bool || !scalar || !PyIndex_Check(obj.ptr())) fail("an int");
    return whole(obj);
  }
  if (d.kind == "real") {
    if (!scalar) fail("a real number");
    if (PyIndex_Check(obj.ptr()) && !is_bool) {
      const py::int_ i(py::reinterpret_borrow<py::object>(obj));
      const double v = PyLong_AsDouble(i.ptr());  // inf beyond the double range: refused by the range check
      if (v == -1.0 && PyErr_Occurred()) {
        PyErr_Clear();
        return py::repr(i).cast<std::string>().front() == '-' ? -HUGE_VAL : HUGE_VAL;
      }
      return v;
    }
    return number(obj);
  }
  if (py::isinstance<py::str>(obj) || !(py::isinstance<py::sequence>(obj) || py::hasattr(obj, "__array__")))
    fail("a sequence of real numbers");
  std::vector<double> out;
  for (const py::handle& x : py::iter(obj)) out.push_back(number(x));
  return out;
}

}  // namespace

const std::vector<cli::CommandSpec>& specs() {
  static const std::vector<cli::CommandSpec> all = python_commands();  // built once, read-only afterwards
  return all;
}

const cli::CommandSpec& command_spec(const std::string& path) {
  for (const cli::CommandSpec& s : specs())
    if (s.path == path) return s;
  throw py::value_error("no afmkit command '" + path + "'");
}

namespace detail {
struct Prototype {
  io::ParamSet params;
  std::vector<io::ParamSet::Description> described;
  /// key -> its place in `described` (a keyword's description found without comparing it with every key)
  std::unordered_map<std::string, std::size_t> place;
  /// Copies of `params` that runs gave back (RunParams), reused with their values reset (ParamSet::reset_values):
  /// a copy allocates hundreds of strings (help texts, choices), as much work as a short run's summary.
  mutable std::mutex spare_mutex;
  mutable std::vector<std::unique_ptr<io::ParamSet>> spare;
  /// How many sets are lent out (RunParams::lend), under spare_mutex.
  mutable std::size_t lent = 0;
};
}  // namespace detail

namespace {
using detail::Prototype;
/// A command's parameters with Python's defaults, declared once per process (a command's declaration is fixed: its
/// keys, defaults and ranges do not depend on the run) and reused by each call (RunParams): declaring them and
/// describing them again on every call cost more than a short computation (bench/command_layer.py).
const Prototype& prototype(const cli::CommandSpec& spec) {
  static std::mutex mutex;  // callers hold the GIL; the lock keeps the cache sound without it
  static std::map<std::string, std::unique_ptr<const Prototype>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<const Prototype>& slot = cache[spec.path];
  if (!slot) {
    io::ParamSet p;
    spec.declare(p);
    for (const auto& d : p.describe()) {
      const bool table_file = d.key == "output" || (d.key.size() > 7 && d.key.ends_with("_output"));
      if (table_file && d.kind == "file") p.set_default(d.key, "");
      if (d.key == "json" && d.kind == "flag") p.set_default("json", "true");
    }
    std::vector<io::ParamSet::Description> described = p.describe();
    auto made = std::make_unique<Prototype>();
    made->params = std::move(p);
    made->described = std::move(described);
    for (std::size_t i = 0; i < made->described.size(); ++i) made->place.emplace(made->described[i].key, i);
    slot = std::move(made);
  }
  return *slot;
}
}  // namespace

io::ParamSet python_params(const cli::CommandSpec& spec) { return prototype(spec).params; }

io::ParamSet params_from_python(const std::string& path, const std::string& name, const py::dict& kwargs,
                                const std::vector<std::string>& hidden) {
  return RunParams(path, name, kwargs, hidden).get();
}

namespace {
/// At most this many spare sets per command (as many as calls that ran at once, e.g. from Python threads).
constexpr std::size_t kSpareSets = 4;
}  // namespace

RunParams::RunParams(const std::string& path, const std::string& name, const py::dict& kwargs,
                     const std::vector<std::string>& hidden)
    : prototype_(&prototype(command_spec(path))) {
  const Prototype& declared = *prototype_;
  {
    const std::lock_guard<std::mutex> lock(declared.spare_mutex);
    if (!declared.spare.empty()) {
      params_ = std::move(declared.spare.back());
      declared.spare.pop_back();
    }
  }
  if (params_) params_->reset_values(declared.params);
  else params_ = std::make_unique<io::ParamSet>(declared.params);
  fill(name, kwargs, hidden);
}

RunParams::~RunParams() {
  if (!params_) return;
  const std::lock_guard<std::mutex> lock(prototype_->spare_mutex);
  if (prototype_->spare.size() < kSpareSets) prototype_->spare.push_back(std::move(params_));
}

namespace {
/// At most this many sets of one command lent out at once (a loop keeping its Results holds one per Result whose
/// r.params was not read; beyond, the record is made at once: no set per Result, and no copy of the declarations).
constexpr std::size_t kLentSets = 8;
}  // namespace

std::unique_ptr<LentParams> RunParams::lend() {
  {
    const std::lock_guard<std::mutex> lock(prototype_->spare_mutex);
    if (prototype_->lent >= kLentSets) return nullptr;
    ++prototype_->lent;
  }
  return std::make_unique<LentParams>(prototype_, std::move(params_));
}

LentParams::LentParams(const detail::Prototype* prototype, std::unique_ptr<io::ParamSet> params)
    : prototype_(prototype), params_(std::move(params)) {}

LentParams::~LentParams() { give_back(); }

const nlohmann::json& LentParams::record() {
  if (params_) {
    record_ = params_->to_json();
    give_back();
  }
  return record_;
}

void LentParams::give_back() {
  if (!params_) return;
  const std::lock_guard<std::mutex> lock(prototype_->spare_mutex);
  --prototype_->lent;
  if (prototype_->spare.size() < kSpareSets) prototype_->spare.push_back(std::move(params_));
  params_.reset();
}

void RunParams::fill(const std::string& name, const py::dict& kwargs, const std::vector<std::string>& hidden) {
  const Prototype& declared = *prototype_;
  io::ParamSet& p = *params_;
  const std::vector<io::ParamSet::Description>& described = declared.described;
  auto visible = [&](const std::string& key) {
    return key != "json" && std::find(hidden.begin(), hidden.end(), key) == hidden.end();
  };
  if (kwargs.contains("config") && !kwargs["config"].is_none()) {
    const py::object c = kwargs["config"];
    if (!py::isinstance<py::str>(c) && !py::hasattr(c, "__fspath__"))
      throw py::type_error(name + "(): config must be a path (str or os.PathLike) of a TOML file");
    p.set_config_path(path_text("config", c));
  }
  p.resolve();  // the TOML file, if any; the keyword arguments come on top
  for (const auto& [k, v] : kwargs) {
    if (!py::isinstance<py::str>(k)) throw py::type_error(name + "(): keywords must be strings");
    const std::string key = utf8("keyword", k);
    if (key == "config") continue;
    const auto at = declared.place.find(key);
    const io::ParamSet::Description* d = at != declared.place.end() && visible(key) ? &described[at->second] : nullptr;
    if (d == nullptr) {
      std::string allowed;
      for (const auto& x : described)
        if (visible(x.key)) allowed += (allowed.empty() ? "" : ", ") + x.key;
      throw py::type_error(name + "() got an unexpected keyword argument '" + key + "' (allowed: config, " + allowed +
                           ")");
    }
    if (v.is_none()) continue;  // not given (the default; Python signatures show None where it follows another key)
    p.set_value(key, value_from_python(name, *d, v));
  }
  p.check_files();  // the keyword arguments came after resolve(): no output may replace an input
}

}  // namespace afmkit::python
