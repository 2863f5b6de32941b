// afmkit tapping fm: the FM-AFM forward model — the self-excited cantilever at constant amplitude with an ideal
// phase-locked loop, frequency shift and drive (dissipation) along an approach (docs/theory-tapping.md#fm-afm).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/tapping/fm.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "tapping_fm_params.hpp"
#include "tapping_params.hpp"
#include "tapping_sim_params.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
/// The FM table's units: physical (nm, Hz, J, nN) or normalised (L, cycles per t, L²/t², L/t²), each converting
/// a model quantity into the user's unit (afmkit/core/units.hpp).
struct FmUnits {
  bool physical;
  TappingUnits t;         // length, force
  units::Unit frequency;  // ω [rad/t] -> f
  units::Unit energy;     // the model's energy -> J (aJ per model unit, in J) or L^2/t^2
  units::Unit energy_ev;  // the same in eV
  FmUnits(bool physical_units, const TappingScales& s)
      : physical(physical_units),
        t(s),
        frequency{physical ? "Hz" : "1/t", 1.0 / (2.0 * std::numbers::pi * s.time)},
        energy{physical ? "J" : s.energy_unit, physical ? s.energy * units::si_unit("aJ").to_si : 1.0},
        energy_ev{"eV", energy.multiply, units::si_unit("eV").to_si} {}
};

/// A value of the orbit at a point, nan where Newton found none.
template <class F>
auto of_orbit(F value) {
  return [value](const tapping::FmPoint& pt) { return pt.orbit ? value(*pt.orbit) : kNan; };
}

/// The FM table, one row per target (`wn`: ω_n of the model; `at_gap`: the targets are gaps at the lower turning
/// point): a point without an orbit has its target in its column, nan elsewhere and no flags.
io::TableOf<tapping::FmPoint> fm_table(const FmUnits& u, double wn, bool at_gap) {
  using P = tapping::FmPoint;
  using O = tapping::FmOrbit;
  const units::Unit& L = u.t.length;
  const bool physical = u.physical;
  return {{"separation", L, "separation l: rest position of the tip above the sample surface",
           [at_gap](const P& p) { return p.orbit ? p.orbit->separation : at_gap ? kNan : p.separation; }},
          {"min_gap", L, "tip-sample distance at the lower turning point (smallest gap x + l over the cycle)",
           [at_gap](const P& p) { return p.orbit ? p.orbit->metrics.min_gap : at_gap ? p.separation : kNan; }},
          {"frequency_shift", u.frequency, "frequency shift Δf = f − f0 of the oscillation (f0: the free resonance)",
           of_orbit([](const O& o) { return o.frequency_shift(); })},
          {"relative_frequency_shift", "dimensionless", "Δf/f0",
           of_orbit([wn](const O& o) { return o.frequency_shift() / wn; })},
          {"frequency", u.frequency, "oscillation frequency f held by the phase-locked loop",
           of_orbit([](const O& o) { return o.state.frequency; })},
          {"drive_ratio", "dimensionless", "drive amplitude over the free cantilever's drive at the same amplitude",
           of_orbit([](const O& o) { return o.drive_ratio(); })},
          {"dissipation", u.energy, "energy taken by the tip-sample force per cycle (−∫ F dz; = drive work − viscous loss)",
           of_orbit([](const O& o) { return o.tip_dissipation(); })},
          {"dissipation_ev", u.energy_ev, "the same in eV (nan in normalised units)",
           of_orbit([physical](const O& o) { return physical ? o.tip_dissipation() : kNan; })},
          {"peak_force", u.t.force, "largest tip-sample force over the cycle (positive: repulsive)",
           of_orbit([](const O& o) { return o.metrics.peak_force; })},
          {"offset", L, "mean deflection of the tip over the cycle", of_orbit([](const O& o) { return o.metrics.offset; })},
          {"amplitude", L, "first-harmonic amplitude of the deflection (= the setpoint A at convergence)",
           of_orbit([](const O& o) { return o.metrics.amplitude; })},
          {"harmonic_2", L, "amplitude of the 2nd harmonic of the deflection",
           of_orbit([](const O& o) { return o.metrics.harmonics[0]; })},
          {"contact_fraction", "dimensionless", "fraction of the cycle with the gap below the law's contact gap",
           of_orbit([](const O& o) { return o.metrics.contact_fraction; })},
          {"floquet_max", "dimensionless", "largest Floquet multiplier modulus with the drive frozen (loops held)",
           of_orbit([](const O& o) { return o.floquet_max; })},
          {"stable", "boolean (0/1)", "1: floquet_max < 1", [](const P& p) { return p.orbit && p.orbit->stable; }},
          {"jumped", "boolean (0/1)", "1: reached past a fold of the branch in the separation (another branch, as an "
                                      "instrument's loops would jump)",
           [](const P& p) { return p.orbit && p.jumped; }},
          {"newton_iterations", "count", "Newton iterations of the FM orbit",
           [](const P& p) { return p.orbit ? static_cast<long>(p.orbit->iterations) : 0L; }},
          {"residual", "dimensionless", "largest scaled residual of the four FM conditions",
           of_orbit([](const O& o) { return o.residual; })},
          {"status", "label", "ok, or no_orbit: Newton found no FM orbit here (values nan)",
           [](const P& p) { return tapping::fm_status_name(p.status); }}};
}

void run_fm(const io::ParamSet& p, Captured* capture) {
  reject_keys_not_for_fm(p);
  const tapping::TappingModel base = tapping_model_from(p, law_object_of(capture));
  const FmUnits u(p.text("units") == "physical", tapping_scales_from(p));
  const std::vector<double> separations = fm_separations(p, u.t.length);
  memory::require_fits("points", static_cast<double>(separations.size()), sizeof(tapping::FmPoint));
  const tapping::FmSetting setting(base.cantilever, base.law, fm_amplitude(p, u.t.length));
  tapping::FmSweepOptions options;
  options.fm.shooting = shooting_options_from(p);
  options.max_bisections = static_cast<int>(p.integer("max_bisections"));
  const bool at_gap = p.text("axis") == "min_gap";
  options.axis = at_gap ? tapping::FmAxis::min_gap : tapping::FmAxis::separation;
  options.jumps = p.flag("jumps");
  options.cancellation = cancellation_of(capture);
  const bool quiet = p.flag("json") || p.flag("quiet");
  io::Progress progress("tapping fm", static_cast<long>(separations.size()), !quiet);
  options.progress = [&progress](long n) { progress.advance(n); };
  options.validate();  // the input; what is refused inside was computed (core/computed.hpp)
  const tapping::FmSweepResult r =
      computed("FM orbits along the approach", [&] { return tapping::sweep_fm(setting, separations, options); });
  progress.finish();

  CommandOutput out(p, capture, "tapping fm");
  out.open(fm_table(u, base.cantilever.natural_frequency, at_gap)).add_all(r.points);
  const double wn = base.cantilever.natural_frequency;
  const long n = static_cast<long>(r.points.size()), converged = r.converged();
  const std::string note =
      converged == 0 ? fmt::format("no FM orbit: Newton converged at none of the {} {} (from the free oscillation at "
                                   "the largest, with up to {} bisections of each step)",
                                   n, at_gap ? "turning-point gaps" : "separations", options.max_bisections)
      : converged < n ? fmt::format("no FM orbit at {} of {} separations (rows with status no_orbit)", n - converged, n)
                      : std::string();
  UnitTagged results;
  results.add("amplitude", setting.amplitude, u.t.length)
      .add("resonance_frequency", wn, u.frequency)
      .add("rows", n, "count")
      .add("converged_rows", converged, "count")
      .add("jumped_rows", std::count_if(r.points.begin(), r.points.end(), [](const auto& q) { return q.jumped; }),
           "count")
      .add("no_orbit_rows", n - converged, "count")
      .add("evaluations", r.evaluations, "count")
      .add("failed_attempts", r.failed_attempts, "count")
      .add("seconds", r.seconds, "s")
      .add("seconds_per_separation", n > 0 ? r.seconds / static_cast<double>(n) : kNan, "s")
      .add("status", converged > 0 ? "ok" : "no_orbit")
      .add("note", note);
  // summary: the closest point reached
  std::string summary;
  const tapping::FmPoint* last = nullptr;
  for (const auto& pt : r.points)
    if (pt.orbit) last = &pt;
  auto length = [&](double v) { return u.physical ? io::quantity(u.t.length(v), u.t.length.name) : fmt::format("{:.6g} L", v); };
  if (last) {
    const auto& o = *last->orbit;
    summary = fmt::format(
        "FM approach at amplitude {}: {} of {} separations converged ({} one-period simulations, {} per separation)\n"
        "closest: separation {}, turning point {}: Δf = {} (Δf/f0 = {:.4g}), drive ratio {:.6g}, dissipation {}",
        length(setting.amplitude), converged, n, r.evaluations,
        io::quantity(results.values().at("seconds_per_separation").get<double>(), "s"),
        length(o.separation), length(o.metrics.min_gap),
        u.physical ? io::quantity(u.frequency(o.frequency_shift()), u.frequency.name)
                   : fmt::format("{:.6g} {}", u.frequency(o.frequency_shift()), u.frequency.name),
        o.frequency_shift() / wn, o.drive_ratio(),
        u.physical ? fmt::format("{} ({:.4g} {})", io::quantity(u.energy(o.tip_dissipation()), u.energy.name),
                                 u.energy_ev(o.tip_dissipation()), u.energy_ev.name)
                   : fmt::format("{:.6g} {}", u.energy(o.tip_dissipation()), u.energy.name));
  }
  if (!note.empty()) {
    if (!summary.empty()) summary += '\n';
    summary += note;
  }
  out.finish(results.with_units(), summary);
}

}  // namespace

void register_tapping_fm(CLI::App& tapping) {
  add_command(
      tapping, "fm",
      "FM-AFM forward model: self-excited cantilever at constant amplitude (ideal PLL): frequency shift and "
      "dissipation along an approach, from exact periodic orbits",
      [](io::ParamSet& p) {
        add_tapping_model_params(p);
        add_tapping_sim_params(p);
        add_tapping_fm_params(p);
        add_output_params(p, "out/tapping_fm.csv", "FM approach");
        add_quiet_flag(p);
      },
      run_fm);
}

}  // namespace afmkit::cli
