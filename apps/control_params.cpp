#include "control_params.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/core/units.hpp"
#include "afmkit/io/quantity.hpp"
#include "unit_tagged.hpp"
#include "work_budget.hpp"

namespace afmkit::cli {

using io::Range;

void add_coupling_alpha(io::ParamSet& p) { p.real("alpha", 0.1, "coupling alpha of eq. (20)").unit("Omega"); }

void add_coupling_beta(io::ParamSet& p) { p.real("beta", -0.1, "coupling beta of eq. (20)").unit("Omega"); }

void add_harmonics_param(io::ParamSet& p, long max_harmonics, const std::string& help) {
  p.integer("harmonics", 10, help, 1, max_harmonics);
}

void add_threads_param(io::ParamSet& p) { p.integer("threads", 0, "OpenMP threads (0: default)", 0, 1024); }

void add_progress_flag(io::ParamSet& p) { p.flag("progress", true, "show progress on stderr"); }

void add_control_params(io::ParamSet& p, long max_harmonics) {
  p.group("Controller");
  p.text("controller", "bank", "controller: single oscillator (eqs. 5-6), bank of N oscillators (eq. 15), "
                               "infinite bank (eq. 31) or Smith predictor around a bank",
         {"single", "bank", "infinite", "smith"})
      .real("rotation_frequency", 1.0, "rotation angular frequency Omega; rates below are in units of Omega, delays "
                                       "in units of T = 2 pi/Omega", Range{0.0, 1e12, true, false})
      .unit("rad/s");
  add_si_alternative(p, "rotation_frequency", SiUnit::Hz, Range::positive());
  add_harmonics_param(p, max_harmonics,
                      max_harmonics == kMaxHarmonicsTf
                          ? "number N of oscillators of the bank (eq. 15); cost O(N) per frequency"
                          : "number N of oscillators of the bank (eq. 15); cost O(N) per characteristic evaluation, "
                            "O(N^2) per spectrum / per simulated period");
  add_coupling_alpha(p);
  add_si_alternative(p, "alpha");
  add_coupling_beta(p);
  add_si_alternative(p, "beta");
  p.real("a", 0.5, "coupling a of the single oscillator (eq. 5)").unit("Omega");
  add_si_alternative(p, "a");
  p.real("b", 0.0, "coupling b of the single oscillator (eq. 5)").unit("Omega");
  add_si_alternative(p, "b");
  p.reals("rejected", {1.0}, "harmonic numbers removed from the output (bank controller), e.g. 1,3",
          Range::closed(1, static_cast<double>(max_harmonics)))
      .unit("count")
      .real("gain", 20.0, "controller gain K (design rule K = gamma)", Range{0.0, 1e12, true, false})
      .unit("Omega")
      .default_text("= plant_rate");
  add_si_alternative(p, "gain", SiUnit::Auto, Range::positive());
  p.group("Plant and delay")
      .text("plant", "static", "plant: static y = f + u/gamma (eq. 3) or first order (eq. 1)", {"static", "first_order"})
      .real("plant_rate", 20.0, "plant rate gamma", Range{0.0, 1e12, true, false})
      .unit("Omega");
  add_si_alternative(p, "plant_rate", SiUnit::Auto, Range::positive());
  p.real("delay", 0.1, "measurement delay tau", Range::non_negative()).unit("T");
  add_si_alternative(p, "delay", SiUnit::Auto, Range::non_negative());
  p.group("Smith predictor")
      .text("smith_bank", "bank", "controller inside the Smith predictor", {"bank", "infinite", "single"})
      .text("smith_structure", "periodic", "Smith predictor structure (periodic keeps exact rejection)",
            {"periodic", "classic"})
      .text("model_plant", "same", "kind of the Smith predictor's plant model", {"same", "static", "first_order"})
      .real("model_rate", 20.0, "Smith model rate gamma_hat", Range{0.0, 1e12, true, false})
      .unit("Omega")
      .default_text("= plant_rate");
  add_si_alternative(p, "model_rate", SiUnit::Auto, Range::positive());
  p.real("model_delay", 0.1, "Smith model delay tau_hat", Range::non_negative()).unit("T").default_text("= delay");
  add_si_alternative(p, "model_delay", SiUnit::Auto, Range::non_negative());
  // The records list the keys of the controller in use only (docs/commands.md#recorded-parameters): the Smith
  // predictor's keys with controller = smith; a, b for the single oscillator; alpha, beta for a bank (finite or
  // infinite); rejected for a finite bank — of the inner controller (smith_bank) when controller = smith.
  for (const char* key : {"smith_bank", "smith_structure", "model_plant", "model_rate", "model_delay"})
    p.applies_when(key, "controller", {"smith"});
  const auto in_use = [](std::vector<std::string> kinds) {
    return [kinds = std::move(kinds)](const io::ParamSet& q) {
      const std::string& c = q.text("controller");
      const std::string& inner = c == "smith" ? q.text("smith_bank") : c;
      return std::find(kinds.begin(), kinds.end(), inner) != kinds.end();
    };
  };
  for (const char* key : {"a", "b"}) p.applies_if(key, in_use({"single"}));
  for (const char* key : {"alpha", "beta"}) p.applies_if(key, in_use({"bank", "infinite"}));
  p.applies_if("rejected", in_use({"bank"}));
}

namespace {
// The SI form of a key in the rotation units (docs/units.md): suffix and unit of the alternative.
struct SiForm {
  const char* suffix;
  const char* unit;
};
SiForm si_form(const std::string& base_unit, SiUnit unit) {
  if (unit == SiUnit::Hz) return {"_hz", "Hz"};
  if (base_unit == control::RotationUnits::delay_unit) return {"_seconds", "s"};
  return {"_rad_per_s", "rad/s"};
}
constexpr const char* kSiSuffixes[] = {"_hz", "_rad_per_s", "_seconds"};
}  // namespace

void add_si_alternative(io::ParamSet& p, const std::string& key, SiUnit unit, Range range) {
  const auto all = p.describe();
  const auto it = std::find_if(all.begin(), all.end(), [&](const auto& d) { return d.key == key; });
  if (it == all.end()) throw std::logic_error("add_si_alternative: '" + key + "' is not declared");
  const io::ParamSet::Description& d = *it;
  const bool rotation = d.unit == control::RotationUnits::si_rate_unit;  // Omega itself, in rad/s
  if (!rotation && d.unit != control::RotationUnits::rate_unit && d.unit != control::RotationUnits::delay_unit)
    throw std::logic_error("add_si_alternative: '" + key + "' is not in units of Omega or T");
  if (rotation && unit != SiUnit::Hz) throw std::logic_error("add_si_alternative: rotation_frequency has Hz only");
  const SiForm form = si_form(d.unit, unit);
  const std::string si_key = key + form.suffix;
  const std::string conversion =
      rotation ? fmt::format("{} = 2 pi x {}", key, si_key)
      : unit == SiUnit::Hz ? fmt::format("{} = 2 pi x {} / Omega", key, si_key)
      : d.unit == control::RotationUnits::delay_unit ? fmt::format("{} = {} / T", key, si_key)
                                                      : fmt::format("{} = {} / Omega", key, si_key);
  const std::string help = fmt::format("{} in {} instead of units of {}: {} (give one of the two)", key, form.unit,
                                       rotation ? "rad/s" : d.unit, conversion);
  if (d.kind == "reals")
    p.reals(si_key, {}, help, range);
  else
    p.real(si_key, 1.0, help, range);  // the default is never used (counted only when given)
  p.unit(form.unit).default_text("not given").only_if_given({key});
}

io::ParamSet resolve_si_inputs(const io::ParamSet& given) {
  io::ParamSet p = given;
  // base key -> its SI alternatives declared in `p` (add_si_alternative), rotation_frequency first
  std::vector<std::pair<std::string, std::vector<std::string>>> pairs;
  std::map<std::string, std::string> unit_of;
  const auto all = p.describe();
  for (const auto& d : all) unit_of[d.key] = d.unit;
  for (const auto& d : all)
    for (const char* suffix : kSiSuffixes) {
      const std::string s(suffix);
      if (d.key.size() <= s.size() || d.key.compare(d.key.size() - s.size(), s.size(), s) != 0) continue;
      const std::string base = d.key.substr(0, d.key.size() - s.size());
      if (!unit_of.count(base)) continue;
      auto at = std::find_if(pairs.begin(), pairs.end(), [&](const auto& x) { return x.first == base; });
      if (at == pairs.end()) {
        pairs.push_back({base, {}});
        at = pairs.end() - 1;
      }
      at->second.push_back(d.key);
    }
  std::stable_partition(pairs.begin(), pairs.end(), [](const auto& x) { return x.first == "rotation_frequency"; });
  for (const auto& [base, alternatives] : pairs) {
    std::vector<std::string> set;
    if (p.was_set(base)) set.push_back(base);
    for (const auto& a : alternatives)
      if (p.was_set(a)) set.push_back(a);
    if (set.size() > 1)
      throw InvalidParameter(set[1], fmt::format("{} and {} were both given: they are the same quantity in different "
                                                 "units ({} in {}, {} in {}); give one of them",
                                                 set[0], set[1], set[0], unit_of.at(set[0]), set[1], unit_of.at(set[1])));
    if (set.empty() || set[0] == base) continue;
    const std::string& si_key = set[0];
    const std::string& si_unit = unit_of.at(si_key);
    const std::string& base_unit = unit_of.at(base);
    // Omega is resolved first; the others convert with it (RotationUnits: the same products as control::to_si)
    const auto convert = [&](double v) {
      if (base_unit == control::RotationUnits::si_rate_unit) return 2.0 * std::numbers::pi * v;  // Hz -> rad/s
      const control::RotationUnits u(p.real("rotation_frequency"));
      if (base_unit == control::RotationUnits::delay_unit) return u.in_periods(v);
      return u.in_omega(si_unit == "Hz" ? 2.0 * std::numbers::pi * v : v);
    };
    try {
      if (std::holds_alternative<std::vector<double>>(p.value(si_key))) {
        std::vector<double> values = p.reals(si_key);
        for (double& v : values) v = convert(v);
        p.set_value(base, values);
      } else {
        p.set_value(base, convert(p.real(si_key)));
      }
    } catch (const InvalidParameter& e) {
      if (e.parameter() != base) throw;
      throw InvalidParameter(si_key, fmt::format("{} = {} {} is out of range: converted to {} ({}): {}", si_key,
                                                 std::holds_alternative<std::vector<double>>(p.value(si_key))
                                                     ? fmt::format("[{}]", fmt::join(p.reals(si_key), ", "))
                                                     : fmt::format("{}", p.real(si_key)),
                                                 si_unit, base, base_unit, e.what()));
    }
  }
  return p;
}

namespace {
// Time of one closed-loop spectrum per oscillator (N + 1) per period T of delay: measured 1.8e-4 … 4.5e-4 s (roots
// and chart, N = 10 … 100, delays 100 … 3000 T, 2-core test machine under load, Release; it grows faster than the
// delay), taken as 1e-5 s: the estimate is a lower bound, so only requests that cannot fit are refused.
constexpr double kSpectrumSecondsPerPeriod = 1e-5;
}  // namespace

void require_delay_work(const io::ParamSet& p, const std::string& key, double delay_in_periods,
                        const control::RotationUnits& units, double spectra, int harmonics, const std::string& what) {
  // up to one period the spectra cost what the grid and N make them (their own checks); beyond it, the delay's share
  if (!(delay_in_periods > 1.0)) return;
  const double per_period = spectra * (harmonics + 1.0) * kSpectrumSecondsPerPeriod;
  const std::string model = fmt::format("{:g} closed-loop spectra ({}) with harmonics = {}, each at least {:.2g} s per "
                                        "period T of delay (the roots in the search box grow with the delay)",
                                        spectra, what, harmonics, (harmonics + 1.0) * kSpectrumSecondsPerPeriod);
  if (p.was_set(key + "_seconds"))  // the user's key and unit
    require_work(key + "_seconds", units.delay(delay_in_periods), per_period / units.period(), model);
  else
    require_work(key, delay_in_periods, per_period, model);
}

namespace {
// The SI key given for `key` (its _seconds, _rad_per_s or _hz form), or "".
std::string si_key_given(const io::ParamSet& p, const std::string& key) {
  for (const char* suffix : kSiSuffixes)
    for (const auto& d : p.describe())
      if (d.key == key + suffix && p.was_set(d.key)) return d.key;
  return "";
}

std::string value_text(const io::ParamSet& p, const std::string& key) {
  if (std::holds_alternative<std::vector<double>>(p.value(key))) return fmt::format("[{}]", fmt::join(p.reals(key), ", "));
  return fmt::format("{}", p.real(key));
}
}  // namespace

Run with_si_inputs(Run run) {
  return [run = std::move(run)](const io::ParamSet& p, Captured* capture) {
    const io::ParamSet resolved = resolve_si_inputs(p);
    try {
      run(resolved, capture);
    } catch (const InvalidParameter& e) {
      // a check of the key, given in its SI form: the message names the key the user gave
      const std::string si = si_key_given(p, e.parameter());
      if (si.empty()) throw;
      throw InvalidParameter(si, fmt::format("{} = {} {} (that is {} = {} {}): {}", si, value_text(p, si), p.unit_of(si),
                                             e.parameter(), value_text(resolved, e.parameter()),
                                             resolved.unit_of(e.parameter()), e.what()));
    }
  };
}

void require_memory(const std::string& parameter, double value, double bytes_per_unit) {
  memory::require_fits(parameter, value, bytes_per_unit);
}

control::ControlSettings control_settings_from(const io::ParamSet& p) {
  control::ControlSettings c;
  c.controller = control::controller_kind_from(p.text("controller"));
  c.rotation_frequency = p.real("rotation_frequency");
  c.harmonics = static_cast<int>(p.integer("harmonics"));
  c.alpha = p.real("alpha");
  c.beta = p.real("beta");
  c.a = p.real("a");
  c.b = p.real("b");
  c.rejected.clear();
  for (double r : p.reals("rejected")) {
    if (r != std::floor(r))
      throw InvalidParameter("rejected", fmt::format("rejected contains {}: every entry must be an integer "
                                                     "harmonic number in [1, harmonics]", r));
    c.rejected.push_back(static_cast<int>(r));
  }
  if (p.was_set("gain")) c.gain = p.real("gain");
  c.plant = control::plant_kind_from(p.text("plant"));
  c.plant_rate = p.real("plant_rate");
  c.delay = p.real("delay");
  c.smith_bank = control::controller_kind_from(p.text("smith_bank"), "smith_bank");
  c.smith_structure = p.text("smith_structure") == "classic" ? control::SmithPredictor::Structure::Classic
                                                             : control::SmithPredictor::Structure::Periodic;
  if (p.text("model_plant") != "same") c.model_plant = control::plant_kind_from(p.text("model_plant"), "model_plant");
  if (p.was_set("model_rate")) c.model_rate = p.real("model_rate");
  if (p.was_set("model_delay")) c.model_delay = p.real("model_delay");
  c.validate();
  return c;
}

namespace {
// The resolved settings, each number with its unit: rates (alpha, beta, a, b, gain, plant_rate, model_rate) in
// `rate`, delays in `delay` (Omega and T as given, or rad/s and s: value x rate.multiply); labels without a unit.
UnitTagged settings_record(const control::ControlSettings& c, const units::Unit& rate, const units::Unit& delay) {
  UnitTagged j;
  j.add("controller", control::to_string(c.controller))
      .add("rotation_frequency", c.rotation_frequency, "rad/s")
      .add("harmonics", c.harmonics, "count")
      .add("alpha", c.alpha, rate)
      .add("beta", c.beta, rate)
      .add("a", c.a, rate)
      .add("b", c.b, rate)
      .add("rejected", c.rejected, "count")
      .add("gain", c.gain_value(), rate)
      .add("plant", control::to_string(c.plant))
      .add("plant_rate", c.plant_rate, rate)
      .add("delay", c.delay, delay);
  if (c.controller == control::ControllerKind::Smith)
    j.add("smith_bank", control::to_string(c.smith_bank))
        .add("smith_structure", control::to_string(c.smith_structure))
        .add("model_plant", control::to_string(c.model_plant_value()))
        .add("model_rate", c.model_rate_value(), rate)
        .add("model_delay", c.model_delay_value(), delay);
  return j;
}
}  // namespace

nlohmann::json settings_json(const control::ControlSettings& c) {
  return settings_record(c, units::as_is(control::RotationUnits::rate_unit),
                         units::as_is(control::RotationUnits::delay_unit))
      .with_units();
}

nlohmann::json settings_si_json(const control::ControlSettings& c) {
  const control::RotationUnits u = c.units();
  UnitTagged j = settings_record(c, {control::RotationUnits::si_rate_unit, u.rotation_frequency(), 1.0},
                                 {control::RotationUnits::si_delay_unit, u.period(), 1.0});
  j.add("period", u.period(), control::RotationUnits::si_delay_unit);
  return j.with_units();
}

io::ParamSet params_as_run(const io::ParamSet& p, const control::ControlSettings& c,
                           const std::vector<std::pair<std::string, double>>& values) {
  io::ParamSet run = p;
  run.set_from_string("gain", fmt::format("{}", c.gain_value()));
  run.set_from_string("model_rate", fmt::format("{}", c.model_rate_value()));
  run.set_from_string("model_delay", fmt::format("{}", c.model_delay_value()));
  for (const auto& [key, value] : values) run.set_from_string(key, fmt::format("{}", value));
  return run;
}

std::string rate_summary(double rad_per_s, const control::RotationUnits& units, int digits) {
  return io::normalised(units.in_omega(rad_per_s), control::RotationUnits::rate_unit, digits,
                        fmt::format("{:.{}g} rad/s", rad_per_s, digits));
}

std::string delay_summary(double seconds, const control::RotationUnits& units, int digits) {
  return io::normalised(units.in_periods(seconds), control::RotationUnits::delay_unit, digits,
                        io::quantity(seconds, "s", digits));
}

}  // namespace afmkit::cli
