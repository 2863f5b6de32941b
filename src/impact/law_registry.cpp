// The registry of force laws: built-in laws, their parameters and units (docs/force-laws.md).
#include "afmkit/impact/law_registry.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "afmkit/core/numbers.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"
#include "afmkit/impact/laws/table_law.hpp"

namespace afmkit::impact {

namespace {
using afmkit::numbers::infinity;

LawKey positive(std::string key, std::string unit, double def, std::string help, std::string follows = {}) {
  return {std::move(key), std::move(unit), def, std::move(help), 0.0, infinity, true, std::move(follows), false, ""};
}
LawKey non_negative(std::string key, std::string unit, double def, std::string help, std::string follows = {}) {
  return {std::move(key), std::move(unit), def, std::move(help), 0.0, infinity, false, std::move(follows), false, ""};
}

std::string range_text(const LawKey& k) {
  if (k.upper == infinity) return fmt::format("{} {}", k.lower_open ? ">" : ">=", k.lower);
  return fmt::format("in {}{}, {}]", k.lower_open ? "(" : "[", k.lower, k.upper);
}

std::vector<LawKey> builtin_keys() {
  return {
      non_negative("approach_stiffness", "N/m", 10.0, "K_a, contact stiffness while approaching"),
      non_negative("departure_stiffness", "N/m", 8.0, "K_b, contact stiffness while departing"),
      LawKey{"restitution", "", 1.0,
             "if given: K_b = e^2 K_a for the restitution e in (0, 1] of an impulsive impact (e > 1 needs "
             "allow_energy_gain); instead of departure_stiffness",
             0.0, infinity, true, "", true, "departure_stiffness"},
      non_negative("approach_adhesion", "nN", 0.0, "F_a, attraction at the contact edge while approaching"),
      non_negative("departure_adhesion", "nN", 0.0, "F_b >= F_a, attraction at the contact edge while departing"),
      positive("effective_modulus", "GPa", 1.0, "effective modulus E* (while approaching)"),
      positive("departure_modulus", "GPa", 1.0, "E* while departing", "effective_modulus"),
      positive("tip_radius", "nm", 10.0, "tip radius R"),
      non_negative("hamaker", "J", 6.4e-20, "Hamaker constant A_H (while approaching)"),
      non_negative("departure_hamaker", "J", 6.4e-20, "A_H while departing", "hamaker"),
      positive("intermolecular_distance", "nm", 0.165, "intermolecular distance a0 (contact gap)"),
      non_negative("adhesion_energy", "J/m^2", 0.1, "adhesion energy γ: pull-off force (3/2)πγR on retract"),
      non_negative("viscosity", "Pa*s", 100.0, "sample viscosity η: damping η √(R(a0 − d)) in contact"),
      non_negative("release_tolerance", "nN", 0.0,
                   "with hysteresis = contact: a difference of the branches up to this counts as none when placing "
                   "the release gap (drag, baseline offset or noise above the pull-off); 0: 1e-9 of the largest "
                   "force"),
  };
}
}  // namespace

double LawArguments::real(const LawKey& key, const std::vector<LawKey>& all) const {
  if (const auto it = values.find(key.key); it != values.end()) return it->second;
  if (!key.follows.empty()) {
    const auto f = std::find_if(all.begin(), all.end(), [&](const LawKey& k) { return k.key == key.follows; });
    if (f != all.end()) return real(*f, all);
  }
  return key.default_value;
}

LawRegistry LawRegistry::builtin() {
  LawRegistry r;
  r.keys_ = builtin_keys();
  using V = std::function<double(const std::string&)>;
  const auto gain = [](const LawArguments& a) { return a.allow_energy_gain; };
  const auto departure_stiffness = [](const V& v, const LawArguments& a) {
    if (a.given("restitution") && a.given("departure_stiffness"))
      throw InvalidParameter("restitution", "give either restitution or departure_stiffness, not both");
    return a.given("restitution") ? PiecewiseLinearLaw::departure_stiffness_for_restitution(
                                        v("approach_stiffness"), v("restitution"), a.allow_energy_gain)
                                  : v("departure_stiffness");
  };
  r.add({"linear", "linear repulsion H = -K_a d in contact (seed-1 eq. 10)", {"approach_stiffness"}, false, true,
         [=](const V& v, const LawArguments& a) {
           return ForceLaw(PiecewiseLinearLaw(v("approach_stiffness"), v("approach_stiffness"), 0, 0, gain(a)));
         }});
  r.add({"hysteresis", "linear hysteresis K_a / K_b (seed-1 eq. 11)",
         {"approach_stiffness", "departure_stiffness", "restitution"}, false, true,
         [=](const V& v, const LawArguments& a) {
           return ForceLaw(PiecewiseLinearLaw(v("approach_stiffness"), departure_stiffness(v, a), 0, 0, gain(a)));
         }});
  r.add({"attractive", "repulsive-attractive hysteresis K_a, K_b, F_a, F_b (seed-1 eq. 26)",
         {"approach_stiffness", "departure_stiffness", "restitution", "approach_adhesion", "departure_adhesion"}, false,
         true, [=](const V& v, const LawArguments& a) {
           return ForceLaw(PiecewiseLinearLaw(v("approach_stiffness"), departure_stiffness(v, a),
                                              v("approach_adhesion"), v("departure_adhesion"), gain(a)));
         }});
  r.add({"hertz", "Hertz contact (4/3)E*√R δ^{3/2}, no attraction", {"effective_modulus", "departure_modulus", "tip_radius"},
         false, false, [=](const V& v, const LawArguments& a) {
           return make_law<HertzLaw>(v("effective_modulus"), v("departure_modulus"), v("tip_radius"), gain(a));
         }});
  r.add({"dmt", "DMT contact with van der Waals attraction",
         {"effective_modulus", "departure_modulus", "tip_radius", "hamaker", "departure_hamaker",
          "intermolecular_distance"},
         false, false, [=](const V& v, const LawArguments& a) {
           return ForceLaw(DmtLaw(v("effective_modulus"), v("departure_modulus"), v("tip_radius"), v("hamaker"),
                                  v("departure_hamaker"), v("intermolecular_distance"), gain(a)));
         }});
  r.add({"jkr", "JKR-like adhesion hysteresis: DMT approach, retract from contact with pull-off (3/2)πγR",
         {"effective_modulus", "tip_radius", "hamaker", "intermolecular_distance", "adhesion_energy"},
         false, false, [=](const V& v, const LawArguments& a) {
           return make_law<AdhesionHysteresisLaw>(v("effective_modulus"), v("tip_radius"), v("hamaker"),
                                                  v("intermolecular_distance"), v("adhesion_energy"), gain(a));
         }});
  r.add({"lennard_jones", "Lennard-Jones sphere-plane (A_H R/6)(a0^6/d^8 - 1/d^2)",
         {"tip_radius", "hamaker", "intermolecular_distance"}, false, false, [](const V& v, const LawArguments&) {
           return make_law<LennardJonesLaw>(v("tip_radius"), v("hamaker"), v("intermolecular_distance"));
         }});
  r.add({"kelvin_voigt", "Kelvin-Voigt viscoelastic DMT contact (damping η √(R δ))",
         {"effective_modulus", "tip_radius", "hamaker", "intermolecular_distance", "viscosity"}, false, false,
         [](const V& v, const LawArguments&) {
           return make_law<KelvinVoigtLaw>(v("effective_modulus"), v("tip_radius"), v("hamaker"),
                                           v("intermolecular_distance"), v("viscosity"));
         }});
  r.add({"table", "measured force curve: approach and retract tables (--force-curve FILE), monotone interpolation",
         {"release_tolerance"}, true, false, [=](const V& v, const LawArguments& a) {
           const bool velocity = a.hysteresis == "velocity";
           if (velocity && v("release_tolerance") > 0.0)  // (commands pass the default 0 of every key a law reads)
             throw InvalidParameter("release_tolerance", "release_tolerance applies only to hysteresis = contact "
                                                         "(this run: hysteresis = velocity)");
           return make_law<TableLaw>(read_force_curve(a.force_curve), gain(a),
                                     velocity ? Hysteresis::velocity : Hysteresis::contact, v("release_tolerance"));
         }});
  LawSpec python{"python",
                 "a law written in Python: afmkit.laws.Python(approach=f, departure=g, damping=c), given from the "
                 "Python module",
                 {}, false, false, [](const V&, const LawArguments& a) {
                   if (!a.model)
                     throw InvalidParameter("law", "law = python is a force law written in Python: give it from the "
                                                   "Python module as law=afmkit.laws.Python(approach=..., ...) (a "
                                                   "command line or TOML file cannot hold one; docs/force-laws.md#python)");
                   return ForceLaw(a.model);
                 }};
  python.needs_object = true;
  r.add(std::move(python));
  return r;
}

void LawRegistry::add(LawSpec spec, std::vector<LawKey> new_keys) {
  if (spec.name.empty() || !spec.build) throw InvalidParameter("law", "a law needs a name and a build function");
  if (std::any_of(laws_.begin(), laws_.end(), [&](const LawSpec& s) { return s.name == spec.name; }))
    throw InvalidParameter("law", fmt::format("a law named '{}' is already registered", spec.name));
  for (auto& k : new_keys) {
    const auto it = std::find_if(keys_.begin(), keys_.end(), [&](const LawKey& e) { return e.key == k.key; });
    if (it == keys_.end()) {
      keys_.push_back(std::move(k));
    } else if (it->unit != k.unit || it->default_value != k.default_value) {
      throw InvalidParameter("law", fmt::format("law '{}' redeclares parameter '{}' with another unit or default "
                                                "({} {} vs {} {})",
                                                spec.name, k.key, k.default_value, k.unit, it->default_value, it->unit));
    }
  }
  for (const auto& k : spec.keys) key(k);  // every key the law reads must be declared
  laws_.push_back(std::move(spec));
}

const LawKey& LawRegistry::key(const std::string& name) const {
  const auto it = std::find_if(keys_.begin(), keys_.end(), [&](const LawKey& k) { return k.key == name; });
  if (it == keys_.end()) throw InvalidParameter("law", fmt::format("law parameter '{}' is not declared", name));
  return *it;
}

const LawSpec& LawRegistry::find(const std::string& name) const& {
  const auto it = std::find_if(laws_.begin(), laws_.end(), [&](const LawSpec& s) { return s.name == name; });
  if (it == laws_.end())
    throw InvalidParameter("law", fmt::format("unknown law '{}'; known laws: {}", name, fmt::join(names(), ", ")));
  return *it;
}

std::vector<std::string> LawRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& s : laws_) out.push_back(s.name);
  return out;
}

std::vector<std::string> LawRegistry::laws_using(const std::string& key) const {
  std::vector<std::string> out;
  for (const auto& s : laws_)
    if (std::find(s.keys.begin(), s.keys.end(), key) != s.keys.end()) out.push_back(s.name);
  return out;
}

ForceLaw LawRegistry::build(const std::string& name, const LawArguments& args) const {
  const LawSpec& spec = find(name);
  for (const auto& [k, value] : args.values) {
    if (std::find(spec.keys.begin(), spec.keys.end(), k) == spec.keys.end()) {
      const auto users = laws_using(k);
      throw InvalidParameter(k, users.empty()
                                    ? fmt::format("'{}' is not a force-law parameter", k)
                                    : fmt::format("{} does not apply to law = {} (it is a parameter of law {})", k,
                                                  name, fmt::join(users, ", ")));
    }
    const LawKey& d = key(k);
    const bool ok = std::isfinite(value) && (d.lower_open ? value > d.lower : value >= d.lower) && value <= d.upper;
    if (!ok)
      throw InvalidParameter(k, fmt::format("{} = {} is out of range: must be {} {}", k, value, range_text(d), d.unit));
  }
  if (spec.needs_force_curve && args.force_curve.empty())
    throw InvalidParameter("force_curve", fmt::format("law = {} needs a force-curve file (force_curve = FILE)", name));
  if (!spec.needs_force_curve && !args.force_curve.empty())
    throw InvalidParameter("force_curve", fmt::format("force_curve applies only to law = table (this run: law = {})",
                                                      name));
  if (!args.hysteresis.empty() && args.hysteresis != "law" && args.hysteresis != "contact" &&
      args.hysteresis != "velocity")
    throw InvalidParameter("hysteresis", fmt::format("hysteresis = '{}' is not one of law, contact, velocity",
                                                     args.hysteresis));
  const auto value = [&](const std::string& k) { return args.real(key(k), keys_); };
  ForceLaw law = spec.build(value, args);
  if (!args.hysteresis.empty() && args.hysteresis != "law" && args.hysteresis != hysteresis_name(law.hysteresis()))
    throw InvalidParameter("hysteresis",
                           fmt::format("hysteresis = {} applies only to law = table; law = {} switches its branches "
                                       "by the {} rule (docs/force-laws.md#hysteresis)",
                                       args.hysteresis, name,
                                       law.hysteresis() == Hysteresis::velocity ? "velocity-sign (seed-1 eq. 4)"
                                                                                : "contact"));
  // every command alike: a law that creates energy (K_b > K_a, E*_b > E*_a, …) only with allow_energy_gain
  law.require_dissipative();
  return law;
}

}  // namespace afmkit::impact
