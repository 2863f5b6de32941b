#pragma once
// The one place where a force law is built from named parameters: every command (impact, tapping orbit | hb |
// sweep, demo), TOML configs and C++ users go through a LawRegistry. Parameters are in the physical units of
// docs/force-laws.md (gap nm, force nN, stiffness N/m, E* GPa, R nm, A_H J, γ J/m², η Pa·s, rate nm/s); for the
// piecewise-linear laws any consistent unit set works (the tapping model's normalised units included).
//
// Adding a law: one file defining a ForceLawModel, one `registry.add({...})` line (docs/force-laws.md).
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "afmkit/impact/force_law.hpp"

namespace afmkit::impact {

/// One named law parameter: its unit, default, allowed range and help text.
struct LawKey {
  std::string key;                  // e.g. "effective_modulus"
  std::string unit;                 // e.g. "GPa"; "" for dimensionless
  double default_value = 0.0;
  std::string help;
  double lower = -std::numeric_limits<double>::infinity();  // allowed range [lower, upper] (open if *_open)
  double upper = std::numeric_limits<double>::infinity();
  bool lower_open = false;
  std::string follows;              // when not given: the value of this key (e.g. departure_modulus -> effective_modulus)
  bool only_if_given = false;       // read only when given (e.g. restitution, an alternative to departure_stiffness)
  std::string replaces;             // when given, stands for this key (which must then not be given)
};

/// The values a user gave (anything not given takes the key's default or the key it follows).
struct LawArguments {
  std::map<std::string, double> values;
  std::string force_curve;          // file of a measured force curve (law = table)
  bool allow_energy_gain = false;   // accept laws that create energy (K_b > K_a, …)
  /// Branch selection (docs/force-laws.md#hysteresis): "" or "law" (the law's own: contact for table, velocity
  /// for the others), "contact" or "velocity" (law = table only; the other laws accept only their own).
  std::string hysteresis;
  /// law = python: the law object the caller gave (the Python module's afmkit.laws.Python; null elsewhere).
  std::shared_ptr<const ForceLawModel> model;

  /// A given value, else the default (or followed key) from `key`.
  double real(const LawKey& key, const std::vector<LawKey>& all) const;
  bool given(const std::string& key) const { return values.count(key) != 0; }
};

/// A law the registry can build.
struct LawSpec {
  std::string name;                 // as typed by users: --law NAME
  std::string summary;              // one line: formula family and seed equation
  std::vector<std::string> keys;    // parameters it reads (each declared in the registry's key table)
  bool needs_force_curve = false;   // reads LawArguments::force_curve
  bool piecewise_linear = false;    // works in any consistent unit set (else the physical units above)
  /// Builds the law; `value(key)` gives each parameter (given, default or followed), already range-checked.
  std::function<ForceLaw(const std::function<double(const std::string&)>& value, const LawArguments& args)> build;
  bool needs_object = false;        // reads LawArguments::model (law = python: only a program can give one)
};

class LawRegistry {
 public:
  /// The built-in laws: linear (10), hysteresis (11), attractive (26), hertz, dmt, jkr, lennard_jones,
  /// kelvin_voigt, table; and python (a law object written in Python, given by the Python module).
  static LawRegistry builtin();
  /// Adds a law (and the keys it introduces; a key already declared must be declared identically or omitted).
  /// InvalidParameter("law", …) for a duplicate name or a key that is neither new nor declared.
  void add(LawSpec spec, std::vector<LawKey> new_keys = {});

  /// The law `name` (InvalidParameter("law", "unknown law …; known: …") otherwise).
  const LawSpec& find(const std::string& name) const&;
  const LawSpec& find(const std::string& name) const&& = delete;  // would refer into a temporary
  std::vector<std::string> names() const;
  const std::vector<LawKey>& keys() const& { return keys_; }
  std::vector<LawKey> keys() const&& { return keys_; }
  /// The laws that read `key` (for help texts and error messages).
  std::vector<std::string> laws_using(const std::string& key) const;

  /// Builds law `name`: every given key must be one the law reads (else InvalidParameter naming the key and the
  /// laws that do read it) and inside its range (else InvalidParameter naming key and range).
  ForceLaw build(const std::string& name, const LawArguments& args) const;

 private:
  std::vector<LawSpec> laws_;
  std::vector<LawKey> keys_;
  const LawKey& key(const std::string& name) const;
};

}  // namespace afmkit::impact
