#pragma once
// Keyword arguments → the parameters of one command (io::ParamSet): the same keys, types, ranges and messages as
// the TOML file and the flags of the `afmkit` program.
#include <memory>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "afmkit/io/params.hpp"
#include "command.hpp"

namespace afmkit::python {

/// The commands Python runs: every leaf command of the program but `report` (from Python: afmkit.report.build).
const std::vector<cli::CommandSpec>& specs();

/// The leaf command `path` ("tapping orbit"); ValueError for an unknown one.
const cli::CommandSpec& command_spec(const std::string& path);

/// The parameters of `spec` with Python's defaults: no file written (output and every *_output ""), json on (nothing
/// printed). `json` is not a keyword from Python.
io::ParamSet python_params(const cli::CommandSpec& spec);

/// The parameters of command `path` with `kwargs` applied on top of the defaults (and of the TOML file given as
/// keyword `config`, as --config). `name` ("afmkit.tapping.orbit") prefixes TypeErrors (unexpected keyword, wrong
/// Python type); a value out of range raises afmkit.InvalidParameter with the command line's message. Keys in
/// `hidden` (and `json`) are refused like unknown ones (they mean nothing to this caller).
io::ParamSet params_from_python(const std::string& path, const std::string& name, const pybind11::dict& kwargs,
                                const std::vector<std::string>& hidden = {});

namespace detail {
struct Prototype;
}
class LentParams;
/// params_from_python's parameters for one run, in a set the command's runs reuse (its values reset: no copy of the
/// declarations per call); given back when this goes out of scope.
class RunParams {
 public:
  RunParams(const std::string& path, const std::string& name, const pybind11::dict& kwargs,
            const std::vector<std::string>& hidden = {});
  RunParams(const RunParams&) = delete;
  RunParams& operator=(const RunParams&) = delete;
  ~RunParams();
  const io::ParamSet& get() const& { return *params_; }

  /// The set, lent to the caller (a record made later from it: ParamSet::to_json) and given back to the command's
  /// spare sets by the LentParams' end; nullptr when the command has as many sets lent already as it lends
  /// (kLentSets: each Result of a loop that keeps many holds one until its r.params is read or it is freed), and
  /// the caller records the parameters now. get() stays valid while the LentParams lives.
  std::unique_ptr<LentParams> lend();

 private:
  void fill(const std::string& name, const pybind11::dict& kwargs, const std::vector<std::string>& hidden);
  const detail::Prototype* prototype_;
  std::unique_ptr<io::ParamSet> params_;
};

/// A run's parameter set lent by RunParams::lend: its record made when asked (once), the set given back then or at
/// the end of this object, whichever comes first. Call with the GIL held (the spare sets are the module's).
class LentParams {
 public:
  LentParams(const detail::Prototype* prototype, std::unique_ptr<io::ParamSet> params);
  LentParams(const LentParams&) = delete;
  LentParams& operator=(const LentParams&) = delete;
  ~LentParams();
  /// The parameters as run (ParamSet::to_json of the set), made on the first call; the set is given back then.
  const nlohmann::json& record();

 private:
  void give_back();
  const detail::Prototype* prototype_;
  std::unique_ptr<io::ParamSet> params_;
  nlohmann::json record_;
};

}  // namespace afmkit::python
