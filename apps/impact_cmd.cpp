// afmkit impact: one two-body impact with a hysteresis force law (seed-1 §II, eqs. 1–6; docs/theory-tapping.md#impact).
// Prints a summary (or the result as JSON with --json); --output FILE writes the time history as CSV
// (t, gap, gap_rate, force, x1, v1, x2, v2) with a JSON sidecar holding the parameters and the summary.
//
// Units (docs/units.md): gaps and positions in nm, forces in nN, masses in kg, speeds in nm/s, times in s, energies
// in aJ (1 nN · 1 nm = 1e-18 J; 1 nN / 1 kg = 1 nm/s², so the set is consistent), stiffnesses in N/m (= nN/nm).
// The piecewise-linear laws work in any consistent set; the others need this one (E* in GPa, R in nm, A_H in J).
#include <sys/statvfs.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/impact.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/quantity.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "described_params.hpp"
#include "law_params.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

using io::Range;

std::vector<io::Column> history_columns() {
  return {{"t", "s", "time"},
          {"gap", "nm", "gap d = x2 - x1"},
          {"gap_rate", "nm/s", "gap rate dd/dt"},
          {"force", "nN", "interaction force on body 2 (positive: repulsive)"},
          {"x1", "nm", "position of body 1"},
          {"v1", "nm/s", "velocity of body 1"},
          {"x2", "nm", "position of body 2"},
          {"v2", "nm/s", "velocity of body 2"}};
}

void add_impact_params(io::ParamSet& p) {
  p.group("Bodies");
  p.real("mass1", 1.0, "mass m1 of the lower body", Range::positive())
      .unit("kg")
      .real("mass2", 1.0, "mass m2 of the upper body", Range::positive())
      .unit("kg")
      .real("velocity", 1.0,
            "relative approach speed -(v2 - v1) > 0, centre of mass at rest; or give v1, v2", Range::positive())
      .unit("nm/s")
      .real("v1", 0.0, "initial velocity of body 1 (instead of velocity; needs v2 - v1 < 0)", Range::any())
      .unit("nm/s")
      .only_if_given({"velocity"})  // the record holds velocity, or v1 and v2, as the run used them
      .real("v2", 0.0, "initial velocity of body 2 (instead of velocity)", Range::any())
      .unit("nm/s")
      .only_if_given({"velocity"})
      .real("gap", 1.0, "initial gap d(t_s) = x2 - x1; contact below the law's contact gap (0, or a0)", Range::any())
      .unit("nm")
      .real("force1", 0.0, "constant external force F1 on body 1 (seed-1 eq. 1)", Range::any())
      .unit("nN")
      .real("force2", 0.0, "constant external force F2 on body 2", Range::any())
      .unit("nN")
      .group("Numerics");
  declare_fields(p, impact::ImpactOptions{});  // method, relative_tolerance, absolute_tolerance
  p.integer("points", 400, "time-history samples written with --output (>= 2; events are added)", 2, 10000000);
  add_output_params(p, "", "time history");
  add_law_params(p, impact::LawRegistry::builtin(), "hysteresis");
}

void reject_foreign_keys(const io::ParamSet& p) {
  if (p.was_set("velocity") && (p.was_set("v1") || p.was_set("v2")))
    throw InvalidParameter("velocity", "give either velocity (relative approach speed) or v1 and v2, not both");
}

impact::ImpactProblem problem_from(const io::ParamSet& p, const Captured* capture) {
  reject_foreign_keys(p);
  const double m1 = p.real("mass1"), m2 = p.real("mass2"), total = m1 + m2, gap = p.real("gap");
  if (!std::isfinite(total))
    throw InvalidParameter("mass1", fmt::format("mass1 = {} is out of range: must be such that mass1 + mass2 is finite "
                                                "(mass2 = {}); rescale the mass unit",
                                                m1, m2));
  double v1 = 0, v2 = 0;
  if (p.was_set("v1") || p.was_set("v2")) {
    v1 = p.real("v1");
    v2 = p.real("v2");
  } else {  // centre of mass at rest
    v1 = m2 / total * p.real("velocity");
    v2 = -m1 / total * p.real("velocity");
  }
  impact::ExternalForces ext;
  ext.on_body1 = p.real("force1");
  ext.on_body2 = p.real("force2");
  return {{m1, -m2 / total * gap, v1}, {m2, m1 / total * gap, v2}, law_from_params(p, impact::LawRegistry::builtin(), {}, law_object_of(capture)), ext};
}

/// A body after the impact (mass in kg, position in nm, velocity in nm/s: the units the problem was given in).
UnitTagged body_record(const impact::Body& b) {
  UnitTagged j;
  j.add("mass", b.mass, "kg").add("position", b.position, "nm").add("velocity", b.velocity, "nm/s");
  return j;
}

/// The results, each with its unit (the problem's units: nm, nN, kg, nm/s, s, aJ = nN·nm; values as computed).
nlohmann::json result_json(const impact::ImpactResult& r, const impact::ForceLaw& law) {
  UnitTagged j;
  j.add("outcome", impact::to_string(r.outcome))
      .add("method", r.method)
      .add("law", law.name())
      .add("reduced_mass", r.reduced_mass, "kg")
      .add("start_time", r.start_time, "s")
      .add("minimum_time", r.minimum_time, "s")
      .add("end_time", r.end_time, "s")
      .add("reference_gap", r.reference_gap, "nm")
      .add("minimum_gap", r.minimum_gap, "nm")
      .add("contact_gap", r.contact_gap, "nm")
      .add("max_penetration", r.max_penetration, "nm")
      .add("contact", r.contact, "boolean (0/1)")
      .add("contact_start", r.contact_start, "s")
      .add("contact_end", r.contact_end, "s")
      .add("contact_duration", r.contact_duration, "s")
      .add("approach_gap_rate", r.approach_gap_rate, "nm/s")
      .add("departure_gap_rate", r.departure_gap_rate, "nm/s")
      .add("restitution", r.restitution, "dimensionless")
      .add("restitution_deficit", r.restitution_deficit, "dimensionless")
      .add("kinetic_energy_before", r.kinetic_energy_before, "aJ")
      .add("kinetic_energy_after", r.kinetic_energy_after, "aJ")
      .add("kinetic_energy_loss", r.kinetic_energy_loss, "aJ")
      .add("energy_loss_restitution", r.energy_loss_restitution, "aJ")
      .add("energy_loss_area", r.energy_loss_area, "aJ")
      .add("energy_balance_residual", r.energy_balance_residual, "aJ")
      .add("peak_force", r.peak_force, "nN")
      .add("min_force", r.min_force, "nN")
      .add("body1_after", body_record(r.body1_after))
      .add("body2_after", body_record(r.body2_after))
      .add("steps", r.steps, "count")
      // written for a linear law without adhesion only (below); its unit listed always
      .unit("restitution_impulsive_limit", "dimensionless");
  if (r.outcome == impact::ImpactOutcome::captured) j.add("capture_reason", r.capture_reason);
  if (const auto* lin = law.piecewise_linear();
      lin && lin->approach_stiffness > 0 && lin->approach_adhesion == 0 && lin->departure_adhesion == 0)
    j.add("restitution_impulsive_limit", std::sqrt(lin->departure_stiffness / lin->approach_stiffness),  // ext. E0
          "dimensionless");
  return std::move(j).summary();  // NaN (undefined quantities) is written as null
}

/// Refuse (exit 2) before any work when the CSV would not fit on the disk: each row holds 8 numbers of at
/// most 24 characters (shortest round-trip form) plus separators.
void check_disk_space(const std::string& output, long points) {
  namespace fs = std::filesystem;
  const double need = (static_cast<double>(points) + 16.0) * 8.0 * 25.0;
  fs::path dir = fs::absolute(fs::path(output)).parent_path();
  while (!dir.empty() && !fs::exists(dir) && dir != dir.root_path()) dir = dir.parent_path();  // created later
  struct statvfs fsinfo {};
  if (::statvfs(dir.c_str(), &fsinfo) == 0 && (fsinfo.f_flag & ST_RDONLY) != 0)  // not "0 GB free"
    throw InvalidParameter("output", fmt::format("output '{}' cannot be written: '{}' is on a read-only file system",
                                                 output, dir.string()));
  std::error_code ec;
  const fs::space_info space = fs::space(dir, ec);
  if (!ec && need > static_cast<double>(space.available))
    throw InvalidParameter("points", fmt::format("points = {} writes up to {:.3g} GB to '{}' but only {:.3g} GB are "
                                                 "free there; use fewer points",
                                                 points, need / 1e9, output, static_cast<double>(space.available) / 1e9));
}

void print_summary(const impact::ImpactResult& r, const impact::ForceLaw& law) {
  // lengths, times, speeds, forces and energies with the SI prefix of their magnitude (docs/units.md#summaries);
  // undefined: nan (docs/conventions.md)
  auto q = [](double v, const char* unit) { return io::quantity(v, unit, 10); };
  auto num = [](double v) { return std::isnan(v) ? std::string("nan") : fmt::format("{:.10g}", v); };
  fmt::print("impact ({} law, {}): {}\n", law.name(), r.method, impact::to_string(r.outcome));
  if (r.outcome == impact::ImpactOutcome::captured) fmt::print("  capture: {}\n", r.capture_reason);
  fmt::print("  reduced mass               {} kg\n", num(r.reduced_mass));
  fmt::print("  gap d(t_s) -> minimum      {} -> {} (max penetration {})\n", q(r.reference_gap, "nm"),
             q(r.minimum_gap, "nm"), q(r.max_penetration, "nm"));
  fmt::print("  times t_s, t_min, t_f      {}, {}, {}\n", q(r.start_time, "s"), q(r.minimum_time, "s"),
             q(r.end_time, "s"));
  if (r.contact)
    fmt::print("  contact                    {} .. {} (duration {})\n", q(r.contact_start, "s"), q(r.contact_end, "s"),
               q(r.contact_duration, "s"));
  else
    fmt::print("  contact                    none\n");
  fmt::print("  gap rate before / after    {} / {}\n", q(r.approach_gap_rate, "nm/s"), q(r.departure_gap_rate, "nm/s"));
  fmt::print("  restitution e (eq. 2)      {} (1 - e = {})\n", num(r.restitution), num(r.restitution_deficit));
  fmt::print("  kinetic energy loss        {} (simulated)\n", q(r.kinetic_energy_loss, "aJ"));
  fmt::print("                             {} (eq. 3, from e)\n", q(r.energy_loss_restitution, "aJ"));
  fmt::print("                             {} (eq. 6, area between branches)\n", q(r.energy_loss_area, "aJ"));
  fmt::print("  peak force / min force     {} / {}\n", q(r.peak_force, "nN"), q(r.min_force, "nN"));
  fmt::print("  after: v1 = {}, v2 = {}\n", q(r.body1_after.velocity, "nm/s"), q(r.body2_after.velocity, "nm/s"));
}

void run_impact(const io::ParamSet& p, Captured* capture) {
  const impact::ImpactProblem problem = problem_from(p, capture);
  impact::ImpactOptions options;
  read_fields(p, options);  // method, tolerances
  CommandOutput out(p, capture, "impact");
  options.history_points = out.keeps_rows() ? p.integer("points") : 0;
  if (out.writes_file()) check_disk_space(out.path(), options.history_points);

  // The history is streamed row by row into the CSV (memory does not grow with --points).
  out.open(history_columns());
  if (out.keeps_rows())
    options.on_sample = [&out](const impact::ImpactSample& s) {
      out.row(s.time, s.gap, s.gap_rate, s.force, s.position1, s.velocity1, s.position2, s.velocity2);
    };
  const impact::ImpactResult r = impact::simulate_impact(problem, options);
  if (!p.flag("json")) print_summary(r, problem.law());
  out.finish(result_json(r, problem.law()), "");
}

}  // namespace

void register_impact(CLI::App& app) {
  add_command(app, "impact",
              "two-body impact with a hysteresis force law: restitution, energy loss, contact (seed-1 eqs. 1-6)",
              add_impact_params, run_impact);
}

}  // namespace afmkit::cli
