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

namespace afmkit::cli {

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kJoulePerAttojoule = 1e-18;
constexpr double kElectronvolt = 1.602176634e-19;  // J

/// The FM table's units: physical (nm, Hz, J, nN) or normalised (L, cycles per t, L²/t², L/t²).
struct FmUnits {
  bool physical;
  TappingScales s;
  std::string frequency() const { return physical ? "Hz" : "1/t"; }
  std::string energy() const { return physical ? "J" : s.energy_unit; }
  double frequency_factor() const { return 1.0 / (2.0 * std::numbers::pi * s.time); }  // ω [rad/t] -> f
  double energy_factor() const { return physical ? s.energy * kJoulePerAttojoule : 1.0; }
};

std::vector<io::Column> fm_columns(const FmUnits& u) {
  const std::string L = u.s.length_unit;
  return {{"separation", L, "separation l: rest position of the tip above the sample surface"},
          {"min_gap", L, "tip-sample distance at the lower turning point (smallest gap x + l over the cycle)"},
          {"frequency_shift", u.frequency(), "frequency shift Δf = f − f0 of the oscillation (f0: the free resonance)"},
          {"relative_frequency_shift", "dimensionless", "Δf/f0"},
          {"frequency", u.frequency(), "oscillation frequency f held by the phase-locked loop"},
          {"drive_ratio", "dimensionless", "drive amplitude over the free cantilever's drive at the same amplitude"},
          {"dissipation", u.energy(), "energy taken by the tip-sample force per cycle (−∫ F dz; = drive work − viscous loss)"},
          {"dissipation_ev", "eV", "the same in eV (nan in normalised units)"},
          {"peak_force", u.s.force_unit, "largest tip-sample force over the cycle (positive: repulsive)"},
          {"offset", L, "mean deflection of the tip over the cycle"},
          {"amplitude", L, "first-harmonic amplitude of the deflection (= the setpoint A at convergence)"},
          {"harmonic_2", L, "amplitude of the 2nd harmonic of the deflection"},
          {"contact_fraction", "dimensionless", "fraction of the cycle with the gap below the law's contact gap"},
          {"floquet_max", "dimensionless", "largest Floquet multiplier modulus with the drive frozen (loops held)"},
          {"stable", "boolean (0/1)", "1: floquet_max < 1"},
          {"jumped", "boolean (0/1)", "1: reached past a fold of the branch in the separation (another branch, as an "
                                      "instrument's loops would jump)"},
          {"newton_iterations", "count", "Newton iterations of the FM orbit"},
          {"residual", "dimensionless", "largest scaled residual of the four FM conditions"},
          {"status", "label", "ok, or no_orbit: Newton found no FM orbit here (values nan)"}};
}

void run_fm(const io::ParamSet& p, Captured* capture) {
  reject_keys_not_for_fm(p);
  const tapping::TappingModel base = tapping_model_from(p, law_object_of(capture));
  const FmUnits u{p.text("units") == "physical", tapping_scales_from(p)};
  const std::vector<double> separations = fm_separations(p, u.s.length);
  memory::require_fits("points", static_cast<double>(separations.size()), sizeof(tapping::FmPoint));
  const tapping::FmSetting setting(base.cantilever, base.law, fm_amplitude(p, u.s.length));
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
  out.open(fm_columns(u));
  const double ff = u.frequency_factor(), ef = u.energy_factor();
  const double wn = base.cantilever.natural_frequency;
  for (const tapping::FmPoint& pt : r.points) {
    if (!pt.orbit) {
      const double target = pt.separation * u.s.length;
      out.row(at_gap ? kNan : target, at_gap ? target : kNan, kNan, kNan, kNan, kNan, kNan, kNan, kNan, kNan, kNan,
              kNan, kNan, kNan, false, false, 0L, kNan, tapping::fm_status_name(pt.status));
      continue;
    }
    const tapping::FmOrbit& o = *pt.orbit;
    const auto& m = o.metrics;
    const double e = o.tip_dissipation() * ef;
    out.row(o.separation * u.s.length, m.min_gap * u.s.length, o.frequency_shift() * ff, o.frequency_shift() / wn,
            o.state.frequency * ff, o.drive_ratio(), e, u.physical ? e / kElectronvolt : kNan, m.peak_force * u.s.force,
            m.offset * u.s.length, m.amplitude * u.s.length, m.harmonics[0] * u.s.length, m.contact_fraction,
            o.floquet_max, o.stable, pt.jumped, static_cast<long>(o.iterations), o.residual, tapping::fm_status_name(pt.status));
  }
  const long n = static_cast<long>(r.points.size()), converged = r.converged();
  nlohmann::json results;
  results["amplitude"] = setting.amplitude * u.s.length;
  results["resonance_frequency"] = wn * ff;
  results["rows"] = n;
  results["converged_rows"] = converged;
  results["jumped_rows"] = std::count_if(r.points.begin(), r.points.end(), [](const auto& q) { return q.jumped; });
  results["no_orbit_rows"] = n - converged;
  results["evaluations"] = r.evaluations;
  results["failed_attempts"] = r.failed_attempts;
  results["seconds"] = r.seconds;
  results["seconds_per_separation"] = n > 0 ? r.seconds / static_cast<double>(n) : kNan;
  results["status"] = converged > 0 ? "ok" : "no_orbit";
  results["note"] = converged == 0
                        ? fmt::format("no FM orbit: Newton converged at none of the {} {} (from the free "
                                      "oscillation at the largest, with up to {} bisections of each step)",
                                      n, at_gap ? "turning-point gaps" : "separations", options.max_bisections)
                    : converged < n ? fmt::format("no FM orbit at {} of {} separations (rows with status no_orbit)",
                                                  n - converged, n)
                                    : std::string();
  const std::string L = u.s.length_unit;
  results["units"] = {{"amplitude", L}, {"resonance_frequency", u.frequency()}, {"rows", "count"},
                      {"converged_rows", "count"}, {"jumped_rows", "count"}, {"no_orbit_rows", "count"}, {"evaluations", "count"},
                      {"failed_attempts", "count"}, {"seconds", "s"}, {"seconds_per_separation", "s"}};
  // summary: the closest point reached
  std::string summary;
  const tapping::FmPoint* last = nullptr;
  for (const auto& pt : r.points)
    if (pt.orbit) last = &pt;
  auto length = [&](double v) { return u.physical ? io::quantity(v * u.s.length, "nm") : fmt::format("{:.6g} L", v); };
  if (last) {
    const auto& o = *last->orbit;
    summary = fmt::format(
        "FM approach at amplitude {}: {} of {} separations converged ({} one-period simulations, {} per separation)\n"
        "closest: separation {}, turning point {}: Δf = {} (Δf/f0 = {:.4g}), drive ratio {:.6g}, dissipation {}",
        length(setting.amplitude), converged, n, r.evaluations, io::quantity(results["seconds_per_separation"], "s"),
        length(o.separation), length(o.metrics.min_gap),
        u.physical ? io::quantity(o.frequency_shift() * ff, "Hz") : fmt::format("{:.6g} 1/t", o.frequency_shift() * ff),
        o.frequency_shift() / wn, o.drive_ratio(),
        u.physical ? fmt::format("{} ({:.4g} eV)", io::quantity(o.tip_dissipation() * ef, "J"),
                                 o.tip_dissipation() * ef / kElectronvolt)
                   : fmt::format("{:.6g} {}", o.tip_dissipation(), u.energy()));
  }
  if (const std::string note = results["note"].get<std::string>(); !note.empty()) {
    if (!summary.empty()) summary += '\n';
    summary += note;
  }
  out.finish(results, summary);
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
