// afmkit control tf: frequency response of the seed-2 controller, plant, loop, sensitivity or closed loop
// (seed-2 eqs. 10, 18, 25, 28–31) on a frequency grid, as CSV (frequency, magnitude, phase, real, imag) with a JSON sidecar
// holding the τ = 0 stability verdicts (eqs. 13, 22–24, 40–42, β_c(N)) and |S| at the harmonics.
//   frequency is ω/Ω (harmonic number; the grid bounds frequency_min/max are in the same unit),
//   magnitude = |G(iω)|, phase = arg G(iω) unwrapped along the grid [rad], real/imag = G(iω).
// --json prints the summary (no CSV). Controller/plant parameters and units: control_params.hpp.
#include <complex>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/frequency_response.hpp"
#include "afmkit/control/stability_tau0.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "commands.hpp"
#include "control_params.hpp"

namespace afmkit::cli {

namespace {

control::LoopSystem system_from(const std::string& s) {
  if (s == "plant") return control::LoopSystem::Plant;
  if (s == "loop") return control::LoopSystem::Loop;
  if (s == "sensitivity") return control::LoopSystem::Sensitivity;
  if (s == "closed_loop") return control::LoopSystem::ClosedLoop;
  return control::LoopSystem::Controller;
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// τ = 0 verdicts: eigenvalues for finite banks (any K, plant), closed-form conditions at the design point K = γ.
nlohmann::json stability_summary(const ControlSettings& c, const control::LoopSpec& loop) {
  nlohmann::json j;
  const double w = c.rotation_frequency;
  const std::string inner = c.controller == "smith" ? c.smith_bank : c.controller;
  const bool finite_bank = inner != "infinite";
  if (finite_bank && (inner == "single" || c.harmonics <= kMaxHarmonicsSpectra)) {
    // delay-free loop with the bank alone (for the Smith predictor: its nominal loop with an exact model)
    const control::LoopSpec plain(c.controller == "smith" ? control_controller_from([&] {
      ControlSettings b = c;
      b.controller = c.smith_bank;
      return b;
    }()) : loop.controller, c.plant, c.plant_rate, 0.0);
    const double abscissa = control::undelayed_spectral_abscissa(plain);
    j["delay_free_spectral_abscissa"] = abscissa;
    j["delay_free_stable"] = abscissa < 0.0;
    j["delay_free_basis"] = "eigenvalues of the closed-loop state matrix with tau = 0 (roots of the delay-free "
                            "characteristic polynomial, O(N^2))";
  } else if (finite_bank) {
    j["delay_free_spectral_abscissa"] = nullptr;
    j["delay_free_stable"] = nullptr;
    j["delay_free_basis"] = fmt::format("not computed for harmonics > {} (cost O(N^2)); the design-point verdict "
                                        "below is O(N)", kMaxHarmonicsSpectra);
  }
  if (inner == "single") {
    j["eq13_stable"] = control::single_oscillator_stable_tau0(w, c.a, c.b, c.gain, c.plant_rate);
    j["eq13_b_limit"] = c.plant_rate * w / c.gain;
  } else {
    const bool infinite = inner == "infinite";
    const auto bc = infinite ? control::critical_beta_limit(w) : control::critical_beta(c.harmonics, w);
    j["beta_critical"] = bc.beta;
    j["beta_critical_over_omega"] = bc.beta / w;
    j["crossing_frequency"] = bc.crossing_frequency;
    j["design_point_stable"] = c.alpha > 0.0 && c.beta > bc.beta;
    j["design_point_basis"] = infinite ? "eq. (24): alpha > 0 and beta > -Omega/4 (K = gamma, static plant, tau = 0)"
                                       : "alpha > 0 and beta > beta_c(N) (K = gamma, static plant, tau = 0)";
    if (!infinite) {
      const auto nc = control::necessary_conditions(c.harmonics, w, c.alpha, c.beta);
      j["eq40_coefficient"] = nc.coefficient_2n;
      j["eq41_coefficient_normalised"] = nc.coefficient_1_normalised;
      j["eq42_limit_condition"] = nc.limit_condition;
    }
  }
  return j;
}

nlohmann::json summary(const ControlSettings& c, const control::LoopSpec& loop) {
  nlohmann::json j;
  j["loop"] = loop.describe();
  j["settings"] = c.to_json();
  j["gain_ratio"] = loop.gain_ratio();
  j["tau0"] = stability_summary(c, loop);
  nlohmann::json harmonics = nlohmann::json::array();
  const int kmax = c.controller == "single" ? 3 : std::min(c.controller == "infinite" ? 5 : c.harmonics + 1, 8);
  for (int k = 1; k <= kmax; ++k) {
    const std::complex<double> s(0.0, k * c.rotation_frequency);
    harmonics.push_back({{"harmonic", k},
                         {"sensitivity_magnitude", finite_or_null(std::abs(control::sensitivity(loop, s)))},
                         {"closed_loop_magnitude", finite_or_null(std::abs(control::disturbance_response(loop, s)))}});
  }
  j["at_harmonics"] = harmonics;
  return j;
}

void run_tf(const io::ParamSet& p) {
  const ControlSettings c = control_settings_from(p);
  const control::LoopSpec loop = control_loop_from(c);
  const nlohmann::json results = summary(c, loop);
  if (p.flag("json")) {
    fmt::print("{}\n", results.dump(2));
    return;
  }
  const double fmin = p.real("frequency_min"), fmax = p.real("frequency_max");
  const bool log_spacing = p.flag("log_spacing");
  if (!(fmax > fmin))
    throw InvalidParameter("frequency_max",
                           fmt::format("frequency_max = {} is out of range: must be > frequency_min = {}", fmax, fmin));
  if (log_spacing && fmin <= 0.0)
    throw InvalidParameter("frequency_min", fmt::format("frequency_min = {} is out of range: must be > 0 with "
                                                        "log_spacing (or set --log-spacing false)", fmin));
  const double w = c.rotation_frequency;
  const long points = p.integer("points");
  const control::LoopSystem which = system_from(p.text("system"));
  nlohmann::json res = results;
  res["system"] = p.text("system");
  res["columns"] = {{"frequency", "omega/Omega"},
                    {"magnitude", "|G(i omega)|"},
                    {"phase", "unwrapped arg G(i omega) [rad]"},
                    {"real", "Re G(i omega)"},
                    {"imag", "Im G(i omega)"}};
  res["rows"] = points;
  res["cost"] = "O(N) per frequency (sum over the oscillators); rows streamed to the file";
  const std::string output = p.text("output");
  // each frequency is computed and its row written at once: memory is bounded by a row, not by the file
  io::TableWriter table(output, {"frequency", "magnitude", "phase", "real", "imag"});
  control::PhaseUnwrapper unwrap;
  for (long i = 0; i < points; ++i) {
    const double omega = control::frequency_grid_point(fmin * w, fmax * w, points, log_spacing, i);
    const std::complex<double> g = control::evaluate(loop, which, {0.0, omega});
    double magnitude, phase;
    control::magnitude_phase(g, magnitude, phase);
    table.row(omega / w, magnitude, unwrap(phase), g.real(), g.imag());
  }
  table.commit(io::make_sidecar("control tf", p.to_json(), res));
  fmt::print("wrote {} rows ({} of {}) to {}\n", points, p.text("system"), loop.describe(), output);
}

}  // namespace

void register_control_tf(CLI::App& control) {
  auto params = std::make_shared<io::ParamSet>();
  add_control_params(*params, kMaxHarmonicsTf);
  params->group("Frequency response")
      .text("system", "controller",
               "response to tabulate: controller C, plant P = exp(-s tau) P0, loop L = P C, sensitivity "
               "1/(1 + L), closed_loop (disturbance f -> output y)",
               {"controller", "plant", "loop", "sensitivity", "closed_loop"})
      .real("frequency_min", 0.01, "lowest frequency of the grid [units of Omega]", io::Range::closed(0.0, 1e12))
      .real("frequency_max", 10.0, "highest frequency of the grid [units of Omega]", io::Range{0.0, 1e12, true, false})
      .integer("points", 1000, "number of grid points (rows are streamed: O(N) work and O(1) memory per row)", 2,
               10000000)
      .flag("log_spacing", true, "logarithmic grid (false: linear)")
      .group("Output")
      .flag("json", false, "print the tau = 0 stability summary as JSON to stdout instead of writing the CSV")
      .text("output", "out/control_tf.csv", "output CSV path (JSON sidecar written next to it)");
  auto* cmd = control.add_subcommand(
      "tf", "frequency response of the harmonic-rejection controller / loop (seed 2), tau = 0 stability summary");
  params->add_options(*cmd);
  cmd->callback([params] {
    params->resolve();
    run_tf(*params);
  });
}

}  // namespace afmkit::cli
