// afmkit tapping sweep: separation sweeps of periodic orbits — as an instrument does (approach then retract,
// each orbit continued from the previous one, transients where a branch ends: jumps and hysteresis) and/or by
// pseudo-arclength continuation through folds (unstable branches included). HB value beside each point.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/number_list.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/tapping/continuation.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "tapping_params.hpp"
#include "tapping_sim_params.hpp"
#include "tapping_sweep_parameter.hpp"
#include "tapping_tables.hpp"
#include "work_budget.hpp"

namespace afmkit::cli {

namespace {

nlohmann::json scaled(const std::vector<double>& v, const units::Unit& u) {
  nlohmann::json j = nlohmann::json::array();
  for (double x : v) j.push_back(u(x));
  return j;
}
std::vector<double> scaled_values(std::vector<double> v, const units::Unit& u) {
  for (double& x : v) x = u(x);
  return v;
}

/// "contact" when the orbit spends part of its period below the law's contact gap, else "free".
const char* branch_of(const tapping::OrbitMetrics& m) { return m.contact_fraction > 0.0 ? "contact" : "free"; }

/// Records sorted by separation (ties: in the order given).
nlohmann::json sorted_by_separation(nlohmann::json records) {
  std::stable_sort(records.begin(), records.end(), [](const nlohmann::json& a, const nlohmann::json& b) {
    return a["separation"].get<double>() < b["separation"].get<double>();
  });
  return records;
}

/// The instrument sweep's jumps as records, sorted by separation.
nlohmann::json jump_records(const std::vector<tapping::SweepJump>& jumps, const TappingUnits& u) {
  nlohmann::json out = nlohmann::json::array();
  for (const tapping::SweepJump& j : jumps)
    out.push_back({{"separation", u.length(j.separation)},
                   {"tolerance", u.length(j.tolerance)},
                   {"direction", tapping::direction_name(j.direction)},
                   {"located", j.located},
                   {"branch", branch_of(j.from_metrics)},
                   {"amplitude_before", u.length(j.from_metrics.amplitude)},
                   {"amplitude_after", u.length(j.to_metrics.amplitude)},
                   {"landed_periodic", j.landed_periodic}});
  return sorted_by_separation(std::move(out));
}

/// The continuation's folds as records (as `tapping hb` reports its folds), sorted by separation.
nlohmann::json fold_records(const tapping::ContinuationResult& c, const TappingUnits& u) {
  nlohmann::json out = nlohmann::json::array();
  for (const tapping::ContinuationFold& f : c.folds) {
    const tapping::OrbitMetrics& m = c.points.at(f.point).metrics;
    out.push_back({{"separation", u.length(f.separation)},
                   {"amplitude", u.length(m.amplitude)},
                   {"offset", u.length(m.offset)},
                   {"phase", m.phase},
                   {"branch", branch_of(m)},
                   {"kind", f.separation_maximum ? "maximum" : "minimum"}});
  }
  return sorted_by_separation(std::move(out));
}

/// The units: by dimension, and per results key (the units of study outputs, docs/study.md#outputs).
nlohmann::json sweep_units(const TappingUnits& u) {
  const std::string& L = u.length.name;
  return {{"length", L},
          {"energy", u.energy.name},
          {"force", u.force.name},
          {"approach_jumps", L},
          {"retract_jumps", L},
          {"jump_tolerance", L},
          {"jumps", {{"separation", L}, {"tolerance", L}, {"direction", "label"}, {"located", "boolean (0/1)"},
                     {"branch", "label"}, {"amplitude_before", L}, {"amplitude_after", L},
                     {"landed_periodic", "boolean (0/1)"}}},
          {"folds", {{"separation", L}, {"amplitude", L}, {"offset", L}, {"phase", "rad"}, {"branch", "label"},
                     {"kind", "label"}}},
          {"grazing", L},
          {"continuation_points", "count"},
          {"free_amplitude", L},
          {"trapped_rows", "count"},
          {"rows", "count"}};
}

/// The separations of the instrument sweep (model units): the explicit list (`separations` or `separations_file`)
/// when one is given, else `points` equally spaced in [separation_min, separation_max].
std::vector<double> sweep_separations(const io::ParamSet& p, const units::Unit& length) {
  if (p.was_set("separations") && p.was_set("separations_file"))
    throw InvalidParameter("separations", "give either separations or separations_file, not both");
  std::vector<double> list;
  if (p.was_set("separations")) list = p.reals("separations");
  else if (p.was_set("separations_file")) list = io::read_number_list(p.text("separations_file"), "separations_file");
  else return {};
  const char* key = p.was_set("separations") ? "separations" : "separations_file";
  for (double& l : list) {
    if (!(std::abs(l) <= 1e6))
      throw InvalidParameter(key, fmt::format("{} contains {}: every separation must be in [-1e+06, 1e+06]", key, l));
    l = length.internal(l);
  }
  std::sort(list.begin(), list.end());
  list.erase(std::unique(list.begin(), list.end()), list.end());
  if (list.size() < 2)
    throw InvalidParameter(key, fmt::format("{} holds {} distinct separation(s): at least 2 are needed", key,
                                            list.size()));
  return list;
}

/// Whether the harmonic-balance solution goes beside each point (hb_* columns): hb_beside = on, off, or auto — on
/// where it is a closed form (piecewise-linear laws: ~10 µs a point after a 0.5 ms scan), off for the other laws
/// (a describing-function curve traced per model, 5–20 ms, then more per point than the orbits themselves: 0.84 vs
/// 0.40 ms per DMT point with and without it, bench_sweep_options; docs/commands.md#sweep-options).
bool hb_beside(const io::ParamSet& p, const tapping::TappingModel& base) {
  const std::string& mode = p.text("hb_beside");
  return mode == "on" || (mode == "auto" && base.law.piecewise_linear() != nullptr);
}
/// Why the hb_* columns are NaN (results "harmonic_balance") when HB is not put beside the points.
std::string hb_not_evaluated(const io::ParamSet& p) {
  if (p.text("hb_beside") == "off") return "not evaluated (hb_* columns nan): hb_beside = off";
  return fmt::format("not evaluated (hb_* columns nan): hb_beside = auto and law = {} has no closed-form harmonic "
                     "balance (its describing-function curve costs more than the orbits); hb_beside = on puts it "
                     "beside each point",
                     p.text("law"));
}

/// The sweep's status and note from its trapped rows (docs/conventions.md#statuses): every row with the tip
/// trapped is no tapping anywhere in the range ("tip_trapped"); some trapped rows are said in the note and summary.
/// `what`: what one row is a value of ("separation", or "value" for a sweep in another parameter).
void record_trapped(nlohmann::json& results, std::string& summary, std::size_t rows, long trapped,
                    const char* what) {
  const bool all_trapped = rows > 0 && trapped == static_cast<long>(rows);
  results["status"] = all_trapped ? "tip_trapped" : "ok";
  results["note"] = all_trapped ? fmt::format("tip trapped: the tip sticks to the sample or stays in contact over "
                                              "the whole period at every {} of the sweep ({} rows; column "
                                              "trapped): no tapping",
                                              what, rows)
                                : trapped > 0 ? fmt::format("{} of {} rows with the tip trapped (stuck to the sample or "
                                                            "in contact over the whole period; column trapped)",
                                                            trapped, rows)
                                              : std::string();
  if (trapped > 0) summary += fmt::format("\n{}", results["note"].get<std::string>());
}

/// Records sorted by the value of `key`.
nlohmann::json records_sorted_by(nlohmann::json records, const std::string& key) {
  std::stable_sort(records.begin(), records.end(), [&](const nlohmann::json& a, const nlohmann::json& b) {
    return a[key].get<double>() < b[key].get<double>();
  });
  return records;
}

/// A sweep in another parameter than the separation (--parameter): the same instrument sweep (down from
/// parameter_max, then up) and continuation through folds, with the swept value first in every row and record.
void run_parameter_sweep(const io::ParamSet& p, Captured* capture) {
  const tapping::TappingModel base = tapping_model_from(p, law_object_of(capture));
  const TappingUnits u(tapping_scales_from(p));
  const SweptParameter swept = swept_parameter_from(p, law_object_of(capture));
  const std::string& name = swept.name;
  const int points = static_cast<int>(p.integer("points"));
  const bool retract = p.text("directions") == "both";  // the up pass after the down pass
  memory::require_fits("points", static_cast<double>(points), (retract ? 2.0 : 1.0) * sizeof(tapping::SweepPoint));
  const std::string& mode = p.text("mode");
  const bool instrument = mode == "instrument" || mode == "both";
  const bool continuation = mode == "continuation" || mode == "both";
  const bool quiet = p.flag("json") || p.flag("quiet");
  const bool beside = hb_beside(p, base);
  const std::string unit = swept.unit;
  // values of the swept parameter in its own unit (none for ω/ω_n)
  const auto values_text = [&](const std::vector<double>& v) {
    if (v.empty()) return std::string("none");
    std::string text;
    for (double x : v) text += fmt::format("{}{:.4g}", text.empty() ? "" : ", ", x);
    return unit == "dimensionless" ? text : text + " " + unit;
  };

  CommandOutput out(p, capture, "tapping sweep");
  io::TableOf<tapping::SweepPoint> table = sweep_table(u, false);
  table
      .prepend({name, unit,
                name == "drive_frequency"
                    ? std::string("drive frequency over natural frequency ω/ω_n (the drive force held)")
                    : fmt::format("value of the swept parameter {}", name),
                &tapping::SweepPoint::parameter})
      .describe("separation", "separation l of the orbit (fixed: the sweep moves " + name + ")")
      .describe("direction", "down (from parameter_max to parameter_min), up (back) or continuation");
  auto rows = out.open(std::move(table));
  long trapped = 0;
  const auto write_rows = [&](const std::vector<tapping::SweepPoint>& pts) {
    rows.add_all(pts);
    for (const tapping::SweepPoint& pt : pts) trapped += tapping::tip_trapped(pt.metrics) ? 1 : 0;
  };
  nlohmann::json results = nlohmann::json::object();
  results["parameter"] = name;
  // HB beside each point where it is a closed form at each value (docs/commands.md#sweeps-in-another-parameter)
  results["harmonic_balance"] =
      beside && base.law.piecewise_linear()
          ? std::string("beside each point (closed form at each point's model)")
      : !beside ? hb_not_evaluated(p)
          : fmt::format("not evaluated (hb_* columns nan): law = {} has no closed-form harmonic balance, and a "
                        "describing-function curve per point costs 7 ms to 0.3 s; use tapping hb at chosen values",
                        p.text("law"));
  std::string summary;
  const double magnitude = std::max(std::abs(swept.min), std::abs(swept.max));
  if (instrument) {
    io::Progress progress(fmt::format("tapping sweep in {} ({})", name, retract ? "down + up" : "down"),
                          (retract ? 2L : 1L) * points, !quiet);
    tapping::SweepOptions options;
    options.shooting = shooting_options_from(p);
    options.transient = transient_options_from(p);
    options.harmonic_balance = beside;
    options.retract = retract;
    options.progress = [&progress](long n) { progress.advance(n); };
    options.cancellation = cancellation_of(capture);
    options.validate();
    const tapping::SweepResult r = computed("instrument sweep", [&] {
      return tapping::sweep_instrument(base, swept.parameter, swept.min, swept.max, points, options);
    });
    progress.finish();
    write_rows(r.approach);
    write_rows(r.retract);
    results["down_jumps"] = r.approach_jumps;
    results["up_jumps"] = r.retract_jumps;
    nlohmann::json jumps = nlohmann::json::array();
    for (const tapping::SweepJump& j : r.jumps)
      jumps.push_back({{name, j.parameter},
                       {"tolerance", j.tolerance},
                       {"direction", sweep_direction_label(j.direction, false)},
                       {"located", j.located},
                       {"branch", branch_of(j.from_metrics)},
                       {"amplitude_before", u.length(j.from_metrics.amplitude)},
                       {"amplitude_after", u.length(j.to_metrics.amplitude)},
                       {"landed_periodic", j.landed_periodic}});
    results["jumps"] = records_sorted_by(std::move(jumps), name);
    const double tolerance = options.jump_tolerance * magnitude;
    results["jump_tolerance"] = tolerance;
    if (!retract) results["directions"] = "approach";
    summary += retract ? fmt::format("instrument sweep in {}: jumps down at {}; up at {} (located to ±{})", name,
                                     values_text(r.approach_jumps), values_text(r.retract_jumps),
                                     values_text({tolerance}))
                       : fmt::format("instrument sweep in {}: jumps down at {} (located to ±{}); no up pass "
                                     "(directions = approach)",
                                     name, values_text(r.approach_jumps), values_text({tolerance}));
  }
  if (continuation) {
    tapping::ContinuationOptions options;
    options.shooting = shooting_options_from(p);
    options.harmonic_balance = beside;
    options.max_step = u.length.internal(p.real("max_arclength_step"));
    options.initial_step = std::min(options.initial_step, options.max_step);
    options.max_points = static_cast<int>(p.integer("max_continuation_points"));
    options.cancellation = cancellation_of(capture);
    options.validate();
    const tapping::ContinuationResult c = computed("branch continuation", [&] {
      return tapping::sweep_continuation(base, swept.parameter, swept.min, swept.max, options);
    });
    write_rows(c.points);
    nlohmann::json folds = nlohmann::json::array();
    std::vector<double> at;
    for (const tapping::ContinuationFold& f : c.folds) {
      const tapping::OrbitMetrics& m = c.points.at(f.point).metrics;
      folds.push_back({{name, f.parameter},
                       {"amplitude", u.length(m.amplitude)},
                       {"offset", u.length(m.offset)},
                       {"phase", m.phase},
                       {"branch", branch_of(m)},
                       {"kind", f.separation_maximum ? "maximum" : "minimum"}});
      at.push_back(f.parameter);
    }
    std::sort(at.begin(), at.end());
    results["folds"] = records_sorted_by(std::move(folds), name);
    results["grazing"] = c.grazing;
    results["continuation_stop"] = c.stop_reason;
    results["continuation_points"] = c.points.size();
    summary += fmt::format("{}continuation in {}: {} points, folds at {}; grazing at {} ({})",
                           summary.empty() ? "" : "\n", name, c.points.size(), values_text(at),
                           values_text(c.grazing), c.stop_reason);
  }
  results["free_amplitude"] = u.length(base.free_amplitude());
  results["rows"] = out.rows();
  results["trapped_rows"] = trapped;
  record_trapped(results, summary, out.rows(), trapped, "value");
  const std::string& L = u.length.name;
  results["units"] = {{"length", L},
                      {"energy", u.energy.name},
                      {"force", u.force.name},
                      {"parameter", "label"},
                      {"harmonic_balance", "label"},
                      {"down_jumps", unit},
                      {"up_jumps", unit},
                      {"jump_tolerance", unit},
                      {"jumps", {{name, unit}, {"tolerance", unit}, {"direction", "label"}, {"located", "boolean (0/1)"},
                                 {"branch", "label"}, {"amplitude_before", L}, {"amplitude_after", L},
                                 {"landed_periodic", "boolean (0/1)"}}},
                      {"folds", {{name, unit}, {"amplitude", L}, {"offset", L}, {"phase", "rad"}, {"branch", "label"},
                                 {"kind", "label"}}},
                      {"grazing", unit},
                      {"continuation_points", "count"},
                      {"free_amplitude", L},
                      {"trapped_rows", "count"},
                      {"rows", "count"}};
  if (results.contains("directions")) results["units"]["directions"] = "label";
  out.finish(results, summary);
}

void run_sweep(const io::ParamSet& p, Captured* capture) {
  if (p.text("parameter") != "separation") return run_parameter_sweep(p, capture);
  for (const char* key : {"parameter_min", "parameter_max"})
    if (p.was_set(key))
      throw InvalidParameter(key, fmt::format("{} applies only with a parameter other than the separation (the "
                                              "separation's range is separation_min, separation_max)",
                                              key));
  const tapping::TappingModel base = tapping_model_from(p, law_object_of(capture));
  const TappingUnits u(tapping_scales_from(p));
  const std::vector<double> list = sweep_separations(p, u.length);
  double l_min = u.length.internal(p.real("separation_min")), l_max = u.length.internal(p.real("separation_max"));
  if (!list.empty()) {
    l_min = list.front();
    l_max = list.back();
  } else if (!(l_min < l_max)) {
    throw InvalidParameter("separation_min", fmt::format("separation_min = {} is out of range: must be < "
                                                         "separation_max = {}",
                                                         p.real("separation_min"), p.real("separation_max")));
  }
  const int points = list.empty() ? static_cast<int>(p.integer("points")) : static_cast<int>(list.size());
  const bool retract = p.text("directions") == "both";  // the retract pass after the approach
  // Both directions are held in memory (then streamed out).
  memory::require_fits("points", static_cast<double>(points), (retract ? 2.0 : 1.0) * sizeof(tapping::SweepPoint));
  const std::string& mode = p.text("mode");
  const bool instrument = mode == "instrument" || mode == "both";
  const bool continuation = mode == "continuation" || mode == "both";
  const bool quiet = p.flag("json") || p.flag("quiet");
  const bool beside = hb_beside(p, base);

  CommandOutput out(p, capture, "tapping sweep");
  auto rows = out.open(sweep_table(u));
  long trapped = 0;  // rows on which the tip does not tap (column trapped)
  const auto write_rows = [&](const std::vector<tapping::SweepPoint>& points) {
    rows.add_all(points);
    for (const tapping::SweepPoint& pt : points) trapped += tapping::tip_trapped(pt.metrics) ? 1 : 0;
  };
  nlohmann::json results = nlohmann::json::object();
  if (!beside) results["harmonic_balance"] = hb_not_evaluated(p);
  std::string summary;
  if (instrument) {
    io::Progress progress(retract ? "tapping sweep (approach + retract)" : "tapping sweep (approach)",
                          (retract ? 2L : 1L) * points, !quiet);
    tapping::SweepOptions options;
    options.shooting = shooting_options_from(p);
    options.transient = transient_options_from(p);
    options.harmonic_balance = beside;
    options.retract = retract;
    options.progress = [&progress](long n) { progress.advance(n); };
    // a jump runs a transient of up to max_transient_periods drive periods (a response decaying at Q settles in
    // about Q of them): when one can take seconds, its periods show as well (docs/development.md#work-and-time)
    const double transient_seconds =
        kTransientPeriodSeconds * std::min(static_cast<double>(options.transient.max_periods), p.real("quality_factor"));
    io::Progress transient_progress("tapping sweep (drive periods of transients at jumps, of at most)",
                                    (retract ? 2L : 1L) * points * options.transient.max_periods,
                                    !quiet && transient_seconds > kProgressAfterSeconds);
    options.transient.on_periods = [&transient_progress](int n) { transient_progress.advance(n); };
    options.cancellation = cancellation_of(capture);
    options.validate();  // the input; what is refused inside the sweep was computed (core/computed.hpp)
    const tapping::SweepResult r = computed("instrument sweep", [&] {
      return list.empty() ? tapping::sweep_instrument(base, l_min, l_max, points, options)
                          : tapping::sweep_instrument(base, list, options);
    });
    progress.finish();
    transient_progress.finish();
    write_rows(r.approach);
    write_rows(r.retract);
    results["approach_jumps"] = scaled(r.approach_jumps, u.length);
    results["retract_jumps"] = scaled(r.retract_jumps, u.length);
    results["jumps"] = jump_records(r.jumps, u);
    const double tolerance = u.length(options.jump_tolerance * base.free_amplitude());
    results["jump_tolerance"] = tolerance;
    if (!retract) results["directions"] = "approach";
    summary += retract
                   ? fmt::format("instrument sweep: jumps on approach at {}; on retract at {} (located to ±{})",
                                 io::summary_values(scaled_values(r.approach_jumps, u.length), u.length.name),
                                 io::summary_values(scaled_values(r.retract_jumps, u.length), u.length.name),
                                 io::summary_value(tolerance, u.length.name, 3))
                   : fmt::format("instrument sweep: jumps on approach at {} (located to ±{}); no retract pass "
                                 "(directions = approach)",
                                 io::summary_values(scaled_values(r.approach_jumps, u.length), u.length.name),
                                 io::summary_value(tolerance, u.length.name, 3));
  }
  if (continuation) {
    tapping::ContinuationOptions options;
    options.shooting = shooting_options_from(p);
    options.harmonic_balance = beside;
    options.max_step = u.length.internal(p.real("max_arclength_step"));
    options.initial_step = std::min(options.initial_step, options.max_step);
    options.max_points = static_cast<int>(p.integer("max_continuation_points"));
    options.cancellation = cancellation_of(capture);
    options.validate();
    const tapping::ContinuationResult c =
        computed("branch continuation", [&] { return tapping::sweep_continuation(base, l_min, l_max, options); });
    write_rows(c.points);
    results["folds"] = fold_records(c, u);
    results["grazing"] = scaled(c.grazing, u.length);
    results["continuation_stop"] = c.stop_reason;
    results["continuation_points"] = c.points.size();
    std::vector<double> folds;
    for (const auto& f : results["folds"]) folds.push_back(f["separation"].get<double>());
    summary += fmt::format("{}continuation: {} points, folds at {}; grazing at {} ({})", summary.empty() ? "" : "\n",
                           c.points.size(), io::summary_values(folds, u.length.name),
                           io::summary_values(scaled_values(c.grazing, u.length), u.length.name),
                           c.stop_reason);
  }
  results["free_amplitude"] = u.length(base.free_amplitude());
  results["rows"] = out.rows();
  results["trapped_rows"] = trapped;
  record_trapped(results, summary, out.rows(), trapped, "separation");
  results["units"] = sweep_units(u);
  for (const char* key : {"harmonic_balance", "directions"})  // present only where an option turned something off
    if (results.contains(key)) results["units"][key] = "label";
  out.finish(results, summary);
}

}  // namespace

void register_tapping_sweep(CLI::App& tapping) {
  add_command(
      tapping, "sweep",
      "sweep of periodic orbits in the separation (or --parameter: drive frequency, drive amplitude, a law "
      "parameter): instrument approach/retract or down/up (jumps, hysteresis) and/or continuation through folds; HB "
      "beside each point",
      [](io::ParamSet& p) {
        add_tapping_model_params(p);
        add_tapping_sim_params(p);
        p.group("Sweep");
        add_separation_range_params(p, 5.0, 15.0);
        add_separation_points_param(p, 200, 2, 10000000, "separations per direction of the instrument sweep (>= 2)");
        add_separation_list_params(p, "explicit separations of the instrument sweep instead of the uniform grid (any "
                                      "order, e.g. 20,18,16,15.5); the continuation runs between the smallest and the "
                                      "largest");
        p.text("mode", "instrument",
                  "instrument (approach then retract, jumps and hysteresis), continuation (pseudo-arclength through "
                  "folds, unstable branches) or both",
                  {"instrument", "continuation", "both"})
            .real("max_arclength_step", 0.2, "largest continuation step (scaled arclength)", io::Range::positive())
            .unit(kLengthUnit)
            .integer("max_continuation_points", 5000, "continuation point budget", 2, 100000000)
            .text("directions", "both",
                  "passes of the instrument sweep: both (approach then retract, or down then up: hysteresis and "
                  "the jumps of both) or approach (the approach, or down, pass only: half the work)",
                  {"both", "approach"})
            .only_if_given()
            .text("hb_beside", "auto",
                  "the harmonic-balance solution beside each point (hb_* columns): on, off, or auto (on where it is "
                  "a closed form, i.e. piecewise-linear laws, about 10 us a point; off for the other laws, whose "
                  "describing-function curve costs more than the orbits)",
                  {"auto", "on", "off"})
            .only_if_given()
            .text("parameter", "separation",
                  "the parameter swept: separation (separation_min .. separation_max), drive_frequency (ω/ω_n, the "
                  "drive force held: resonance curves), or a numeric model or law key of the run (drive_amplitude, "
                  "free_amplitude, quality_factor, approach_stiffness, effective_modulus, ...) over parameter_min .. "
                  "parameter_max in that key's unit, the separation fixed at `separation`",
                  sweep_parameter_names())
            .only_if_given()
            .real("parameter_min", 0.0, "smallest value of the swept parameter (not the separation)", io::Range::any())
            .unit("the unit of the swept parameter")
            .only_if_given()
            .real("parameter_max", 0.0, "largest value of the swept parameter, > parameter_min", io::Range::any())
            .unit("the unit of the swept parameter")
            .only_if_given();
        // the records of a sweep in another parameter do not list the separation grid it did not use
        for (const char* key : {"separation_min", "separation_max", "separations", "separations_file"})
          p.applies_when(key, "parameter", {"separation"});
        add_output_params(p, "out/tapping_sweep.csv", "sweep");
        add_quiet_flag(p);
      },
      run_sweep);
}

}  // namespace afmkit::cli
