// afmkit tapping orbit: every harmonic-balance solution and every periodic orbit found at one separation
// (find_orbits: shooting from each HB solution, transients, a phase × amplitude grid, states in contact and the
// branches continued through l), with Floquet stability and the orbit observables. CSV: one row per orbit;
// JSON sidecar: HB solutions, transients and the search report (seeds per kind, which seeds found which orbit).
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/io/table.hpp"
#include "command.hpp"
#include "work_budget.hpp"
#include "commands.hpp"
#include "tapping_params.hpp"
#include "tapping_sim_params.hpp"

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

/// How find_orbits searched: seeds per kind, converged per kind, the continuation bracket, every seed.
nlohmann::json search_json(const tapping::OrbitSearchReport& r, const TappingScales& s) {
  nlohmann::json by_kind = nlohmann::json::object(), converged = nlohmann::json::object();
  for (int k = 0; k < tapping::seed_kind_count; ++k) {
    const char* name = tapping::seed_kind_name(static_cast<tapping::SeedKind>(k));
    by_kind[name] = r.seeds_by_kind[k];
    converged[name] = r.converged_by_kind[k];
  }
  nlohmann::json seeds = nlohmann::json::array();
  for (const tapping::SearchSeed& seed : r.seeds) {
    nlohmann::json j = {{"kind", tapping::seed_kind_name(seed.kind)},
                        {"initial_position", seed.start.position * s.length},
                        {"initial_velocity", seed.start.velocity * s.length / s.time},
                        {"orbits", seed.orbits}};
    if (seed.kind == tapping::SeedKind::grid) {
      j["grid_phase"] = seed.grid_phase;
      j["grid_amplitude"] = seed.grid_amplitude * s.length;
    }
    seeds.push_back(j);
  }
  return {{"seeds_by_kind", by_kind},
          {"converged_by_kind", converged},
          {"seeds_total", r.seeds.size()},
          {"continuation_runs", r.continuation_runs},
          {"continuation_bracket", {r.bracket_min * s.length, r.bracket_max * s.length}},
          {"seconds", r.seconds},
          {"seeds", seeds}};
}

nlohmann::json orbit_json(const tapping::FoundOrbit& f, const tapping::OrbitSearchReport& report,
                          const TappingScales& s) {
  const auto& m = f.metrics;
  const auto& o = f.orbit;
  return {{"source", tapping::orbit_source_name(f.source)},
          {"found_by", seeds_by_kind(f.seeds, report)},
          {"seeds", f.seeds},
          {"period_multiple", o.period_multiple},
          {"stable", o.stable},
          {"floquet_max", o.floquet_max},
          {"floquet_multipliers",
           {{{"re", o.floquet_multipliers[0].real()}, {"im", o.floquet_multipliers[0].imag()}},
            {{"re", o.floquet_multipliers[1].real()}, {"im", o.floquet_multipliers[1].imag()}}}},
          {"amplitude", m.amplitude * s.length},
          {"offset", m.offset * s.length},
          {"phase", m.phase},
          {"harmonics", {m.harmonics[0] * s.length, m.harmonics[1] * s.length, m.harmonics[2] * s.length,
                         m.harmonics[3] * s.length}},
          {"contact_fraction", m.contact_fraction},
          {"peak_force", m.peak_force * s.force},
          {"min_gap", m.min_gap * s.length},
          {"drive_work", m.drive_work * s.energy},
          {"viscous_dissipation", m.viscous_dissipation * s.energy},
          {"contact_dissipation", m.contact_dissipation * s.energy},
          {"energy_dissipated", m.energy_dissipated() * s.energy},
          {"sticking_time", m.sticking_duration * s.time},
          {"initial_position", o.initial.position * s.length},
          {"initial_velocity", o.initial.velocity * s.length / s.time},
          {"shooting_residual", o.residual},
          {"trapped", tapping::tip_trapped(m)}};
}

/// What the search found, in words (docs/conventions.md#statuses): "ok" (an orbit on which the tip taps),
/// "tip_trapped" (every orbit found keeps the tip in contact) or "no_orbit" (none found).
struct OrbitStatus {
  std::string status, note;
};
OrbitStatus orbit_status(const tapping::OrbitSearchResult& r, double separation, const std::string& unit) {
  if (r.orbits.empty())
    return {"no_orbit", fmt::format("no periodic orbit found at separation {} (see the search report)",
                                    io::summary_value(separation, unit))};
  for (const tapping::FoundOrbit& f : r.orbits)
    if (!tapping::tip_trapped(f.metrics)) return {"ok", ""};
  return {"tip_trapped",
          fmt::format("tip trapped: on every orbit found ({}) the tip sticks to the sample or stays in contact over "
                      "the whole period at separation {} (held by the sample: an attraction larger than the drive "
                      "can pull off); no tapping orbit",
                      r.orbits.size(), io::summary_value(separation, unit))};
}

/// The unit of every number of orbit_json.
nlohmann::json orbit_units(const TappingScales& s) {
  const std::string L = s.length_unit;
  return {{"found_by", "count"},           {"seeds", "count"},
          {"period_multiple", "count"},    {"stable", "boolean (0/1)"},
          {"floquet_max", "dimensionless"}, {"floquet_multipliers", "dimensionless"},
          {"amplitude", L},                {"offset", L},
          {"phase", "rad"},                {"harmonics", L},
          {"contact_fraction", "dimensionless"}, {"peak_force", s.force_unit},
          {"min_gap", L},                  {"drive_work", s.energy_unit},
          {"viscous_dissipation", s.energy_unit}, {"contact_dissipation", s.energy_unit},
          {"energy_dissipated", s.energy_unit},   {"sticking_time", s.time_unit},
          {"initial_position", L},         {"initial_velocity", L + "/" + s.time_unit},
          {"shooting_residual", "dimensionless"}};
}

/// The table: one row per orbit found.
io::TableOf<tapping::FoundOrbit> orbit_table(const TappingScales& s) {
  using F = tapping::FoundOrbit;
  const std::string L = s.length_unit, velocity = L + "/" + s.time_unit;
  const double l = s.length, force = s.force, energy = s.energy, time = s.time;
  return {
      {"source", "label", "how the orbit was found first (harmonic_balance, transient, grid, contact, continuation)",
       [](const F& f) { return tapping::orbit_source_name(f.source); }},
      {"period_multiple", "count", "n of a period-n orbit (1: the drive period)",
       [](const F& f) { return f.orbit.period_multiple; }},
      {"stable", "boolean (0/1)", "1: all Floquet multipliers inside the unit circle",
       [](const F& f) { return f.orbit.stable; }},
      {"amplitude", L, "first-harmonic amplitude B", [l](const F& f) { return f.metrics.amplitude * l; }},
      {"offset", L, "mean deflection A", [l](const F& f) { return f.metrics.offset * l; }},
      {"phase", "rad", "phase lag φ of the first harmonic behind the drive (docs/conventions.md), in (-π, π]",
       [](const F& f) { return f.metrics.phase; }},
      {"harmonic_2", L, "amplitude of the 2nd harmonic", [l](const F& f) { return f.metrics.harmonics[0] * l; }},
      {"harmonic_3", L, "amplitude of the 3rd harmonic", [l](const F& f) { return f.metrics.harmonics[1] * l; }},
      {"harmonic_4", L, "amplitude of the 4th harmonic", [l](const F& f) { return f.metrics.harmonics[2] * l; }},
      {"harmonic_5", L, "amplitude of the 5th harmonic", [l](const F& f) { return f.metrics.harmonics[3] * l; }},
      {"contact_fraction", "dimensionless", "fraction of the period with the gap below the law's contact gap",
       [](const F& f) { return f.metrics.contact_fraction; }},
      {"peak_force", s.force_unit, "largest tip-sample force (positive: repulsive)",
       [force](const F& f) { return f.metrics.peak_force * force; }},
      {"min_gap", L, "smallest gap x + l", [l](const F& f) { return f.metrics.min_gap * l; }},
      {"energy_dissipated", s.energy_unit, "energy dissipated per drive period (viscous + contact)",
       [energy](const F& f) { return f.metrics.energy_dissipated() * energy; }},
      {"viscous_dissipation", s.energy_unit, "viscous (cantilever damping) part per drive period",
       [energy](const F& f) { return f.metrics.viscous_dissipation * energy; }},
      {"contact_dissipation", s.energy_unit, "tip-sample (hysteresis) part per drive period",
       [energy](const F& f) { return f.metrics.contact_dissipation * energy; }},
      {"floquet_max", "dimensionless", "largest Floquet multiplier modulus",
       [](const F& f) { return f.orbit.floquet_max; }},
      {"sticking_time", s.time_unit, "time spent sticking to the sample per orbit",
       [time](const F& f) { return f.metrics.sticking_duration * time; }},
      {"initial_position", L, "tip position x at drive phase 0 on the orbit",
       [l](const F& f) { return f.orbit.initial.position * l; }},
      {"initial_velocity", velocity, "tip velocity at drive phase 0 on the orbit",
       [l, time](const F& f) { return f.orbit.initial.velocity * l / time; }},
      {"trapped", "boolean (0/1)",
       "1: the tip sticks to the sample or stays in contact over the whole period (no tapping; "
       "docs/conventions.md#statuses)",
       [](const F& f) { return tapping::tip_trapped(f.metrics); }}};
}

void run_orbit(const io::ParamSet& p, Captured* capture) {
  const tapping::TappingModel model = tapping_model_from(p, law_object_of(capture));
  const TappingScales scales = tapping_scales_from(p);
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
  const tapping::OrbitSearchResult r = tapping::find_orbits(model, options);
  progress.finish();
  const OrbitStatus status = orbit_status(r, p.real("separation"), scales.length_unit);

  nlohmann::json orbits = nlohmann::json::array();
  for (const tapping::FoundOrbit& f : r.orbits) orbits.push_back(orbit_json(f, r.report, scales));
  nlohmann::json hb = nlohmann::json::array();
  for (const tapping::HbPoint& h : r.harmonic_balance)
    hb.push_back({{"branch", tapping::branch_name(h.branch)},
                  {"q", h.q},
                  {"amplitude", h.amplitude * scales.length},
                  {"offset", h.offset * scales.length},
                  {"phase", h.phase}});
  nlohmann::json transients = nlohmann::json::array();
  for (const tapping::TransientOutcome& t : r.transients) {
    nlohmann::json j = {{"kind", tapping::response_kind_name(t.kind)}, {"periods_simulated", t.periods_simulated}};
    if (t.orbit) j["period_multiple"] = t.orbit->period_multiple;
    if (!t.message.empty()) j["message"] = t.message;
    transients.push_back(j);
  }
  const std::string length = scales.length_unit, velocity = length + "/" + scales.time_unit;
  const nlohmann::json summary = {
      {"separation", p.real("separation")},
      {"free_amplitude", model.free_amplitude() * scales.length},
      {"harmonic_balance", hb},
      {"orbits", orbits},
      {"transients", transients},
      {"search", search_json(r.report, scales)},
      {"status", status.status},
      {"note", status.note},
      {"units",
       {{"length", length}, {"velocity", velocity}, {"force", scales.force_unit}, {"energy", scales.energy_unit},
        {"time", scales.time_unit}, {"phase", "rad"}, {"seconds", "s"},
        // per results key (the units of study outputs, docs/study.md#outputs)
        {"separation", length}, {"free_amplitude", length},
        {"harmonic_balance", {{"q", "dimensionless"}, {"amplitude", length}, {"offset", length}, {"phase", "rad"}}},
        {"orbits", orbit_units(scales)},
        {"transients", {{"periods_simulated", "count"}, {"period_multiple", "count"}}},
        {"search", {{"seeds_by_kind", "count"}, {"converged_by_kind", "count"}, {"seeds_total", "count"},
                    {"continuation_runs", "count"}, {"continuation_bracket", length}, {"seconds", "s"},
                    {"seeds", {{"initial_position", length}, {"initial_velocity", velocity}, {"orbits", "count"},
                               {"grid_phase", "rad"}, {"grid_amplitude", length}}}}}}}};
  CommandOutput out(p, capture, "tapping orbit");
  out.open(orbit_table(scales)).add_all(r.orbits);
  if (p.flag("json")) {
    out.finish(summary, "");
    return;
  }
  // lengths by magnitude in physical units, said to be normalised otherwise (docs/units.md#summaries)
  const auto len = [&](double model_length) { return io::summary_value(model_length * scales.length, length, 6); };
  fmt::print("separation {}: {} HB solution(s), {} periodic orbit(s); phases in rad\n",
             io::summary_value(p.real("separation"), length, 6), hb.size(), r.orbits.size());
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
  if (status.status != "ok") fmt::print("  {}\n", status.note);
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
  out.finish(summary, "");
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
      run_orbit);
}

}  // namespace afmkit::cli
