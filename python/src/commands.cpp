// The commands of the `afmkit` program as Python functions (python/afmkit/_commands.py builds the public functions
// from `commands()`): keyword arguments are the TOML keys, validated by the same ParamSet with the same messages;
// results come back as the summary document, the column descriptions and the table as NumPy arrays.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/params.hpp"
#include "bindings.hpp"
#include "interrupts.hpp"
#include "command.hpp"
#include "params_from_python.hpp"
#include "python_law.hpp"

namespace py = pybind11;

namespace afmkit::python {

namespace {

using cli::CommandSpec;

/// The commands whose law comes from law_from_params with the caller's law object (cli::law_object_of).
bool takes_law_object(const std::string& path) {
  for (const char* p : {"tapping orbit", "tapping hb", "tapping sweep", "tapping fm", "tapping image", "tapping modes",
                        "demo", "impact"})
    if (path == p) return true;
  return false;
}

py::object value_to_python(const io::ParamSet::Value& v) {
  return std::visit([](const auto& x) -> py::object { return py::cast(x); }, v);
}

/// `j` as Python objects (dict, list, str, int, float, bool, None), built with the C API directly: a summary
/// document holds hundreds of values (the orbit search's seeds), and pybind11's accessors per item cost as much as
/// a short computation (bench/command_layer.py). Dict keys in the document's order (nlohmann's: sorted). The
/// records of an array mostly have the same keys: a key equal to the previous record's at the same place is the same
/// str object (made and hashed once), as Python shares the names of attributes.
class JsonToPython {
 public:
  /// A new reference, or nullptr with a Python error set.
  PyObject* convert(const nlohmann::json& j) { return convert(j, nullptr); }

 private:
  /// The keys of the previous record of an array, in order: its text and its str (borrowed: its dict holds it).
  using Keys = std::vector<std::pair<const std::string*, PyObject*>>;

  /// `previous`: the keys of the previous record of the array `j` is in (nullptr: not in an array); updated to
  /// those of `j` when it is a record.
  PyObject* convert(const nlohmann::json& j, Keys* previous) {
    switch (j.type()) {
      case nlohmann::json::value_t::boolean: return PyBool_FromLong(j.get<bool>() ? 1 : 0);
      case nlohmann::json::value_t::number_integer: return PyLong_FromLongLong(j.get<std::int64_t>());
      case nlohmann::json::value_t::number_unsigned: return PyLong_FromUnsignedLongLong(j.get<std::uint64_t>());
      case nlohmann::json::value_t::number_float: return PyFloat_FromDouble(j.get<double>());
      case nlohmann::json::value_t::string: {
        const std::string& t = j.get_ref<const std::string&>();
        return PyUnicode_FromStringAndSize(t.data(), static_cast<Py_ssize_t>(t.size()));
      }
      case nlohmann::json::value_t::array: {
        PyObject* l = PyList_New(static_cast<Py_ssize_t>(j.size()));
        if (l == nullptr) return nullptr;
        Keys keys;  // of the records in this array
        Py_ssize_t i = 0;
        for (const auto& x : j) {
          PyObject* v = convert(x, &keys);
          if (v == nullptr) {
            Py_DECREF(l);
            return nullptr;
          }
          PyList_SET_ITEM(l, i++, v);  // steals v
        }
        return l;
      }
      case nlohmann::json::value_t::object: {
        PyObject* d = PyDict_New();
        if (d == nullptr) return nullptr;
        std::size_t at = 0;
        for (const auto& [k, x] : j.get_ref<const nlohmann::json::object_t&>()) {
          PyObject* key = nullptr;
          if (previous != nullptr && at < previous->size() && *(*previous)[at].first == k) {
            key = (*previous)[at].second;
            Py_INCREF(key);
          } else {
            key = PyUnicode_FromStringAndSize(k.data(), static_cast<Py_ssize_t>(k.size()));
          }
          PyObject* v = key == nullptr ? nullptr : convert(x, nullptr);
          const int failed = v == nullptr ? -1 : PyDict_SetItem(d, key, v);
          if (failed == 0 && previous != nullptr) {  // the dict holds the key now
            if (at < previous->size()) (*previous)[at] = {&k, key};
            else previous->emplace_back(&k, key);
          }
          Py_XDECREF(key);
          Py_XDECREF(v);
          if (failed != 0) {
            Py_DECREF(d);
            return nullptr;
          }
          ++at;
        }
        return d;
      }
      default: Py_RETURN_NONE;  // null (and discarded/binary, which a summary never holds)
    }
  }
};

py::object json_to_python(const nlohmann::json& j) {
  PyObject* o = JsonToPython().convert(j);
  if (o == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::object>(o);
}

/// A command's column names, units and meanings as Python objects, kept from its last call: a command's table has
/// the same columns on every call (made and freed per call, ~60 str objects and two dicts cost a short command ~2 %:
/// bench/command_layer.py), so a call whose columns have the last call's texts gets copies of the last call's list
/// and dicts (a dict copy clones its table at once), holding the same str objects (immutable: sharing them is
/// invisible to the caller). Texts are compared, not hashed (most differ in length at once). The caller holds the GIL.
class ColumnTexts {
 public:
  /// New objects for this call: the names in order, name -> unit, name -> description.
  struct Made {
    py::list names;
    py::dict units, meaning;
  };
  template <class Columns>
  Made of(const Columns& columns) {
    if (!same(columns)) remake(columns);
    Made out;
    out.names = py::reinterpret_steal<py::list>(PyList_GetSlice(names_.ptr(), 0, PyList_GET_SIZE(names_.ptr())));
    out.units = py::reinterpret_steal<py::dict>(PyDict_Copy(units_.ptr()));
    out.meaning = py::reinterpret_steal<py::dict>(PyDict_Copy(meaning_.ptr()));
    if (!out.names || !out.units || !out.meaning) throw py::error_already_set();
    return out;
  }

 private:
  template <class Columns>
  bool same(const Columns& columns) const {
    if (!made_ || kept_.size() != 3 * columns.size()) return false;
    std::size_t i = 0;
    for (const io::Column& c : columns)
      if (kept_[i++] != c.name || kept_[i++] != c.unit || kept_[i++] != c.description) return false;
    return true;
  }
  template <class Columns>
  void remake(const Columns& columns) {
    py::list names;
    py::dict units, meaning;
    std::vector<std::string> kept;
    for (const io::Column& c : columns) {
      const py::str name(c.name);
      names.append(name);
      units[name] = py::str(c.unit);
      meaning[name] = py::str(c.description);
      kept.insert(kept.end(), {c.name, c.unit, c.description});
    }
    names_ = std::move(names);
    units_ = std::move(units);
    meaning_ = std::move(meaning);
    kept_ = std::move(kept);
    made_ = true;
  }

  bool made_ = false;
  std::vector<std::string> kept_;  // name, unit, description of each column of the last call
  py::list names_;
  py::dict units_, meaning_;
};

/// Command `path`'s ColumnTexts (never destroyed: its str objects live as long as the interpreter; the commands
/// are few).
ColumnTexts& column_texts(const std::string& path) {
  static auto* texts = new std::map<std::string, ColumnTexts, std::less<>>;
  return (*texts)[path];
}

/// `text` as a str made once per process (Result's attribute names), a borrowed reference.
PyObject* interned(const char* text) {
  PyObject* s = PyUnicode_InternFromString(text);
  if (s == nullptr) throw py::error_already_set();
  return s;  // the interned table keeps it (the static that holds the pointer never releases it)
}

/// Whether column `c` is a flag (unit "boolean", "boolean (0/1)") holding only booleans or 0/1 (no NaN).
bool flag_column(const io::Column& column, const nlohmann::json& rows, std::size_t c) {
  if (column.unit.rfind("boolean", 0) != 0) return false;
  for (const auto& r : rows)
    if (!(r[c].is_boolean() || (r[c].is_number() && (r[c].get<double>() == 0.0 || r[c].get<double>() == 1.0))))
      return false;
  return true;
}

/// A new 1-D NumPy array of `n` elements of type T (float64, bool), made by NumPy's C API as pybind11's array_t(n)
/// makes it, without its shape and strides containers (a third of the cost, per column of every call).
template <class T>
py::array_t<T> new_column(py::ssize_t n) {
  const auto& api = py::detail::npy_api::get();
  PyObject* descr = api.PyArray_DescrFromType_(py::detail::npy_format_descriptor<T>::value);
  if (descr == nullptr) throw py::error_already_set();
  Py_intptr_t shape[1] = {static_cast<Py_intptr_t>(n)};
  // C order, owning its data, writeable (NumPy's defaults for data it allocates); takes the reference to descr
  PyObject* a = api.PyArray_NewFromDescr_(api.PyArray_Type_, descr, 1, shape, nullptr, nullptr, 0, nullptr);
  if (a == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::array_t<T>>(a);
}

/// The numeric columns of a table as the rows of one float64 block (columns x rows, C order), each column a view of
/// its row: one allocation for the table's numbers rather than one per column (a short command's 20 columns cost
/// ~1 % of it: bench/command_layer.py). The views are writeable, C-contiguous float64 arrays like any other; their
/// `base` is the block.
class NumberBlock {
 public:
  NumberBlock(std::size_t columns, std::size_t rows) : rows_(static_cast<Py_intptr_t>(rows)) {
    const auto& api = py::detail::npy_api::get();
    Py_intptr_t shape[2] = {static_cast<Py_intptr_t>(columns), rows_};
    block_ = py::reinterpret_steal<py::object>(api.PyArray_NewFromDescr_(
        api.PyArray_Type_, api.PyArray_DescrFromType_(py::detail::npy_api::NPY_DOUBLE_), 2, shape, nullptr, nullptr, 0,
        nullptr));
    if (!block_) throw py::error_already_set();
    data_ = static_cast<double*>(py::reinterpret_borrow<py::array>(block_).mutable_data());
  }
  /// Row `c` of the block (rows() values to fill).
  double* row(std::size_t c) { return data_ + static_cast<Py_intptr_t>(c) * rows_; }
  /// Row `c` as a 1-D array viewing the block.
  py::object column(std::size_t c) {
    const auto& api = py::detail::npy_api::get();
    Py_intptr_t shape[1] = {rows_}, strides[1] = {static_cast<Py_intptr_t>(sizeof(double))};
    auto view = py::reinterpret_steal<py::object>(
        api.PyArray_NewFromDescr_(api.PyArray_Type_, api.PyArray_DescrFromType_(py::detail::npy_api::NPY_DOUBLE_), 1,
                                  shape, strides, row(c), py::detail::npy_api::NPY_ARRAY_WRITEABLE_, nullptr));
    if (!view || api.PyArray_SetBaseObject_(view.ptr(), block_.inc_ref().ptr()) != 0) throw py::error_already_set();
    return view;
  }

 private:
  Py_intptr_t rows_;
  py::object block_;
  double* data_ = nullptr;
};

/// Column `c` of the rows: bool for a flag column (flag_column), float64 (a row of `numbers`) when every cell is a
/// number, a boolean or null (NaN), else an array of str.
py::object column_array(const io::Column& column, const nlohmann::json& rows, std::size_t c, NumberBlock& numbers) {
  if (flag_column(column, rows, c)) {
    py::array_t<bool> a = new_column<bool>(static_cast<py::ssize_t>(rows.size()));
    auto w = a.mutable_unchecked<1>();
    py::ssize_t i = 0;
    for (const auto& r : rows) w(i++) = r[c].is_boolean() ? r[c].get<bool>() : r[c].get<double>() == 1.0;
    return a;
  }
  bool numeric = true;
  for (const auto& r : rows)
    if (!(r[c].is_number() || r[c].is_boolean() || r[c].is_null())) numeric = false;
  if (numeric) {
    double* w = numbers.row(c);
    for (const auto& r : rows) {
      const auto& x = r[c];
      *w++ = x.is_boolean() ? (x.get<bool>() ? 1.0 : 0.0) : x.is_null() ? std::nan("") : x.get<double>();
    }
    return numbers.column(c);
  }
  // an array of str as numpy.array(cells, "str") makes it (dtype '<U' of the longest cell, at least 1), made here
  // (the Python call costs a short command ~1 %)
  std::vector<py::str> cells;
  cells.reserve(rows.size());
  Py_ssize_t longest = 1;
  for (const auto& r : rows) {
    cells.push_back(r[c].is_string() ? py::str(r[c].get_ref<const std::string&>()) : py::str(r[c].dump()));
    longest = std::max(longest, PyUnicode_GET_LENGTH(cells.back().ptr()));
  }
  const auto& api = py::detail::npy_api::get();
  // the dtype of that width, made once per width (parsing "<U7" costs as much as the array); dtypes are immutable
  static auto* made = new std::map<Py_ssize_t, py::dtype>;
  auto at = made->find(longest);
  if (at == made->end()) at = made->emplace(longest, py::dtype("<U" + std::to_string(longest))).first;
  const py::dtype& type = at->second;
  Py_intptr_t shape[1] = {static_cast<Py_intptr_t>(cells.size())};
  auto a = py::reinterpret_steal<py::array>(api.PyArray_NewFromDescr_(api.PyArray_Type_, type.inc_ref().ptr(), 1, shape,
                                                                      nullptr, nullptr, 0, nullptr));  // takes descr
  if (!a) throw py::error_already_set();
  auto* data = static_cast<char*>(a.mutable_data());
  const std::size_t width = static_cast<std::size_t>(longest) * sizeof(Py_UCS4);
  std::memset(data, 0, width * cells.size());  // shorter cells end in zeros
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (PyUnicode_AsUCS4(cells[i].ptr(), reinterpret_cast<Py_UCS4*>(data + i * width), longest, 0) == nullptr)
      throw py::error_already_set();
  return a;
}

/// Every leaf command of the program, in registration order (the registry: commands.hpp, program.cpp).
const std::vector<CommandSpec>& program_specs() {
  static const std::vector<CommandSpec> all = cli::command_specs();  // built once, read-only afterwards
  return all;
}

/// Whether `run` runs command `path` (specs(): not `report`, `study run`, `tapping grid`).
bool runnable(const std::string& path) {
  return std::any_of(specs().begin(), specs().end(), [&](const CommandSpec& s) { return s.path == path; });
}

/// The parameters of `s` as Python sees them: a command `run` runs with its Python defaults (python_params), any
/// other (a Python program the command line starts) with the command line's. `positional`: also the command's
/// positional argument (`afmkit study run FILE`).
py::list describe(const CommandSpec& s, bool python) {
  io::ParamSet p;
  if (python) p = python_params(s);
  else s.declare(p);
  CLI::App app;  // the options the command line makes of them, to tell which key is positional
  p.add_options(app);
  py::list out;
  for (const auto& d : p.describe()) {
    if (python && d.key == "json") continue;  // always on from Python (nothing printed)
    py::dict e;
    e["key"] = d.key;
    e["kind"] = d.kind;
    e["default"] = value_to_python(d.default_value);
    e["default_text"] = d.default_text;
    e["help"] = d.help;
    e["unit"] = d.unit;
    e["allowed"] = d.allowed;
    e["group"] = d.group;
    e["choices"] = d.choices;
    e["follows"] = d.follows;
    bool positional = false;
    for (const CLI::Option* o : app.get_options())
      positional = positional || (o->get_positional() && o->get_name() == d.key);
    e["positional"] = positional;
    out.append(e);
  }
  return out;
}

/// A progress line of a command (io::Progress) written to Python's sys.stderr as it is then (Jupyter shows it under
/// the running cell; contextlib.redirect_stderr catches it), from whichever thread advances the progress: the
/// computation runs without the GIL, so the line takes it. A Ctrl-C whose handler runs inside the write stops the
/// computation (`interrupts`: it must not be lost with the line); a stderr that fails to write drops the line.
void progress_to_python(const std::string& line, SignalPoll& interrupts) {
  py::gil_scoped_acquire gil;
  try {
    py::object err = py::module_::import("sys").attr("stderr");
    if (err.is_none()) return;
    err.attr("write")(line + "\n");
    err.attr("flush")();
  } catch (py::error_already_set& e) {
    if (interrupts.hold(e)) return;  // the stop request: raised when the computation stops at its next check
    // a closed or broken sys.stderr: progress is not worth an error (the computation goes on)
  }
}

/// The name of the capsules holding a summary's maker (run(), made_summary()).
constexpr const char* kMakerCapsule = "afmkit.results_maker";

/// A summary's maker as a Python object that owns it: a capsule, the cheapest such object (a function object made
/// and freed per call costs a short command ~0.2 %: bench/command_layer.py).
py::capsule maker_capsule(cli::ResultsMaker maker) {
  return py::capsule(new cli::ResultsMaker(std::move(maker)), kMakerCapsule, [](PyObject* o) {
    delete static_cast<cli::ResultsMaker*>(PyCapsule_GetPointer(o, kMakerCapsule));
  });
}

/// The summary the maker in `capsule` makes, as Python objects.
py::object made_summary(const py::capsule& capsule) {
  if (capsule.name() == nullptr || std::string(capsule.name()) != kMakerCapsule)
    throw py::type_error("made_summary() takes the results of run() for a command that makes its summary when read");
  return json_to_python((*capsule.get_pointer<cli::ResultsMaker>())());
}

void set_item(const py::handle& d, const py::handle& key, const py::handle& value) {
  if (PyDict_SetItem(d.ptr(), key.ptr(), value.ptr()) != 0) throw py::error_already_set();
}

/// The name of the capsules holding a run's parameter record (run(), made_params()).
constexpr const char* kParamsCapsule = "afmkit.params_record";

/// A run's parameter record, or the parameter set it is made from (lent: made when first read).
struct ParamsRecord {
  std::unique_ptr<LentParams> lent;
  nlohmann::json json;
  /// The record without `json` (not a keyword from Python: r.params replays as f(**r.params)).
  const nlohmann::json& made() {
    if (lent) {
      json = lent->record();
      lent.reset();  // the set goes back to the command's spare sets
    }
    json.erase("json");
    return json;
  }
};

/// A run's parameter record as a Python object that owns it: afmkit.Result.params makes the dict when first read (a
/// record of ~20 values made and converted on every call costs a short command ~1.5 %: bench/command_layer.py).
py::capsule params_capsule(ParamsRecord record) {
  return py::capsule(new ParamsRecord(std::move(record)), kParamsCapsule, [](PyObject* o) {
    delete static_cast<ParamsRecord*>(PyCapsule_GetPointer(o, kParamsCapsule));
  });
}

/// The parameter record in `capsule` as Python objects.
py::object made_params(const py::capsule& capsule) {
  if (capsule.name() == nullptr || std::string(capsule.name()) != kParamsCapsule)
    throw py::type_error("made_params() takes the params capsule of a Result made by run()");
  return json_to_python(capsule.get_pointer<ParamsRecord>()->made());
}

/// What a run gave as an instance of `type` (afmkit.Result: a dict subclass), made here rather than by its
/// __init__ from a dict of what the run gave (a Python frame, a copy of the table and a dozen attributes per call
/// cost a short command ~1.5 %: bench/command_layer.py): the table's columns are its items; its attributes command,
/// _results (the summary or its maker), _params (the record's capsule: Result.params makes the dict when first read),
/// columns, units, meaning and grid, as Result.__init__ sets them.
py::object typed_result(const py::handle& type, const std::string& path, cli::Captured& captured, py::object summary,
                        ParamsRecord params) {
  if (!PyType_Check(type.ptr()) || !PyType_IsSubtype(reinterpret_cast<PyTypeObject*>(type.ptr()), &PyDict_Type))
    throw py::type_error("run(): result_type must be a subclass of dict (afmkit.Result)");
  auto* t = reinterpret_cast<PyTypeObject*>(type.ptr());
  const py::tuple no_args;
  py::object r = py::reinterpret_steal<py::object>(t->tp_new(t, no_args.ptr(), nullptr));  // dict.__new__
  if (!r) throw py::error_already_set();
  ColumnTexts::Made texts = column_texts(path).of(captured.columns);
  NumberBlock numbers(captured.columns.size(), captured.rows.size());
  for (std::size_t c = 0; c < captured.columns.size(); ++c) {
    const py::handle name = PyList_GET_ITEM(texts.names.ptr(), static_cast<Py_ssize_t>(c));
    // the dict's own storage (its __setitem__ refuses)
    set_item(r, name, column_array(captured.columns[c], captured.rows, c, numbers));
  }
  static PyObject* const command_key = interned("command");
  static PyObject* const results_key = interned("_results");
  static PyObject* const params_key = interned("_params");
  static PyObject* const columns_key = interned("columns");
  static PyObject* const units_key = interned("units");
  static PyObject* const meaning_key = interned("meaning");
  static PyObject* const grid_key = interned("grid");
  py::dict attributes;
  set_item(attributes, command_key, py::str(path));
  set_item(attributes, results_key, summary);
  set_item(attributes, params_key, params_capsule(std::move(params)));
  set_item(attributes, columns_key, texts.names);
  set_item(attributes, units_key, texts.units);
  set_item(attributes, meaning_key, texts.meaning);
  set_item(attributes, grid_key, captured.grid.is_null() ? py::none() : json_to_python(captured.grid));
  if (PyObject_SetAttrString(r.ptr(), "__dict__", attributes.ptr()) != 0) throw py::error_already_set();
  return r;
}

/// Runs command `path` with `kwargs` (TOML keys; `config`: a TOML file loaded first, as --config; a value None is
/// not given). Returns an instance of `result_type` (typed_result).
py::object run(const std::string& path, const py::dict& kwargs, const py::object& result_type) {
  std::string name = "afmkit." + path;
  std::replace(name.begin(), name.end(), ' ', '.');
  const CommandSpec& s = command_spec(path);
  cli::Captured captured;
  py::dict given = kwargs;
  if (kwargs.contains("law") && py::isinstance<PythonLawModel>(kwargs["law"])) {
    // law = python: the law object goes to the run, the record says law = python (docs/force-laws.md#python)
    if (!takes_law_object(path))
      throw InvalidParameter("law", name + ": law = afmkit.laws.Python(...) applies only to the commands that "
                                           "simulate with a given law (tapping orbit, hb, sweep, fm, demo, impact)");
    captured.law = kwargs["law"].cast<std::shared_ptr<PythonLawModel>>();
    given = py::dict();
    for (const auto& [k, v] : kwargs) given[k] = py::str(k).cast<std::string>() == "law" ? py::str("python") : v;
  }
  RunParams run_params(path, name, given);  // a set this command's runs reuse
  const io::ParamSet& p = run_params.get();
  captured.record_later = &p;  // ParamsRecord: made from the set when r.params is read
  SignalPoll interrupts;  // Ctrl-C stops the computation at its next check (KeyboardInterrupt)
  captured.cancellation = interrupts.cancellation();
  // progress lines to sys.stderr (Jupyter), not to descriptor 2
  io::ProgressSink progress([&interrupts](const std::string& line) { progress_to_python(line, interrupts); });
  py::object results;  // the summary as Python objects, converted where the command hands it over (no copy)
  captured.take_results = [&results](const nlohmann::json& document) {
    py::gil_scoped_acquire gil;  // the computation runs without the GIL
    results = json_to_python(document);
  };
  // or, from a command that makes its summary where it is read, the maker: r.results makes it on first access
  cli::ResultsMaker make_results;
  captured.take_results_maker = [&make_results](cli::ResultsMaker maker) { make_results = std::move(maker); };
  try {
    interrupts.run([&] { s.run(p, &captured); });
  } catch (const PythonLawError& e) {  // the user's law failed: their error (exit-2 style), not a crash
    throw InvalidParameter("law", e.what());
  }
  // the maker (afmkit.Result.results makes the summary with it, once, when first read), or the summary
  py::object summary = make_results ? py::object(maker_capsule(std::move(make_results)))
                                    : results ? results : json_to_python(captured.results);
  // the parameters as the run used them (computed defaults filled in), as its sidecar records them: made when
  // r.params is first read, from the set the run used (lent), unless the command recorded other values or the
  // command has lent as many sets as it lends
  ParamsRecord params;
  if (!captured.parameters.is_null()) params.json = std::move(captured.parameters);
  else if (!(params.lent = run_params.lend())) params.json = p.to_json();
  return typed_result(result_type, path, captured, std::move(summary), std::move(params));
}

}  // namespace

void bind_commands(py::module_& m) {
  m.def(
      "commands",
      [](bool program) {
        py::list out;
        for (const CommandSpec& s : program_specs()) {
          if (!program && !runnable(s.path)) continue;
          py::dict d;
          d["path"] = s.path;
          d["help"] = s.help;
          d["runnable"] = runnable(s.path);
          d["params"] = describe(s, runnable(s.path));
          out.append(d);
        }
        return out;
      },
      py::arg("program") = false,
      "The commands run() runs (program=True: every leaf command of the afmkit program), in registration order: "
      "path, help, runnable (run() runs it; else it is a Python program of the package the command line starts: "
      "report, study run, or writes a store: tapping grid) and parameters (key, kind, default, unit, allowed range, "
      "positional).");
  m.def(
      "require_memory",
      [](const std::string& parameter, double value, double bytes_per_unit) {
        memory::require_fits(parameter, value, bytes_per_unit);
      },
      py::arg("parameter"), py::arg("value"), py::arg("bytes_per_unit"),
      "InvalidParameter naming `parameter` when value x bytes_per_unit exceeds the memory afmkit may use (half of "
      "what is available, capped by AFMKIT_MEMORY_LIMIT), as the commands check their sizes.");
  m.def("run", &run, py::arg("path"), py::arg("kwargs"), py::arg("result_type"),
        "Runs one command with keyword arguments named as its TOML keys (None: not given); returns an instance of "
        "result_type (afmkit.Result), whose summary and parameter record are made when first read (made_summary, "
        "made_params).");
  m.def("made_params", &made_params, py::arg("params"),
        "The parameter record (a dict) of the capsule a Result made by run() holds until r.params is "
        "first read.");
  m.def("made_summary", &made_summary, py::arg("results"),
        "The summary document a Result's results capsule makes (run() of a command that makes its summary when read).");
}

}  // namespace afmkit::python
