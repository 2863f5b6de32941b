#pragma once
// Results whose numbers carry their units (the output edge of afmkit/core/units.hpp): each entry is declared once,
// with the Unit that converts the program's value and names the unit, and the sidecar's "units" object is built
// from the same declarations as the values, so that a value and its unit cannot drift apart.
//   UnitTagged orbit;
//   orbit.add("amplitude", m.amplitude, u.length)            // value * scale, unit "nm" (or "L")
//        .add("stable", o.stable, "boolean (0/1)")           // shown as computed, with its unit
//        .add("source", "hb_plus");                           // a label: no unit
//   summary["orbit"] = orbit.values();  units["orbit"] = orbit.units();
// A record that is one row of an array (whose units are listed once for all rows) is built without its units:
// UnitTagged row(UnitTagged::values_only) (the same declarations; add() then records no unit). Records used once
// are moved out (std::move(record).values(), add(key, std::move(nested)), std::move(record).summary()): a summary
// of hundreds of values is copied in as much time as a short computation takes (bench/command_layer.py).
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "afmkit/core/units.hpp"
#include "afmkit/io/quantity.hpp"

namespace afmkit::cli {

class UnitTagged {
 public:
  /// A record of values without units (a row of an array whose units are given once beside it).
  enum ValuesOnly { values_only };
  UnitTagged() = default;
  explicit UnitTagged(ValuesOnly) : with_units_(false) {}

  /// A number converted by `unit`.
  UnitTagged& add(std::string_view key, double value, const units::Unit& unit) {
    values_[key] = unit(value);
    if (with_units_) units_[key] = unit.name;
    return *this;
  }
  /// Numbers converted by `unit`, one JSON array.
  UnitTagged& add(std::string_view key, const std::vector<double>& values, const units::Unit& unit) {
    nlohmann::json a = nlohmann::json::array();
    for (double v : values) a.push_back(unit(v));
    values_[key] = std::move(a);
    if (with_units_) units_[key] = unit.name;
    return *this;
  }
  /// Named numbers converted by `unit`, one JSON object (a box's edges); one unit for all of them.
  UnitTagged& add(const std::string& key, const std::vector<std::pair<std::string, double>>& named,
                  const units::Unit& unit) {
    nlohmann::json o = nlohmann::json::object();
    for (const auto& [name, v] : named) o[name] = unit(v);
    values_[key] = std::move(o);
    units_[key] = unit.name;
    return *this;
  }
  /// A value shown as computed (counts, flags, rad, dimensionless numbers) and its unit.
  UnitTagged& add(std::string_view key, nlohmann::json value, const char* unit) {
    values_[key] = std::move(value);
    if (with_units_) units_[key] = unit;
    return *this;
  }
  /// The same with a unit named at run time (the unit of a swept parameter, "label").
  UnitTagged& add(const std::string& key, nlohmann::json value, const std::string& unit) {
    values_[key] = std::move(value);
    units_[key] = unit;
    return *this;
  }
  /// A value without a unit (a label, a text).
  UnitTagged& add(std::string_view key, nlohmann::json value) {
    values_[key] = std::move(value);
    return *this;
  }
  /// A nested record: its values and its units under `key`.
  UnitTagged& add(std::string_view key, const UnitTagged& nested) {
    values_[key] = nested.values_;
    if (with_units_) units_[key] = nested.units_;
    return *this;
  }
  UnitTagged& add(std::string_view key, UnitTagged&& nested) {
    values_[key] = std::move(nested.values_);
    if (with_units_) units_[key] = std::move(nested.units_);
    return *this;
  }
  /// Records of one kind under `key` (an array of their values), with the units of `prototype`: a record made by
  /// the same function (of a default value, so that it names every field and the units are there when the list is
  /// empty).
  UnitTagged& add(const std::string& key, const std::vector<UnitTagged>& records, const UnitTagged& prototype) {
    nlohmann::json a = nlohmann::json::array();
    for (const UnitTagged& r : records) a.push_back(r.values_);
    values_[key] = std::move(a);
    units_[key] = prototype.units_;
    return *this;
  }
  /// `other`'s entries (values and units) beside these.
  UnitTagged& merge(const UnitTagged& other) {
    for (const auto& [key, value] : other.values_.items()) values_[key] = value;
    return units_of(other);
  }
  /// The units of `other`'s entries without their values: the entries of a part this run did not compute (a mode
  /// or pass not run), declared by the code that writes them when it runs (the units list every key a command
  /// can write).
  UnitTagged& units_of(const UnitTagged& other) {
    for (const auto& [key, unit] : other.units_.items()) units_[key] = unit;
    return *this;
  }
  /// A unit without a value here (an entry whose values are listed elsewhere, e.g. in the rows of an array).
  UnitTagged& unit(std::string_view key, nlohmann::json unit) {
    if (with_units_) units_[key] = std::move(unit);
    return *this;
  }

  const nlohmann::json& values() const& { return values_; }
  /// The values with their units under "units" (a command's results).
  nlohmann::json with_units() const {
    nlohmann::json j = values_;
    j["units"] = units_;
    return j;
  }
  const nlohmann::json& units() const& { return units_; }
  nlohmann::json values() && { return std::move(values_); }
  nlohmann::json units() && { return std::move(units_); }
  /// A command's summary document: the values, with the units under "units".
  nlohmann::json summary() && {
    values_["units"] = std::move(units_);
    return std::move(values_);
  }

 private:
  nlohmann::json values_ = nlohmann::json::object();
  nlohmann::json units_ = nlohmann::json::object();
  bool with_units_ = true;
};

/// A length, time, force or energy of a summary line, converted by `unit` and printed in it (io::summary_value).
inline std::string summary_value(double value, const units::Unit& unit, int digits = 4) {
  return io::summary_value(unit(value), unit.name, digits);
}

}  // namespace afmkit::cli
