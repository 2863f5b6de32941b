// afmkit control simulate: time-domain closed loop of the seed-2 harmonic-rejection controller
// (closed_loop_simulation.hpp; docs/theory-control.md#simulation). Writes the time series as CSV
//   t [s], y (plant output), u (control), m = y(t − τ) (measurement), target (uncontrolled steady state without the
//   rejected harmonics: f_k for the static plant, γ f_k/(γ + ikΩ) for the first-order plant), f_minus_f1 (f − f^(1))
// with a JSON sidecar holding the harmonic report; --json prints the report instead.
// Shared controller/plant parameters and their units: control_params.hpp (rates in units of Ω, delays in units of
// T). Disturbance (seed-2 eq. 14): f = c0 + Σ F_k sin(kΩt + φ_k); default = the Fig. 5 example
// (c0 = 0.2, F1 = 1, F_k = 0.3/k for k = 2..8, random phases from disturbance_seed, φ1 = 0).
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/closed_loop_simulation.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/progress.hpp"
#include "commands.hpp"
#include "control_params.hpp"

namespace afmkit::cli {

namespace {

control::ControllerStepping stepping_from(const std::string& s) {
  if (s == "zoh") return control::ControllerStepping::ZeroOrderHold;
  if (s == "block_zoh") return control::ControllerStepping::BlockZeroOrderHold;
  return control::ControllerStepping::AdamsBashforth3;
}

control::Disturbance disturbance_from(const io::ParamSet& p) {
  const auto seed = static_cast<unsigned>(p.integer("disturbance_seed"));
  if (!p.was_set("disturbance_amplitudes") && !p.was_set("disturbance_phases") && !p.was_set("disturbance_offset"))
    return control::Disturbance::paper_example(seed);
  const auto& amps = p.reals("disturbance_amplitudes");
  const auto& given = p.reals("disturbance_phases");
  if (!given.empty() && given.size() != amps.size())
    throw InvalidParameter("disturbance_phases",
                           fmt::format("disturbance_phases has {} entries: must be empty (random phases) or have one "
                                       "per amplitude ({})", given.size(), amps.size()));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
  std::vector<control::Disturbance::Harmonic> h;
  for (std::size_t k = 0; k < amps.size(); ++k) {
    const double ph = !given.empty() ? given[k] : (k == 0 ? 0.0 : phase(rng));
    if (amps[k] > 0.0) h.push_back({static_cast<int>(k + 1), amps[k], ph});
  }
  return control::Disturbance(p.real("disturbance_offset"), std::move(h));
}

nlohmann::json complex_json(std::complex<double> z) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  return {{"re", num(z.real())}, {"im", num(z.imag())}, {"abs", num(std::abs(z))}};
}

nlohmann::json report_json(const control::SimulationReport& r, const control::ClosedLoopSimulation& sim) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json j;
  j["method"] = control::to_string(sim.options().stepping);
  j["step"] = r.step;
  j["steps_per_period"] = r.steps_per_period;
  j["periods_completed"] = r.periods_completed;
  j["diverged"] = r.diverged;
  j["delay_exceeds_period"] = r.delay_exceeds_period;
  j["residual_first_harmonic"] = num(r.residual_first_harmonic);
  j["first_harmonic"] = complex_json(r.first_harmonic);
  j["control_first_harmonic"] = complex_json(r.control_first_harmonic);
  j["max_harmonic_error"] = num(r.max_harmonic_error);
  nlohmann::json hs = nlohmann::json::array();
  for (const auto& h : r.harmonics)
    hs.push_back({{"order", h.order}, {"value", complex_json(h.value)}, {"target", complex_json(h.target)},
                  {"error", num(h.error)}});
  j["harmonics"] = hs;
  j["growth_rate"] = num(r.growth_rate);
  j["convergence_rate"] = num(-r.growth_rate);
  j["fit_periods"] = {r.fit_first_period, r.fit_last_period};
  j["envelope_first_harmonic"] = r.envelope;
  j["notes"] = {{"harmonics", "complex amplitudes over the last period: y = Re sum c_k exp(i k Omega t)"},
                {"growth_rate", "slope of ln |y_1| per period [1/s]; negative = converging"}};
  return j;
}

void run_simulate(const io::ParamSet& p) {
  const ControlSettings c = control_settings_from(p);
  if (c.controller == "smith")
    throw InvalidParameter("controller", "controller = smith is not simulated in the time domain: must be single, "
                                         "bank or infinite");
  if (c.controller == "infinite" && p.text("method") != "ab3")
    throw InvalidParameter("method", fmt::format("method = {} is not available for controller = infinite: must be ab3 "
                                                 "(the neutral realisation, eqs. 32-33, is stepped by AB3)",
                                                 p.text("method")));
  if (p.real("delay_variation") > p.real("delay"))
    throw InvalidParameter("delay_variation",
                           fmt::format("delay_variation = {} is out of range: must be <= delay = {} (units of T; the "
                                       "delay must stay >= 0)", p.real("delay_variation"), p.real("delay")));
  const control::Controller any = control_controller_from(c);
  control::Bank bank = std::holds_alternative<control::InfiniteBank>(any)
                           ? control::Bank(std::get<control::InfiniteBank>(any))
                           : control::Bank(std::get<control::OscillatorBank>(any));
  const control::Plant plant(c.plant, c.plant_rate, c.rotation_frequency, c.delay, disturbance_from(p),
                             p.real("delay_variation") * c.period,
                             p.real("delay_variation_frequency") * c.rotation_frequency);
  control::SimulationOptions o;
  o.periods = static_cast<int>(p.integer("periods"));
  o.steps_per_period = static_cast<int>(p.integer("steps_per_period"));
  o.stepping = stepping_from(p.text("method"));
  const bool json = p.flag("json");
  o.record_every = json ? 0 : static_cast<int>(p.integer("record_every"));
  // memory: the per-period tables of the run (about 14 doubles per step of a period) and the controller's modes
  require_memory("steps_per_period", static_cast<double>(o.steps_per_period), 14.0 * sizeof(double));
  // the measurement delay line holds (delay + delay_variation)/h samples (rounded up to a power of two)
  require_memory("delay", p.real("delay") + p.real("delay_variation"),
                 2.0 * sizeof(double) * static_cast<double>(o.steps_per_period));
  const control::ClosedLoopSimulation sim(plant, bank, o);
  const std::string output = p.text("output");
  // the time series is streamed to the CSV as it is computed (memory bounded by a row, not by the run)
  std::optional<io::TableWriter> table;
  if (!json) table.emplace(output, std::vector<std::string>{"t", "y", "u", "m", "target", "f_minus_f1"});
  io::Progress progress("control simulate (periods)", o.periods, true, 1.0);
  const auto sink = [&table](const control::TimeSample& r) {
    table->row(r.t, r.y, r.u, r.m, r.target, r.f_minus_first);
  };
  const auto res = json ? sim.run([&](long, long) { progress.advance(); })
                        : sim.run([&](long, long) { progress.advance(); }, sink);
  progress.finish();
  nlohmann::json report = report_json(res.report, sim);
  report["settings"] = c.to_json();
  if (res.report.diverged)
    fmt::print(stderr, "afmkit: warning: the closed loop diverged after {} periods (|y| > 1e100); run stopped\n",
               res.report.periods_completed);
  if (res.report.delay_exceeds_period)
    fmt::print(stderr, "afmkit: warning: the delay reaches one rotation period (the paper assumes tau < T)\n");
  if (json) {
    fmt::print("{}\n", report.dump(2));
    return;
  }
  report["columns"] = {{"t", "time [s]"},
                       {"y", "plant output"},
                       {"u", "control"},
                       {"m", "measurement y(t - tau)"},
                       {"target", "steady state to reach: uncontrolled output without the rejected harmonics"},
                       {"f_minus_f1", "disturbance without its first harmonic"}};
  report["rows"] = table->size();
  const std::size_t rows = table->size();
  table->commit(io::make_sidecar("control simulate", p.to_json(), report));
  fmt::print("wrote {} rows to {}: |y_1| over the last period = {:.3e}, max harmonic error = {:.3e}, growth rate = "
             "{:.4g} 1/s\n",
             rows, output, res.report.residual_first_harmonic, res.report.max_harmonic_error,
             res.report.growth_rate);
}

}  // namespace

void register_control_simulate(CLI::App& control) {
  auto params = std::make_shared<io::ParamSet>();
  add_control_params(*params);
  params->group("Simulation")
      .integer("periods", 60, "number of rotation periods to simulate", 1, 10000000)
      .integer("steps_per_period", 2000, "fixed steps (samples) per rotation period T", 8, 100000000)
      .text("method", "ab3",
            "controller discretisation: ab3 (Adams-Bashforth 3, as in the paper), zoh (exact zero-order hold of the "
            "controller), block_zoh (each oscillator exact for the held error; what RealtimeFilter runs)",
            {"ab3", "zoh", "block_zoh"})
      .real("disturbance_offset", 0.2, "c0 of f (eq. 14)")
      .reals("disturbance_amplitudes", {1.0, 0.15, 0.1, 0.075, 0.06, 0.05, 0.3 / 7.0, 0.0375},
             "F_1, F_2, ... of f (eq. 14); default: the Fig. 5 example F1 = 1, F_k = 0.3/k (k = 2..8)",
             io::Range::non_negative())
      .reals("disturbance_phases", {}, "phi_1, phi_2, ... [rad]")
      .default_text("random from disturbance_seed, phi_1 = 0")
      .integer("disturbance_seed", 1, "seed of the random phases", 0, 4294967295L)
      .real("delay_variation", 0.0, "amplitude of a slow sinusoidal delay variation [units of T] (<= delay)",
            io::Range::non_negative())
      .real("delay_variation_frequency", 0.0, "angular frequency of the delay variation [units of Omega]",
            io::Range::non_negative())
      .integer("record_every", 10, "keep every n-th step in the CSV", 1, 1000000000)
      .group("Output")
      .flag("json", false, "print the harmonic report as JSON to stdout instead of writing the CSV")
      .text("output", "out/control_simulate.csv", "output CSV path (JSON sidecar written next to it)");
  auto* cmd = control.add_subcommand(
      "simulate", "time-domain closed loop: plant (eq. 1 or 3) with delayed measurement and the harmonic-rejection "
                  "controller (AB3 / exact ZOH / N = infinity neutral form); harmonic report");
  params->add_options(*cmd);
  cmd->callback([params] {
    params->resolve();
    run_simulate(*params);
  });
}

}  // namespace afmkit::cli
