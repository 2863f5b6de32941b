// afmkit control tf: frequency response of the seed-2 controller, plant, loop, sensitivity or closed loop
// (seed-2 eqs. 10, 18, 25, 28–31) on a frequency grid, as CSV (frequency, magnitude, phase, real, imag) with a JSON
// sidecar holding the τ = 0 stability verdicts (eqs. 13, 22–24, 40–42, β_c(N)) and |S| at the harmonics.
// Units (control_params.hpp): frequency ω in units of Ω (the harmonic number at ω = kΩ); the response in the
// units of the system: the controller C in units of Ω (C/Ω), the plant P in units of 1/Ω (P·Ω), the loop,
// sensitivity and closed loop dimensionless; phase = arg G(iω) unwrapped along the grid [rad].
#include <complex>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/frequency_response.hpp"
#include "afmkit/control/stability_tau0.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/table.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "control_params.hpp"
#include "control_units.hpp"
#include "unit_tagged.hpp"
#include "work_budget.hpp"
#include "afmkit/io/progress.hpp"

namespace afmkit::cli {

namespace {
using control::ControllerKind;

// Time of one oscillator term of the frequency response: measured 1.2e-7 … 2.3e-7 s (N = 10 … 1e5, 2-core test
// machine under load, Release), taken as 5e-8 s: the work estimate is a lower bound, so only requests that
// cannot fit are refused.
constexpr double kTermSeconds = 5e-8;

control::LoopSystem system_from(const std::string& s) {
  if (s == "plant") return control::LoopSystem::Plant;
  if (s == "loop") return control::LoopSystem::Loop;
  if (s == "sensitivity") return control::LoopSystem::Sensitivity;
  if (s == "closed_loop") return control::LoopSystem::ClosedLoop;
  return control::LoopSystem::Controller;
}

// Unit of the response of `system` and the factor taking the library's value (rad/s, s) to it.
struct ResponseUnit {
  std::string unit;
  double factor;
};
ResponseUnit response_unit(const std::string& system, double w, bool si) {
  if (system == "controller") return si ? ResponseUnit{"1/s", 1.0} : ResponseUnit{"Omega", 1.0 / w};  // C: a rate
  if (system == "plant") return si ? ResponseUnit{"s", 1.0} : ResponseUnit{"1/Omega", w};  // P: an inverse rate
  return {"dimensionless", 1.0};
}

// The frequency column in `unit` (frequency_unit) from omega [rad/s]: Omega (omega / Omega), rad/s, Hz.
double frequency_in(const std::string& unit, double omega, double w) {
  if (unit == "rad/s") return omega;
  if (unit == "Hz") return omega / (2.0 * std::numbers::pi);
  return omega / w;
}

// τ = 0 verdicts (units of Ω): eigenvalues for finite banks (any K, plant), closed-form conditions at the design
// point K = γ.
nlohmann::json stability_summary(const control::ControlSettings& c) {
  UnitTagged j;
  const control::ControlSettingsSi si = control::to_si(c);
  const ControlUnits cu(c.units());
  const double w = si.rotation_frequency;
  const ControllerKind inner = c.bank_kind();
  const bool finite_bank = inner != ControllerKind::Infinite;
  if (finite_bank && (inner == ControllerKind::Single || c.harmonics <= kMaxHarmonicsSpectra)) {
    // delay-free loop with the bank alone (for the Smith predictor: its nominal loop with an exact model)
    control::ControlSettings plain = c;
    plain.controller = inner;
    plain.delay = 0.0;
    const double abscissa = control::undelayed_spectral_abscissa(control::loop_from(plain));  // rad/s
    j.add("delay_free_spectral_abscissa", abscissa, cu.omega)
        .add("delay_free_stable", abscissa < 0.0, "boolean (0/1)")
        .add("delay_free_basis", "eigenvalues of the closed-loop state matrix with tau = 0 (roots of the delay-free "
                                 "characteristic polynomial, O(N^2))");
  } else if (finite_bank) {
    j.add("delay_free_spectral_abscissa", nullptr)
        .add("delay_free_stable", nullptr)
        .add("delay_free_basis", fmt::format("not computed for harmonics > {} (cost O(N^2)); the design-point verdict "
                                             "below is O(N)",
                                             kMaxHarmonicsSpectra));
  }
  if (inner == ControllerKind::Single) {
    j.add("eq13_stable", control::single_oscillator_stable_tau0(w, si.a, si.b, si.gain, si.plant_rate), "boolean (0/1)")
        .add("eq13_b_limit", si.plant_rate / si.gain, control::RotationUnits::rate_unit);  // b < γΩ/K, in units of Ω
  } else {
    const bool infinite = inner == ControllerKind::Infinite;
    const auto bc = infinite ? control::critical_beta_limit(w) : control::critical_beta(c.harmonics, w);
    j.add("beta_critical", bc.beta, cu.omega)
        .add("beta_critical_over_omega", bc.beta, cu.omega)  // the same (kept for readers of earlier sidecars)
        .add("crossing_frequency", bc.crossing_frequency, cu.omega)
        .add("design_point_stable", c.alpha > 0.0 && si.beta > bc.beta, "boolean (0/1)")
        .add("design_point_basis", infinite ? "eq. (24): alpha > 0 and beta > -Omega/4 (K = gamma, static plant, tau = 0)"
                                            : "alpha > 0 and beta > beta_c(N) (K = gamma, static plant, tau = 0)");
    if (!infinite) {
      const auto nc = control::necessary_conditions(c.harmonics, w, si.alpha, si.beta);
      j.add("eq40_coefficient", nc.coefficient_2n, control::RotationUnits::si_rate_unit)  // (2N + 1) α, α in rad/s
          .add("eq41_coefficient_normalised", nc.coefficient_1_normalised, "dimensionless")
          .add("eq42_limit_condition", nc.limit_condition, "boolean (0/1)");
    }
  }
  return j.with_units();  // a record with its own units
}

UnitTagged summary(const control::ControlSettings& c, const control::LoopSpec& loop) {
  const auto harmonic_record = [&](int k) {
    const std::complex<double> s(0.0, k * loop.rotation_frequency());
    UnitTagged h;
    h.add("harmonic", k, "count")
        .add("sensitivity_magnitude", std::abs(control::sensitivity(loop, s)), "dimensionless")
        .add("closed_loop_magnitude", std::abs(control::disturbance_response(loop, s)), "dimensionless");
    return h;
  };
  std::vector<UnitTagged> harmonics;
  const int kmax = c.controller == ControllerKind::Single ? 3
                                                          : std::min(c.controller == ControllerKind::Infinite ? 5
                                                                                                              : c.harmonics + 1,
                                                                     8);
  for (int k = 1; k <= kmax; ++k) harmonics.push_back(harmonic_record(k));
  UnitTagged j;
  j.add("loop", control::describe_in_rotation_units(loop))
      .add("settings", settings_json(c))  // records with their own units
      .add("settings_si", settings_si_json(c))
      .add("gain_ratio", loop.gain_ratio(), "dimensionless")
      .add("tau0", stability_summary(c))
      .add("at_harmonics", harmonics, harmonic_record(1));
  return j;
}

/// One frequency of the response: ω [rad/s], G(iω), |G| and the phase unwrapped along the grid.
struct TfPoint {
  double omega;
  std::complex<double> g;
  double magnitude = 0.0, phase = 0.0;
};

/// The response's table in `frequency_unit` (w: Ω [rad/s]) and the system's unit.
io::TableOf<TfPoint> tf_table(const std::string& frequency_unit, double w, const ResponseUnit& unit) {
  const double factor = unit.factor;
  return {{"frequency", frequency_unit,
           frequency_unit == "Hz" ? "frequency omega/(2 pi) of the grid point (k Omega/(2 pi) at harmonic k)"
                                  : "angular frequency omega of the grid point (omega = k Omega at harmonic k)",
           [frequency_unit, w](const TfPoint& p) { return frequency_in(frequency_unit, p.omega, w); }},
          {"magnitude", unit.unit, "|G(i omega)| of the system",
           [factor](const TfPoint& p) { return p.magnitude * factor; }},
          {"phase", "rad", "arg G(i omega), unwrapped along the grid", &TfPoint::phase},
          {"real", unit.unit, "Re G(i omega)", [factor](const TfPoint& p) { return p.g.real() * factor; }},
          {"imag", unit.unit, "Im G(i omega)", [factor](const TfPoint& p) { return p.g.imag() * factor; }}};
}

void run_tf(const io::ParamSet& p, Captured* capture) {
  const control::ControlSettings c = control_settings_from(p);
  const control::LoopSpec loop = control::loop_from(c);
  const double fmin = p.real("frequency_min"), fmax = p.real("frequency_max");
  const bool log_spacing = p.flag("log_spacing");
  if (!(fmax > fmin))
    throw InvalidParameter("frequency_max",
                           fmt::format("frequency_max = {} is out of range: must be > frequency_min = {}", fmax, fmin));
  if (log_spacing && fmin <= 0.0)
    throw InvalidParameter("frequency_min", fmt::format("frequency_min = {} is out of range: must be > 0 with "
                                                        "log_spacing (or set --log-spacing false)", fmin));
  const long points = p.integer("points");
  const io::ParamSet as_run = params_as_run(p, c);
  CommandOutput out(as_run, capture, "control tf");
  // without a file, --json holds the rows in memory (a few hundred bytes each)
  if (!out.writes_file() && p.flag("json")) require_memory("points", static_cast<double>(points), 256.0);
  // cost model: one evaluation of the loop per frequency, each a sum over the N oscillators (measured ≈ kTermSeconds
  // per oscillator term, docs/development.md#work-and-time); bank-free systems count as one term
  const double terms = static_cast<double>(c.harmonics) + 8.0;
  const double estimate = require_work(
      "points", static_cast<double>(points), terms * kTermSeconds,
      fmt::format("points x (harmonics + 8) oscillator terms of about {:.2g} s each, harmonics = {}", kTermSeconds,
                  c.harmonics));
  UnitTagged res = summary(c, loop);
  const double w = c.rotation_frequency;
  const std::string system = p.text("system");
  const std::string frequency_unit = p.text("frequency_unit");
  const ResponseUnit unit = response_unit(system, w, frequency_unit != "Omega");
  const control::LoopSystem which = system_from(system);
  res.add("system", system)
      .add("rows", points, "count")
      .add("cost", "O(N) per frequency (sum over the oscillators); rows streamed to the file");
  auto rows = out.open(tf_table(frequency_unit, w, unit));
  // each frequency is computed and its row written at once: memory is bounded by a row, not by the file
  control::PhaseUnwrapper unwrap;
  io::Progress progress("control tf (frequencies)", points, estimate > kProgressAfterSeconds && !p.flag("json"));
  for (long i = 0; i < points; ++i) {
    if ((i & 1023) == 1023) progress.advance(1024);
    const double omega = control::frequency_grid_point(fmin * w, fmax * w, points, log_spacing, i);
    const std::complex<double> g = control::evaluate(loop, which, {0.0, omega});
    TfPoint point{omega, g};
    control::magnitude_phase(g, point.magnitude, point.phase);
    point.phase = unwrap(point.phase);
    rows.add(point);
  }
  progress.finish();
  out.finish(res.with_units(),
             fmt::format("{} frequencies of the {} ({})", points, system, res.values().at("loop").get<std::string>()));
}

}  // namespace

void register_control_tf(CLI::App& control) {
  add_command(
      control, "tf",
      "frequency response of the harmonic-rejection controller / loop (seed 2), tau = 0 stability summary",
      [](io::ParamSet& p) {
        add_control_params(p, kMaxHarmonicsTf);
        p.group("Frequency response")
            .text("system", "controller",
                  "response to tabulate: controller C (units of Omega), plant P = exp(-s tau) P0 (units of 1/Omega), "
                  "loop L = P C, sensitivity 1/(1 + L), closed_loop (disturbance f -> output y; all three "
                  "dimensionless)",
                  {"controller", "plant", "loop", "sensitivity", "closed_loop"})
            .real("frequency_min", 0.01, "lowest frequency of the grid", io::Range::closed(0.0, 1e12))
            .unit("Omega");
        add_si_alternative(p, "frequency_min", SiUnit::Auto, io::Range::non_negative());
        add_si_alternative(p, "frequency_min", SiUnit::Hz, io::Range::non_negative());
        p.real("frequency_max", 10.0, "highest frequency of the grid", io::Range{0.0, 1e12, true, false})
            .unit("Omega");
        add_si_alternative(p, "frequency_max", SiUnit::Auto, io::Range::positive());
        add_si_alternative(p, "frequency_max", SiUnit::Hz, io::Range::positive());
        p.text("frequency_unit", "Omega",
               "unit of the frequency column: Omega (harmonic number at k Omega), rad/s or Hz; with rad/s or Hz the "
               "controller's response is in 1/s and the plant's in s (Omega: in units of Omega and 1/Omega)",
               {"Omega", "rad/s", "Hz"})
            .only_if_given()  // recorded when given: the records of earlier runs stay as they were
            .integer("points", 1000, "number of grid points (rows are streamed: O(N) work and O(1) memory per row)",
                     2, 10000000)
            .flag("log_spacing", true, "logarithmic grid (false: linear)");
        add_output_params(p, "out/control_tf.csv", "frequency-response");
      },
      with_si_inputs(run_tf));
}

}  // namespace afmkit::cli
