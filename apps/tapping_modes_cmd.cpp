// afmkit tapping modes: a cantilever with two or three flexural eigenmodes (bimodal AM-AFM), excited at one or two
// frequencies, directly or through its base, in air or in a liquid: the amplitude and phase of every mode along an
// approach, by time-domain simulation with event location and a lock-in over whole periods
// (docs/theory-tapping.md#more-than-one-eigenmode).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/tapping/modal_response.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "tapping_params.hpp"
#include "unit_tagged.hpp"
#include "work_budget.hpp"

namespace afmkit::cli {

namespace {

using io::Range;
constexpr double kModesNan = std::numeric_limits<double>::quiet_NaN();
/// A lower bound of the time of one step of the multi-mode simulation (adaptive: at least 24 steps per period of
/// the fastest mode or drive; measured 7.6e-7 s per step with two modes on the 2-core test machine, Release).
constexpr double kModalStepSeconds = 2e-7;

void add_modes_params(io::ParamSet& p) {
  p.recorded_only_if_given("separation");  // refused: the approach is separation_min .. separation_max
  p.group("Eigenmodes (docs/theory-tapping.md#more-than-one-eigenmode)")
      .integer("modes", 2, "flexural eigenmodes of the cantilever (1 to 3)", 1, 3)
      .reals("mode_frequency_ratios", {}, "f_i/f_1 of the higher modes, one per higher mode, increasing, > 1",
             {1.0, 1e4, true, false})
      .unit("dimensionless")
      .default_text("Euler-Bernoulli beam: 6.2669, 17.547")
      .reals("mode_stiffness_ratios", {}, "k_i/k_1 of the higher modes, one per higher mode",
             {0.0, 1e12, true, false})
      .unit("dimensionless")
      .default_text("(f_i/f_1)^2: equal modal masses, as the uniform beam (39.27, 307.9 with its frequencies)")
      .reals("mode_quality_factors", {}, "quality factors Q_i of the higher modes, one per higher mode",
             {0.0, 1e9, true, false})
      .unit("dimensionless")
      .default_text("quality_factor * f_i/f_1 (the same viscous damping on every mode)")
      .text("excitation", "direct", "direct: a force at the tip; base: the base moves (acoustic excitation)",
            {"direct", "base"})
      .real("second_free_amplitude", 0.0,
            "free amplitude of mode 2 at the second drive frequency (bimodal AM-AFM; 0: one drive)",
            Range::closed(0.0, 1e6))
      .unit(kLengthUnit)
      .real("second_frequency_ratio", 1.0, "second drive frequency over the frequency of mode 2 (in the medium)",
            {0.0, 1e3, true, false})
      .unit("dimensionless")
      .real("added_mass_ratio", 0.0, "liquid: added mass of the fluid over the modal mass (0: air)",
            Range::closed(0.0, 1e6))
      .unit("dimensionless")
      .real("fluid_quality_factor", 0.0,
            "liquid: quality factor of mode 1 from the fluid damping alone (0: no fluid damping)",
            Range::closed(0.0, 1e9))
      .unit("dimensionless")
      .group("Approach");
  add_separation_range_params(p, 5.0, 12.0);
  add_separation_points_param(p, 8, 1, 10000000, "separations of the approach (1: separation_max only)");
  p.integer("settle_periods", 0,
            "drive periods simulated at each separation before the lock-in (0: automatic, 2 Q_i f_drive/f_i at "
            "least: every transient decays by exp(-2 pi))",
            0, 100000000)
      .integer("lockin_periods", 20, "drive periods of the lock-in window (whole periods of each drive)", 1, 10000000)
      .flag("periodic", false,
            "after the settling, solve the periodic orbit by shooting and measure on it (the drives must be "
            "commensurate: one drive, or f_b/f_a = n2/n1 with n1, n2 <= 64)");
}

/// The higher modes' ratio list `key`: empty (default) or one value per higher mode.
std::vector<double> modes_ratio_list(const io::ParamSet& p, const std::string& key, int modes) {
  std::vector<double> v = p.reals(key);
  if (!v.empty() && static_cast<int>(v.size()) != modes - 1)
    throw InvalidParameter(key, fmt::format("{} holds {} value(s): give one per higher mode (modes = {}: {})", key,
                                            v.size(), modes, modes - 1));
  return v;
}

tapping::MultiModeModel modes_model(const io::ParamSet& p, const tapping::TappingModel& single) {
  if (p.was_set("separation"))
    throw InvalidParameter("separation", "separation does not apply to tapping modes: give separation_min and "
                                         "separation_max (the approach)");
  const int modes = static_cast<int>(p.integer("modes"));
  const auto& c = single.cantilever;
  std::vector<double> f = modes_ratio_list(p, "mode_frequency_ratios", modes);
  std::vector<double> k = modes_ratio_list(p, "mode_stiffness_ratios", modes);
  std::vector<double> q = modes_ratio_list(p, "mode_quality_factors", modes);
  for (std::size_t i = 1; i < f.size(); ++i)
    if (!(f[i] > f[i - 1]))
      throw InvalidParameter("mode_frequency_ratios", fmt::format("mode_frequency_ratios must increase: {} follows {}",
                                                                  f[i], f[i - 1]));
  std::vector<tapping::Eigenmode> list = tapping::euler_bernoulli_modes(c, modes, q);
  for (int i = 1; i < modes; ++i) {
    const double fr = f.empty() ? list[i].natural_frequency / c.natural_frequency : f[i - 1];
    const double kr = !k.empty() ? k[i - 1] : f.empty() ? std::pow(tapping::euler_bernoulli_eigenvalue(i + 1) /
                                                                       tapping::euler_bernoulli_eigenvalue(1), 4)
                                                        : fr * fr;
    const double qi = q.empty() ? c.quality_factor * fr : q[i - 1];  // the same viscous damping on every mode
    list[i] = tapping::Eigenmode::from_ratios(c, fr, kr, qi, list[i].participation);
  }
  const tapping::Excitation excitation =
      p.text("excitation") == "base" ? tapping::Excitation::base : tapping::Excitation::direct;
  tapping::Medium medium;
  medium.added_mass_ratio = p.real("added_mass_ratio");
  if (p.real("fluid_quality_factor") > 0) medium.fluid_quality_factor = p.real("fluid_quality_factor");
  // drive 1: the single-mode drive (the free amplitude of mode 1 at the drive frequency); its frequency is the
  // ratio times mode 1's frequency in the medium
  const double w1 = c.natural_frequency / std::sqrt(1.0 + medium.added_mass_ratio);
  const double wa = single.drive.frequency / c.natural_frequency * w1;
  std::vector<tapping::Drive> drives;
  if (excitation == tapping::Excitation::direct && medium.vacuum()) {
    drives.push_back(single.drive);  // bit for bit the single-mode drive
  } else {
    const double a1 = single.free_amplitude();
    drives.emplace_back(tapping::drive_for_mode_amplitude(list, excitation, medium, 0, wa, a1), wa);
  }
  const double a2 = TappingUnits(tapping_scales_from(p)).length.internal(p.real("second_free_amplitude"));
  if (a2 > 0) {
    if (modes < 2)
      throw InvalidParameter("second_free_amplitude", "second_free_amplitude drives mode 2: it needs modes >= 2");
    const double wb = p.real("second_frequency_ratio") * list[1].natural_frequency /
                      std::sqrt(1.0 + medium.added_mass_ratio);
    drives.emplace_back(tapping::drive_for_mode_amplitude(list, excitation, medium, 1, wb, a2), wb);
    // the lock-in must tell the two drives apart: at least one beat over its window
    const double window = static_cast<double>(p.integer("lockin_periods")) * drives[0].period();
    if (!(std::abs(wb - wa) * window >= 2.0 * std::numbers::pi))
      throw InvalidParameter("second_frequency_ratio",
                             fmt::format("second_frequency_ratio = {}: the second drive ({:.6g} rad/t) is within one "
                                         "beat of the first ({:.6g} rad/t) over the lock-in window of lockin_periods "
                                         "= {} periods; the lock-in cannot separate them",
                                         p.real("second_frequency_ratio"), wb, wa, p.integer("lockin_periods")));
  }
  return {list, drives, excitation, medium, single.law, single.separation};
}

std::vector<double> modes_approach(const io::ParamSet& p, const units::Unit& length) {
  const double lo = p.real("separation_min"), hi = p.real("separation_max");
  if (!(lo <= hi))
    throw InvalidParameter("separation_min",
                           fmt::format("separation_min = {} is out of range: must be <= separation_max = {}", lo, hi));
  const long n = p.integer("points");
  std::vector<double> list;
  for (long i = 0; i < n; ++i)
    list.push_back(length.internal(n == 1 ? hi : hi - (hi - lo) * static_cast<double>(i) / static_cast<double>(n - 1)));
  return list;
}

/// The table, one row per separation: `m` modes, `nd` drives (columns of absent modes or drives: nan).
io::TableOf<tapping::ModalResponse> modes_table(const TappingUnits& u, int m, int nd) {
  using R = tapping::ModalResponse;
  using E = tapping::ModeEnergy;
  const units::Unit& L = u.length;
  const int d2 = nd > 1 ? 1 : 0;
  const auto amp = [m, nd](int i, int d) {
    return [m, nd, i, d](const R& pt) { return i < m && d < nd ? pt.mode[i][d].amplitude : kModesNan; };
  };
  const auto ph = [m, nd](int i, int d) {
    return [m, nd, i, d](const R& pt) { return i < m && d < nd ? pt.mode[i][d].phase : kModesNan; };
  };
  const auto work = [m](int i, double E::*field) {
    return [m, i, field](const R& pt) { return i < m ? pt.energy[i].*field : kModesNan; };
  };
  return {{"separation", L, "separation l: rest position of the tip above the sample surface", &R::separation},
          {"min_gap", L, "smallest tip-sample distance over the lock-in window (sampled)", &R::min_gap},
          {"peak_force", u.force, "largest tip-sample force over the window (sampled; positive: repulsive)",
           &R::peak_force},
          {"offset", L, "mean tip position over the window", &R::mean},
          {"amplitude_1", L, "amplitude of mode 1 at drive 1", amp(0, 0)},
          {"phase_1", "rad", "phase lag of mode 1 at drive 1 (pi/2: free, at resonance)", ph(0, 0)},
          {"amplitude_2", L, "amplitude of mode 2 at drive 2 (at drive 1 with one drive; nan with one mode)",
           amp(1, d2)},
          {"phase_2", "rad", "phase lag of mode 2 at drive 2 (at drive 1 with one drive): the bimodal observable",
           ph(1, d2)},
          {"amplitude_3", L, "amplitude of mode 3 at drive 1 (nan with fewer modes)", amp(2, 0)},
          {"phase_3", "rad", "phase lag of mode 3 at drive 1", ph(2, 0)},
          {"tip_amplitude_1", L, "amplitude of the tip (sum of the modes, base motion included) at drive 1",
           [](const R& pt) { return pt.tip[0].amplitude; }},
          {"tip_phase_1", "rad", "phase lag of the tip at drive 1", [](const R& pt) { return pt.tip[0].phase; }},
          {"tip_amplitude_2", L, "amplitude of the tip at drive 2 (nan with one drive)",
           [nd](const R& pt) { return nd > 1 ? pt.tip[1].amplitude : kModesNan; }},
          {"tip_phase_2", "rad", "phase lag of the tip at drive 2",
           [nd](const R& pt) { return nd > 1 ? pt.tip[1].phase : kModesNan; }},
          {"drive_work_1", u.energy, "work of the drive on mode 1 over the window", work(0, &E::drive_work)},
          {"drive_work_2", u.energy, "work of the drive on mode 2 over the window", work(1, &E::drive_work)},
          {"drive_work_3", u.energy, "work of the drive on mode 3 over the window", work(2, &E::drive_work)},
          {"damping_loss_1", u.energy, "energy lost to the damping of mode 1 over the window",
           work(0, &E::damping_loss)},
          {"damping_loss_2", u.energy, "energy lost to the damping of mode 2", work(1, &E::damping_loss)},
          {"damping_loss_3", u.energy, "energy lost to the damping of mode 3", work(2, &E::damping_loss)},
          {"tip_work_1", u.energy, "work of the tip-sample force on mode 1 (negative: the sample takes energy)",
           work(0, &E::tip_work)},
          {"tip_work_2", u.energy, "work of the tip-sample force on mode 2", work(1, &E::tip_work)},
          {"tip_work_3", u.energy, "work of the tip-sample force on mode 3", work(2, &E::tip_work)},
          {"energy_residual", u.energy,
           "largest |drive work - damping loss + tip work - change of stored energy| of a mode (the energy balance; "
           "integration error)",
           [m](const R& pt) {
             double residual = 0.0;
             for (int i = 0; i < m; ++i) residual = std::max(residual, std::abs(pt.energy[i].residual()));
             return residual;
           }},
          {"impacts", "count", "entries into contact during the window and the settling before it",
           [](const R& pt) { return pt.stats.impacts; }},
          {"periodic", "boolean (0/1)", "1: measured on a periodic orbit found by shooting (--periodic)",
           &R::periodic}};
}

void run_modes(const io::ParamSet& p, Captured* capture) {
  const tapping::TappingModel single = tapping_model_from(p, law_object_of(capture));
  const TappingUnits u(tapping_scales_from(p));
  const tapping::MultiModeModel model = modes_model(p, single);
  const std::vector<double> separations = modes_approach(p, u.length);
  tapping::ModalResponseOptions options;
  options.settle_periods = p.integer("settle_periods");
  options.lockin_periods = p.integer("lockin_periods");
  options.periodic = p.flag("periodic");
  options.validate();
  if (options.periodic) {
    try {
      (void)tapping::common_period(model);
    } catch (const InvalidParameter& e) {
      throw InvalidParameter("second_frequency_ratio", fmt::format("periodic needs commensurate drives: {}", e.what()));
    }
  }
  const double periods = static_cast<double>(options.settle_periods_for(model) + options.lockin_periods);
  memory::require_fits("points", static_cast<double>(separations.size()), sizeof(tapping::ModalResponse));
  double fastest = 0.0;  // the scan step is 1/24 of the shortest period present
  for (int i = 0; i < model.mode_count(); ++i) fastest = std::max(fastest, model.frequency(i));
  for (const auto& d : model.drives) fastest = std::max(fastest, d.frequency);
  const double steps_per_period = 24.0 * fastest / model.drives[0].frequency;
  const double estimate = require_work(
      "points", static_cast<double>(separations.size()), periods * steps_per_period * kModalStepSeconds,
      fmt::format("points x {} drive periods (settle_periods + lockin_periods) x {:.4g} steps per period (24 per "
                  "period of the fastest mode or drive)",
                  periods, steps_per_period));
  const bool quiet = p.flag("json") || p.flag("quiet");
  io::Progress progress("tapping modes", static_cast<long>(separations.size()),
                        !quiet && estimate > kProgressAfterSeconds);
  const std::vector<tapping::ModalResponse> r = computed("the multi-mode approach", [&] {
    return tapping::modal_sweep(model, separations, options, [&progress](long n) { progress.advance(n); });
  });
  progress.finish();

  const bool physical = p.text("units") == "physical";
  CommandOutput out(p, capture, "tapping modes");
  const int m = model.mode_count(), nd = model.drive_count();
  out.open(modes_table(u, m, nd)).add_all(r);
  double worst_residual = 0.0;  // in the model's energy unit
  for (const tapping::ModalResponse& pt : r)
    for (int i = 0; i < m; ++i) worst_residual = std::max(worst_residual, std::abs(pt.energy[i].residual()));
  // ω [rad/t] -> f (Hz, or cycles per t)
  const units::Unit frequency{physical ? "Hz" : "1/t", 1.0, 2.0 * std::numbers::pi * u.time.multiply};
  std::vector<double> frequencies, quality, free_amplitudes;  // in the model's units
  for (int i = 0; i < m; ++i) {
    frequencies.push_back(model.frequency(i));
    quality.push_back(model.quality_factor(i));
    free_amplitudes.push_back(std::abs(model.free_response(i, i < nd ? i : 0)));
  }
  UnitTagged results;
  results.add("modes", m, "count")
      .add("drives", nd, "count")
      .add("excitation", tapping::excitation_name(model.excitation))
      .add("mode_frequencies", frequencies, frequency)
      .add("mode_quality_factors", quality, "dimensionless")
      .add("free_amplitudes", free_amplitudes, u.length)
      .add("settle_periods", options.settle_periods_for(model), "count")
      .add("rows", static_cast<long>(r.size()), "count")
      .add("largest_energy_residual", worst_residual, u.energy)
      .add("periodic_rows", std::count_if(r.begin(), r.end(), [](const auto& q) { return q.periodic; }), "count")
      .add("status", "ok");
  std::string summary = fmt::format("{} modes ({} excitation, {} drive{}), {} separations", m,
                                    tapping::excitation_name(model.excitation), nd, nd > 1 ? "s" : "", r.size());
  if (!r.empty()) {
    const auto& last = r.back();
    const int d2 = nd > 1 ? 1 : 0;
    summary += fmt::format("\nclosest, separation {}: A1 = {}, phase1 = {:.4f} rad",
                           summary_value(last.separation, u.length),
                           summary_value(last.mode[0][0].amplitude, u.length), last.mode[0][0].phase);
    if (m > 1)
      summary += fmt::format(", A2 = {}, phase2 = {:.4f} rad",
                             summary_value(last.mode[1][d2].amplitude, u.length),
                             last.mode[1][d2].phase);
  }
  out.finish(results.with_units(), summary);
}

}  // namespace

void register_tapping_modes(CLI::App& tapping) {
  add_command(
      tapping, "modes",
      "Multi-mode cantilever (2-3 eigenmodes, bimodal AM-AFM): amplitude and phase of every mode along an approach, "
      "direct or base excitation, in air or liquid",
      [](io::ParamSet& p) {
        add_tapping_model_params(p);
        add_modes_params(p);
        add_output_params(p, "out/tapping_modes.csv", "multi-mode approach");
        add_quiet_flag(p);
      },
      run_modes);
}

}  // namespace afmkit::cli
