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
#include "table_cache.hpp"
#include "tapping_params.hpp"
#include "tapping_sim_params.hpp"
#include "tapping_sweep_parameter.hpp"
#include "tapping_tables.hpp"
#include "unit_tagged.hpp"
#include "work_budget.hpp"

namespace afmkit::cli {

namespace {

/// "contact" when the orbit spends part of its period below the law's contact gap, else "free".
const char* branch_of(const tapping::OrbitMetrics& m) { return m.contact_fraction > 0.0 ? "contact" : "free"; }

/// One jump of the instrument sweep as a record, in a separation sweep (`parameter` empty: at a separation, with
/// its tolerance, in the length unit) or in a sweep of `parameter` (at its value, in its `unit`).
UnitTagged jump_record(const tapping::SweepJump& j, const TappingUnits& u, const std::string& parameter = {},
                       const std::string& unit = {}) {
  const bool separation = parameter.empty();
  const units::Unit at = separation ? u.length : units::as_is(unit);
  UnitTagged r;
  r.add(separation ? "separation" : parameter, separation ? j.separation : j.parameter, at)
      .add("tolerance", j.tolerance, at)
      .add("direction", sweep_direction_label(j.direction, separation), "label")
      .add("located", j.located, "boolean (0/1)")
      .add("branch", branch_of(j.from_metrics), "label")
      .add("amplitude_before", j.from_metrics.amplitude, u.length)
      .add("amplitude_after", j.to_metrics.amplitude, u.length)
      .add("landed_periodic", j.landed_periodic, "boolean (0/1)");
  return r;
}

/// One fold of the continuation as a record (as `tapping hb` reports its folds): where (the separation, or the
/// value of `parameter` in its `unit`), the orbit there (`m`: the metrics of the point nearest the fold).
UnitTagged fold_record(const tapping::ContinuationFold& f, const tapping::OrbitMetrics& m, const TappingUnits& u,
                       const std::string& parameter = {}, const std::string& unit = {}) {
  const bool separation = parameter.empty();
  UnitTagged r;
  if (separation) r.add("separation", f.separation, u.length);
  else r.add(parameter, f.parameter, units::as_is(unit));
  r.add("amplitude", m.amplitude, u.length)
      .add("offset", m.offset, u.length)
      .add("phase", m.phase, "rad")
      .add("branch", branch_of(m), "label")
      .add("kind", f.separation_maximum ? "maximum" : "minimum", "label");
  return r;
}

/// `items` sorted by `key` (stable: ties in the order given).
template <class T, class Key>
std::vector<T> sorted_by(std::vector<T> items, Key key) {
  std::stable_sort(items.begin(), items.end(), [&](const T& a, const T& b) { return key(a) < key(b); });
  return items;
}

/// The instrument sweep's results: the jumps of both directions (`down`, `up`: the keys of their locations), every
/// jump as a record sorted by where it is, the tolerance of their locations (`tolerance`: in the unit `at`).
/// `parameter` empty: a separation sweep (lengths); else a sweep of `parameter` in `unit`.
UnitTagged instrument_results(const tapping::SweepResult& r, double tolerance, const TappingUnits& u,
                              const std::string& parameter = {}, const std::string& unit = {}) {
  const bool separation = parameter.empty();
  const units::Unit at = separation ? u.length : units::as_is(unit);
  std::vector<UnitTagged> jumps;
  for (const tapping::SweepJump& j : sorted_by(r.jumps, [&](const tapping::SweepJump& j) {
         return separation ? j.separation : j.parameter;
       }))
    jumps.push_back(jump_record(j, u, parameter, unit));
  UnitTagged results;
  results.add(separation ? "approach_jumps" : "down_jumps", r.approach_jumps, at)
      .add(separation ? "retract_jumps" : "up_jumps", r.retract_jumps, at)
      .add("jumps", jumps, jump_record(tapping::SweepJump{}, u, parameter, unit))
      .add("jump_tolerance", tolerance, at);
  return results;
}

/// The continuation's results: its folds as records sorted by where they are, where it met grazing, its points and
/// why it stopped (as instrument_results for `parameter` and `unit`).
UnitTagged continuation_results(const tapping::ContinuationResult& c, const TappingUnits& u,
                                const std::string& parameter = {}, const std::string& unit = {}) {
  const bool separation = parameter.empty();
  std::vector<UnitTagged> folds;
  for (const tapping::ContinuationFold& f : sorted_by(c.folds, [&](const tapping::ContinuationFold& f) {
         return separation ? f.separation : f.parameter;
       }))
    folds.push_back(fold_record(f, c.points.at(f.point).metrics, u, parameter, unit));
  UnitTagged results;
  results
      .add("folds", folds, fold_record(tapping::ContinuationFold{}, tapping::OrbitMetrics{}, u, parameter, unit))
      .add("grazing", c.grazing, separation ? u.length : units::as_is(unit))
      .add("continuation_points", c.points.size(), "count")
      .add("continuation_stop", c.stop_reason);
  return results;
}

/// The entries of every run: the free amplitude, the rows and those with the tip trapped, and the units by
/// dimension of the table's columns.
void add_common_results(UnitTagged& results, const tapping::TappingModel& base, const TappingUnits& u,
                        std::size_t rows, long trapped) {
  results.add("free_amplitude", base.free_amplitude(), u.length)
      .add("rows", rows, "count")
      .add("trapped_rows", trapped, "count")
      .unit("length", u.length.name)
      .unit("energy", u.energy.name)
      .unit("force", u.force.name);
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
void record_trapped(UnitTagged& results, std::string& summary, std::size_t rows, long trapped, const char* what) {
  const bool all_trapped = rows > 0 && trapped == static_cast<long>(rows);
  const std::string note =
      all_trapped ? fmt::format("tip trapped: the tip sticks to the sample or stays in contact over the whole period "
                                "at every {} of the sweep ({} rows; column trapped): no tapping",
                                what, rows)
      : trapped > 0 ? fmt::format("{} of {} rows with the tip trapped (stuck to the sample or in contact over the "
                                  "whole period; column trapped)",
                                  trapped, rows)
                    : std::string();
  results.add("status", all_trapped ? "tip_trapped" : "ok").add("note", note);
  if (trapped > 0) summary += fmt::format("\n{}", note);
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
  UnitTagged results;
  results.add("parameter", name, "label");
  // HB beside each point where it is a closed form at each value (docs/commands.md#sweeps-in-another-parameter)
  results.add("harmonic_balance",
              beside && base.law.piecewise_linear()
                  ? std::string("beside each point (closed form at each point's model)")
              : !beside ? hb_not_evaluated(p)
                        : fmt::format("not evaluated (hb_* columns nan): law = {} has no closed-form harmonic balance, "
                                      "and a describing-function curve per point costs 7 ms to 0.3 s; use tapping hb "
                                      "at chosen values",
                                      p.text("law")),
              "label");
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
    const double tolerance = options.jump_tolerance * magnitude;
    results.merge(instrument_results(r, tolerance, u, name, unit));
    if (!retract) results.add("directions", "approach", "label");
    summary += retract ? fmt::format("instrument sweep in {}: jumps down at {}; up at {} (located to ±{})", name,
                                     values_text(r.approach_jumps), values_text(r.retract_jumps),
                                     values_text({tolerance}))
                       : fmt::format("instrument sweep in {}: jumps down at {} (located to ±{}); no up pass "
                                     "(directions = approach)",
                                     name, values_text(r.approach_jumps), values_text({tolerance}));
  } else {
    results.units_of(instrument_results(tapping::SweepResult{}, 0.0, u, name, unit));
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
    results.merge(continuation_results(c, u, name, unit));
    std::vector<double> at;
    for (const tapping::ContinuationFold& f : c.folds) at.push_back(f.parameter);
    std::sort(at.begin(), at.end());
    summary += fmt::format("{}continuation in {}: {} points, folds at {}; grazing at {} ({})",
                           summary.empty() ? "" : "\n", name, c.points.size(), values_text(at),
                           values_text(c.grazing), c.stop_reason);
  } else {
    results.units_of(continuation_results(tapping::ContinuationResult{}, u, name, unit));
  }
  add_common_results(results, base, u, out.rows(), trapped);
  record_trapped(results, summary, out.rows(), trapped, "value");
  out.finish(results.with_units(), summary);
}

/// The table of separation sweeps, declared once per units (sweep_table), shared by a registration's runs.
using SweepTables = TableCache<tapping::SweepPoint, TappingUnits>;

void run_sweep(const io::ParamSet& p, Captured* capture, SweepTables& tables) {
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
  auto rows = out.open(tables.get(u));
  long trapped = 0;  // rows on which the tip does not tap (column trapped)
  const auto write_rows = [&](const std::vector<tapping::SweepPoint>& points) {
    rows.add_all(points);
    for (const tapping::SweepPoint& pt : points) trapped += tapping::tip_trapped(pt.metrics) ? 1 : 0;
  };
  UnitTagged results;
  if (!beside) results.add("harmonic_balance", hb_not_evaluated(p), "label");
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
    const UnitTagged instrument = instrument_results(r, options.jump_tolerance * base.free_amplitude(), u);
    results.merge(instrument);
    if (!retract) results.add("directions", "approach", "label");
    // the summary says the values written (in their unit)
    const auto written = [&](const char* key) { return instrument.values().at(key).get<std::vector<double>>(); };
    const std::string& L = u.length.name;
    const std::string tolerance = io::summary_value(instrument.values().at("jump_tolerance").get<double>(), L, 3);
    summary += retract ? fmt::format("instrument sweep: jumps on approach at {}; on retract at {} (located to ±{})",
                                     io::summary_values(written("approach_jumps"), L),
                                     io::summary_values(written("retract_jumps"), L), tolerance)
                       : fmt::format("instrument sweep: jumps on approach at {} (located to ±{}); no retract pass "
                                     "(directions = approach)",
                                     io::summary_values(written("approach_jumps"), L), tolerance);
  } else {
    results.units_of(instrument_results(tapping::SweepResult{}, 0.0, u));
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
    const UnitTagged continued = continuation_results(c, u);
    results.merge(continued);
    std::vector<double> folds;
    for (const auto& f : continued.values().at("folds")) folds.push_back(f.at("separation").get<double>());
    const std::string& L = u.length.name;
    summary += fmt::format("{}continuation: {} points, folds at {}; grazing at {} ({})", summary.empty() ? "" : "\n",
                           c.points.size(), io::summary_values(folds, L),
                           io::summary_values(continued.values().at("grazing").get<std::vector<double>>(), L),
                           c.stop_reason);
  } else {
    results.units_of(continuation_results(tapping::ContinuationResult{}, u));
  }
  add_common_results(results, base, u, out.rows(), trapped);
  record_trapped(results, summary, out.rows(), trapped, "separation");
  out.finish(results.with_units(), summary);
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
            .real("max_arclength_step", 0.2,
                  "largest continuation step: of the arclength, a length in the separation's unit",
                  io::Range::positive())
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
      [tables = std::make_shared<SweepTables>(+[](const TappingUnits& u) { return sweep_table(u); })](
          const io::ParamSet& p, Captured* capture) { run_sweep(p, capture, *tables); });
}

}  // namespace afmkit::cli
