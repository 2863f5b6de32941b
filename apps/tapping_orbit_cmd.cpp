// afmkit tapping orbit: every harmonic-balance solution and every periodic orbit found at one separation
// (find_orbits: shooting from each HB solution, transients, a phase × amplitude grid, states in contact and the
// branches continued through l), with Floquet stability and the orbit observables. CSV: one row per orbit;
// JSON sidecar: HB solutions, transients and the search report (seeds per kind, which seeds found which orbit).
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/io/table.hpp"
#include "command.hpp"
#include "table_cache.hpp"
#include "work_budget.hpp"
#include "commands.hpp"
#include "tapping_params.hpp"
#include "tapping_sim_params.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

/// Seeds of each kind (tapping::SeedKind names) among `seeds` (indices into the search report).
nlohmann::json seeds_by_kind(const std::vector<int>& seeds, const tapping::OrbitSearchReport& report) {
  std::array<int, tapping::seed_kind_count> n{};
  for (int i : seeds) ++n[static_cast<std::size_t>(report.seeds[i].kind)];
  nlohmann::json j = nlohmann::json::object();
  for (int k = 0; k < tapping::seed_kind_count; ++k) j[tapping::seed_kind_name(static_cast<tapping::SeedKind>(k))] = n[k];
  return j;
}

/// One seed of the search: how it started and which orbits it converged to (into `j`: a row of the seeds'
/// array is built without units, UnitTagged::values_only; their units are those of a grid seed with every field).
UnitTagged seed_record(UnitTagged j, const tapping::SearchSeed& seed, const TappingUnits& u) {
  j.add("kind", tapping::seed_kind_name(seed.kind))
      .add("initial_position", seed.start.position, u.length)
      .add("initial_velocity", seed.start.velocity, u.velocity)
      .add("orbits", seed.orbits, "count");
  if (seed.kind == tapping::SeedKind::grid)
    j.add("grid_phase", seed.grid_phase, "rad").add("grid_amplitude", seed.grid_amplitude, u.length);
  return j;
}

/// How find_orbits searched: seeds per kind, converged per kind, the continuation bracket, every seed.
UnitTagged search_record(const tapping::OrbitSearchReport& r, const TappingUnits& u) {
  nlohmann::json by_kind = nlohmann::json::object(), converged = nlohmann::json::object();
  for (int k = 0; k < tapping::seed_kind_count; ++k) {
    const char* name = tapping::seed_kind_name(static_cast<tapping::SeedKind>(k));
    by_kind[name] = r.seeds_by_kind[k];
    converged[name] = r.converged_by_kind[k];
  }
  nlohmann::json seeds = nlohmann::json::array();
  seeds.get_ref<nlohmann::json::array_t&>().reserve(r.seeds.size());
  for (const tapping::SearchSeed& seed : r.seeds)
    seeds.push_back(seed_record(UnitTagged(UnitTagged::values_only), seed, u).values());
  UnitTagged j;
  j.add("seeds_by_kind", std::move(by_kind), "count")
      .add("converged_by_kind", std::move(converged), "count")
      .add("seeds_total", r.seeds.size(), "count")
      .add("continuation_runs", r.continuation_runs, "count")
      .add("continuation_bracket", std::vector<double>{r.bracket_min, r.bracket_max}, u.length)
      .add("seconds", r.seconds, "s")
      .add("seeds", std::move(seeds))
      .unit("seeds", seed_record(UnitTagged(), tapping::SearchSeed{}, u).units());  // a grid seed: every field
  return j;
}

/// One orbit found (into `j`: UnitTagged::values_only for a row of the orbits' array).
UnitTagged orbit_record(UnitTagged j, const tapping::FoundOrbit& f, const tapping::OrbitSearchReport& report,
                        const TappingUnits& u) {
  const auto& m = f.metrics;
  const auto& o = f.orbit;
  nlohmann::json multipliers = nlohmann::json::array();  // [{"im", "re"}, ...] of the first two
  for (int k = 0; k < 2; ++k) {
    nlohmann::json z = nlohmann::json::object();
    z["im"] = o.floquet_multipliers[k].imag();
    z["re"] = o.floquet_multipliers[k].real();
    multipliers.push_back(std::move(z));
  }
  j.add("source", tapping::orbit_source_name(f.source))
      .add("found_by", seeds_by_kind(f.seeds, report), "count")
      .add("seeds", f.seeds, "count")
      .add("period_multiple", o.period_multiple, "count")
      .add("stable", o.stable, "boolean (0/1)")
      .add("floquet_max", o.floquet_max, "dimensionless")
      .add("floquet_multipliers", std::move(multipliers), "dimensionless")
      .add("amplitude", m.amplitude, u.length)
      .add("offset", m.offset, u.length)
      .add("phase", m.phase, "rad")
      .add("harmonics", std::vector<double>(m.harmonics.begin(), m.harmonics.end()), u.length)
      .add("contact_fraction", m.contact_fraction, "dimensionless")
      .add("peak_force", m.peak_force, u.force)
      .add("min_gap", m.min_gap, u.length)
      .add("drive_work", m.drive_work, u.energy)
      .add("viscous_dissipation", m.viscous_dissipation, u.energy)
      .add("contact_dissipation", m.contact_dissipation, u.energy)
      .add("energy_dissipated", m.energy_dissipated(), u.energy)
      .add("sticking_time", m.sticking_duration, u.time)
      .add("initial_position", o.initial.position, u.length)
      .add("initial_velocity", o.initial.velocity, u.velocity)
      .add("shooting_residual", o.residual, "dimensionless")
      .add("trapped", tapping::tip_trapped(m), "boolean (0/1)");
  return j;
}

UnitTagged hb_record(UnitTagged j, const tapping::HbPoint& h, const TappingUnits& u) {
  j.add("branch", tapping::branch_name(h.branch))
      .add("q", h.q, "dimensionless")
      .add("amplitude", h.amplitude, u.length)
      .add("offset", h.offset, u.length)
      .add("phase", h.phase, "rad");
  return j;
}

UnitTagged transient_record(UnitTagged j, const tapping::TransientOutcome& t) {
  j.add("kind", tapping::response_kind_name(t.kind)).add("periods_simulated", t.periods_simulated, "count");
  if (t.orbit) j.add("period_multiple", t.orbit->period_multiple, "count");
  if (!t.message.empty()) j.add("message", t.message);
  return j;
}

/// What the search found, in words (docs/conventions.md#statuses): "ok" (an orbit on which the tip taps),
/// "tip_trapped" (every orbit found keeps the tip in contact) or "no_orbit" (none found).
struct OrbitStatus {
  std::string status, note;
};
OrbitStatus orbit_status(const tapping::OrbitSearchResult& r, double separation, const units::Unit& length) {
  if (r.orbits.empty())
    return {"no_orbit", fmt::format("no periodic orbit found at separation {} (see the search report)",
                                    summary_value(separation, length))};
  for (const tapping::FoundOrbit& f : r.orbits)
    if (!tapping::tip_trapped(f.metrics)) return {"ok", ""};
  return {"tip_trapped",
          fmt::format("tip trapped: on every orbit found ({}) the tip sticks to the sample or stays in contact over "
                      "the whole period at separation {} (held by the sample: an attraction larger than the drive "
                      "can pull off); no tapping orbit",
                      r.orbits.size(), summary_value(separation, length))};
}

/// What a run found and what its summary is made of (owned by the summary's maker: Captured::take_results_maker).
struct OrbitRun {
  tapping::OrbitSearchResult result;
  TappingUnits units;
  double separation;
  double free_amplitude;
  OrbitStatus status;
};

/// The command's summary document (--json, the sidecar's results, r.results): the HB solutions, the orbits, the
/// transients and the search report, every entry with its unit.
nlohmann::json orbit_summary(const OrbitRun& run) {
  const tapping::OrbitSearchResult& r = run.result;
  const TappingUnits& u = run.units;
  const double separation = run.separation, free_amplitude = run.free_amplitude;
  const OrbitStatus& status = run.status;
  // every entry with its unit (the sidecar's "units", per results key: docs/study.md#outputs)
  // the rows of each array without units (UnitTagged::values_only), moved into the document (no copies)
  const auto row = [] { return UnitTagged(UnitTagged::values_only); };
  nlohmann::json orbits = nlohmann::json::array();
  for (const tapping::FoundOrbit& f : r.orbits) orbits.push_back(orbit_record(row(), f, r.report, u).values());
  nlohmann::json hb = nlohmann::json::array();
  for (const tapping::HbPoint& h : r.harmonic_balance) hb.push_back(hb_record(row(), h, u).values());
  nlohmann::json transients = nlohmann::json::array();
  for (const tapping::TransientOutcome& t : r.transients) transients.push_back(transient_record(row(), t).values());
  // the units of the rows of each array: those of a record with every field
  const tapping::FoundOrbit any_orbit{};
  tapping::TransientOutcome any_transient;
  any_transient.orbit = tapping::PeriodicOrbit{};
  UnitTagged results;
  results.add("separation", separation, u.length)
      .add("free_amplitude", free_amplitude, u.length)
      .add("harmonic_balance", std::move(hb))
      .unit("harmonic_balance", hb_record(UnitTagged(), tapping::HbPoint{}, u).units())
      .add("orbits", std::move(orbits))
      .unit("orbits", orbit_record(UnitTagged(), any_orbit, r.report, u).units())
      .add("transients", std::move(transients))
      .unit("transients", transient_record(UnitTagged(), any_transient).units())
      .add("search", search_record(r.report, u))
      .add("status", status.status)
      .add("note", status.note)
      // the units of the whole run
      .unit("length", u.length.name)
      .unit("velocity", u.velocity.name)
      .unit("force", u.force.name)
      .unit("energy", u.energy.name)
      .unit("time", u.time.name)
      .unit("phase", "rad")
      .unit("seconds", "s");
  return std::move(results).summary();
}

/// The table: one row per orbit found (declared once per units: OrbitTables).
io::TableOf<tapping::FoundOrbit> orbit_table(const TappingUnits& u) {
  using F = tapping::FoundOrbit;
  return {
      {"source", "label", "how the orbit was found first (harmonic_balance, transient, grid, contact, continuation)",
       [](const F& f) { return tapping::orbit_source_name(f.source); }},
      {"period_multiple", "count", "n of a period-n orbit (1: the drive period)",
       [](const F& f) { return f.orbit.period_multiple; }},
      {"stable", "boolean (0/1)", "1: all Floquet multipliers inside the unit circle",
       [](const F& f) { return f.orbit.stable; }},
      {"amplitude", u.length, "first-harmonic amplitude B", [](const F& f) { return f.metrics.amplitude; }},
      {"offset", u.length, "mean deflection A", [](const F& f) { return f.metrics.offset; }},
      {"phase", "rad", "phase lag φ of the first harmonic behind the drive (docs/conventions.md), in (-π, π]",
       [](const F& f) { return f.metrics.phase; }},
      {"harmonic_2", u.length, "amplitude of the 2nd harmonic", [](const F& f) { return f.metrics.harmonics[0]; }},
      {"harmonic_3", u.length, "amplitude of the 3rd harmonic", [](const F& f) { return f.metrics.harmonics[1]; }},
      {"harmonic_4", u.length, "amplitude of the 4th harmonic", [](const F& f) { return f.metrics.harmonics[2]; }},
      {"harmonic_5", u.length, "amplitude of the 5th harmonic", [](const F& f) { return f.metrics.harmonics[3]; }},
      {"contact_fraction", "dimensionless", "fraction of the period with the gap below the law's contact gap",
       [](const F& f) { return f.metrics.contact_fraction; }},
      {"peak_force", u.force, "largest tip-sample force (positive: repulsive)",
       [](const F& f) { return f.metrics.peak_force; }},
      {"min_gap", u.length, "smallest gap x + l", [](const F& f) { return f.metrics.min_gap; }},
      {"energy_dissipated", u.energy, "energy dissipated per drive period (viscous + contact)",
       [](const F& f) { return f.metrics.energy_dissipated(); }},
      {"viscous_dissipation", u.energy, "viscous (cantilever damping) part per drive period",
       [](const F& f) { return f.metrics.viscous_dissipation; }},
      {"contact_dissipation", u.energy, "tip-sample (hysteresis) part per drive period",
       [](const F& f) { return f.metrics.contact_dissipation; }},
      {"floquet_max", "dimensionless", "largest Floquet multiplier modulus",
       [](const F& f) { return f.orbit.floquet_max; }},
      {"sticking_time", u.time, "time spent sticking to the sample per orbit",
       [](const F& f) { return f.metrics.sticking_duration; }},
      {"initial_position", u.length, "tip position x at drive phase 0 on the orbit",
       [](const F& f) { return f.orbit.initial.position; }},
      {"initial_velocity", u.velocity, "tip velocity at drive phase 0 on the orbit",
       [](const F& f) { return f.orbit.initial.velocity; }},
      {"trapped", "boolean (0/1)",
       "1: the tip sticks to the sample or stays in contact over the whole period (no tapping; "
       "docs/conventions.md#statuses)",
       [](const F& f) { return tapping::tip_trapped(f.metrics); }}};
}

using OrbitTables = TableCache<tapping::FoundOrbit, TappingUnits>;

void run_orbit(const io::ParamSet& p, Captured* capture, OrbitTables& tables) {
  const tapping::TappingModel model = tapping_model_from(p, law_object_of(capture));
  TappingUnits u(tapping_scales_from(p));
  tapping::OrbitSearchOptions options;
  options.shooting = shooting_options_from(p);
  options.transient = transient_options_from(p);
  // cost model (docs/development.md#work-and-time): at least two full transients (the free response and rest),
  // each of up to max_transient_periods drive periods; a response decaying at the quality factor Q needs about Q
  // periods to settle, so min(max_transient_periods, Q) periods of about kPeriodSeconds each is a lower bound
  const double estimate = require_transient_work(p, options.transient, 2.0, "2 transients");
  io::Progress progress("tapping orbit (transient drive periods, of at most)", 5L * options.transient.max_periods,
                        estimate > kProgressAfterSeconds && !p.flag("json"));
  options.transient.on_periods = [&progress](int n) { progress.advance(n); };
  options.cancellation = cancellation_of(capture);
  tapping::OrbitSearchResult r_searched = tapping::find_orbits(model, options);
  progress.finish();

  // the summary, made where it is read (a caller that never reads it does not pay for its ~550 values: Captured::
  // take_results_maker); it owns the search's result
  const double separation = p.real("separation");
  OrbitStatus status = orbit_status(r_searched, separation, u.length);
  const auto run = std::make_shared<const OrbitRun>(
      OrbitRun{std::move(r_searched), std::move(u), separation, model.free_amplitude(), std::move(status)});
  const tapping::OrbitSearchResult& r = run->result;
  const TappingUnits& units = run->units;
  ResultsMaker summary = [run] { return orbit_summary(*run); };
  CommandOutput out(p, capture, "tapping orbit");
  out.open(tables.get(units)).add_all(r.orbits);
  if (p.flag("json")) {
    out.finish(std::move(summary), "");
    return;
  }
  // lengths by magnitude in physical units, said to be normalised otherwise (docs/units.md#summaries)
  const auto len = [&](double model_length) { return summary_value(model_length, units.length, 6); };
  fmt::print("separation {}: {} HB solution(s), {} periodic orbit(s); phases in rad\n", len(separation),
             r.harmonic_balance.size(), r.orbits.size());
  for (const tapping::HbPoint& h : r.harmonic_balance)
    fmt::print("  HB {:5s} amplitude {}  offset {}  phase {:.6g} rad\n", tapping::branch_name(h.branch),
               len(h.amplitude), len(h.offset), h.phase);
  for (const tapping::FoundOrbit& f : r.orbits)
    fmt::print("  orbit ({}{}) amplitude {}  offset {}  phase {:.6g} rad  {}  |mu|max {:.4g}  contact {:.3g}  "
               "found by {} seed(s)\n",
               tapping::orbit_source_name(f.source),
               f.orbit.period_multiple > 1 ? fmt::format(", period {}", f.orbit.period_multiple) : std::string(),
               len(f.metrics.amplitude), len(f.metrics.offset), f.metrics.phase,
               f.orbit.stable ? "stable" : "unstable", f.orbit.floquet_max, f.metrics.contact_fraction,
               f.seeds.size());
  if (run->status.status != "ok") fmt::print("  {}\n", run->status.note);
  for (const tapping::TransientOutcome& t : r.transients)
    if (t.kind != tapping::ResponseKind::periodic) fmt::print("  transient: {}\n", t.message);
  {
    const auto& rep = r.report;
    std::string kinds;
    int converged = 0;
    for (int k = 0; k < tapping::seed_kind_count; ++k) {
      kinds += fmt::format("{}{} {}/{}", k ? ", " : "", tapping::seed_kind_name(static_cast<tapping::SeedKind>(k)),
                           rep.converged_by_kind[k], rep.seeds_by_kind[k]);
      converged += rep.converged_by_kind[k];
    }
    fmt::print("  search: {} seeds, {} converged (converged/seeds: {}); {} branch continuations over l from {} to "
               "{}; {}\n",
               rep.seeds.size(), converged, kinds, rep.continuation_runs, len(rep.bracket_min), len(rep.bracket_max),
               io::quantity(rep.seconds, "s", 3));
  }
  out.finish(std::move(summary), "");
}

}  // namespace

void register_tapping_orbit(CLI::App& tapping) {
  add_command(
      tapping, "orbit",
      "all periodic orbits at one separation: shooting from every HB solution, transients, a phase x amplitude grid, "
      "contact states and branch continuation; Floquet stability, harmonics, contact, energy",
      [](io::ParamSet& p) {
        add_tapping_model_params(p);
        add_tapping_sim_params(p);
        add_output_params(p, "out/tapping_orbit.csv", "orbits");
      },
      // the table declared once per units, shared by this registration's runs
      [tables = std::make_shared<OrbitTables>(orbit_table)](const io::ParamSet& p, Captured* capture) {
        run_orbit(p, capture, *tables);
      });
}

}  // namespace afmkit::cli
