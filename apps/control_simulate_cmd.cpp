// afmkit control simulate: time-domain closed loop of the seed-2 harmonic-rejection controller
// (closed_loop_simulation.hpp; docs/theory-control.md#simulation). Writes the time series as CSV
//   t (units of T), y (plant output), u (control, units of signal·Ω), m = y(t − τ) (measurement), target
//   (uncontrolled steady state without the rejected harmonics: f_k for the static plant, γ f_k/(γ + ikΩ) for the
//   first-order plant), f_minus_f1 (f − f^(1))
// with a JSON sidecar holding the harmonic report (harmonics up to max_order, above the bank's N too).
// "signal" is the unit of the disturbance f and of the output y (any: the loop is linear).
// Shared controller/plant parameters and their units: control_params.hpp (rates in units of Ω, delays in units of
// T). Disturbance (seed-2 eq. 14): f = c0 + Σ F_k sin(kΩt + φ_k); default = the Fig. 5 example
// (c0 = 0.2, F1 = 1, F_k = 0.3/k for k = 2..8, random phases from disturbance_seed, φ1 = 0).
#include <algorithm>
#include <optional>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/closed_loop_simulation.hpp"
#include "afmkit/control/sampled_disturbance.hpp"
#include "afmkit/io/curves/text_column.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/table.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "control_params.hpp"
#include "control_units.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {
using control::ControllerKind;

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

/// The amplitudes the run used (one per entry of disturbance_amplitudes): the paper example's F_k = 0.3/k differ
/// from the declared decimals in the last bit (0.3/3 != 0.1), so the record gives the values used.
std::vector<double> amplitudes_used(const io::ParamSet& p, const control::Disturbance& f) {
  std::vector<double> amplitudes(p.reals("disturbance_amplitudes").size(), 0.0);
  for (const auto& h : f.harmonics)
    if (h.order >= 1 && static_cast<std::size_t>(h.order) <= amplitudes.size()) amplitudes[h.order - 1] = h.amplitude;
  return amplitudes;
}

/// The phases the run drew (one per entry of disturbance_amplitudes; 0 where F_k = 0), for the record.
std::vector<double> phases_used(const io::ParamSet& p, const control::Disturbance& f) {
  std::vector<double> phases(p.reals("disturbance_amplitudes").size(), 0.0);
  for (const auto& h : f.harmonics)
    if (h.order >= 1 && static_cast<std::size_t>(h.order) <= phases.size()) phases[h.order - 1] = h.phase;
  return phases;
}

// The keys of the Fourier form of f, which `signal` replaces.
const std::vector<std::string>& fourier_keys() {
  static const std::vector<std::string> keys = {"disturbance_offset", "disturbance_amplitudes", "disturbance_phases",
                                                "disturbance_seed"};
  return keys;
}

// Samples per rotation period of `signal` from signal_step (T; or signal_step_seconds, converted) or
// signal_sample_rate (samples/s): a whole number, else InvalidParameter naming the key given.
int samples_per_period(const io::ParamSet& p, const control::RotationUnits& u) {
  const bool step = p.was_set("signal_step"), rate = p.was_set("signal_sample_rate");
  const std::string step_key = p.was_set("signal_step_seconds") ? "signal_step_seconds" : "signal_step";
  if (step && rate)
    throw InvalidParameter("signal_sample_rate", fmt::format("{} and signal_sample_rate were both given: they are the "
                                                             "same sampling in different units; give one of them",
                                                             step_key));
  if (!step && !rate)
    throw InvalidParameter("signal_step", "signal is given without its sampling: give signal_sample_rate "
                                          "(samples/s), signal_step_seconds (s) or signal_step (units of T)");
  const std::string key = step ? step_key : "signal_sample_rate";
  const double per_period = step ? 1.0 / p.real("signal_step") : p.real("signal_sample_rate") * u.period();
  const double whole = std::round(per_period);
  if (!(std::abs(per_period - whole) <= 1e-9 * whole) || whole < 2.0 || whole > 1e9)
    throw InvalidParameter(key, fmt::format("{} = {} gives {:.12g} samples per rotation period T = {:.6g} s: must give "
                                            "a whole number of samples per period, at least 2 (f is T-periodic in "
                                            "the model)", key, p.real(key), per_period, u.period()));
  return static_cast<int>(whole);
}

int highest_order(const control::Disturbance& f) {
  int k = 0;
  for (const auto& h : f.harmonics) k = std::max(k, h.order);
  return k;
}

// The harmonic report in the units of the command: complex amplitudes of y in signal units, of u in signal·Ω.
UnitTagged report_record(const control::SimulationReport& r, const control::ClosedLoopSimulation& sim,
                         const control::RotationUnits& u) {
  const ControlUnits cu(u);
  const units::Unit signal = units::as_is("signal");
  const units::Unit control_signal{"signal*Omega", 1.0, u.rotation_frequency()};  // u [signal/s] / Ω
  // a complex amplitude converted by `unit`: re, im and |z| of the converted value
  const auto complex_json = [](std::complex<double> z, const units::Unit& unit) {
    const std::complex<double> c(unit(z.real()), unit(z.imag()));
    return nlohmann::json{{"re", c.real()}, {"im", c.imag()}, {"abs", std::abs(c)}};
  };
  const auto harmonic_record = [&](const control::HarmonicComparison& h) {
    UnitTagged j;
    j.add("order", h.order, "count")
        .add("value", complex_json(h.value, signal), signal.name)
        .add("target", complex_json(h.target, signal), signal.name)
        .add("error", h.error, signal);
    return j;
  };
  std::vector<UnitTagged> harmonics;
  for (const auto& h : r.harmonics) harmonics.push_back(harmonic_record(h));
  UnitTagged j;
  j.add("method", control::to_string(sim.options().stepping))
      .add("step", r.step, cu.period)
      .add("steps_per_period", r.steps_per_period, "count")
      .add("periods_completed", r.periods_completed, "count")
      .add("diverged", r.diverged, "boolean (0/1)")
      .add("delay_exceeds_period", r.delay_exceeds_period, "boolean (0/1)")
      .add("residual_first_harmonic", r.residual_first_harmonic, signal)
      .add("first_harmonic", complex_json(r.first_harmonic, signal), signal.name)
      .add("control_first_harmonic", complex_json(r.control_first_harmonic, control_signal), control_signal.name)
      .add("bank_max_order", r.bank_max_order, "count")
      .add("max_harmonic_error", r.max_harmonic_error, signal)
      .add("max_harmonic_error_above_bank", r.max_harmonic_error_above, signal)
      .add("harmonics", harmonics, harmonic_record(control::HarmonicComparison{}))
      .add("growth_rate", r.growth_rate, cu.omega)
      .add("convergence_rate", -r.growth_rate, cu.omega)
      .add("fit_periods", {r.fit_first_period, r.fit_last_period}, "count")
      .add("envelope_first_harmonic", r.envelope, signal);
  return j;
}

/// What the report's entries mean (results "notes").
nlohmann::json report_notes() {
  return {{"harmonics", "complex amplitudes over the last period: y = Re sum c_k exp(i k Omega t), k = 0 .. max_order "
                        "(above bank_max_order: harmonics the controller does not model)"},
          {"growth_rate", "slope of ln |y_1| against time, in units of Omega (ln-factor per period = 2 pi x "
                          "growth_rate); negative = converging; comparable to the spectral abscissa of `control "
                          "roots`"}};
}

/// The time series' table, one row per recorded step (u: the rotation units of the run).
io::TableOf<control::TimeSample> simulate_table(const control::RotationUnits& u) {
  const ControlUnits cu(u);
  const units::Unit control_signal{"signal*Omega", 1.0, u.rotation_frequency()};  // u [signal/s] / Ω
  using S = control::TimeSample;
  return {{"t", cu.period, "time", [](const S& r) { return r.t; }},
          {"y", "signal", "plant output y", &S::y},
          {"u", control_signal, "control u", &S::u},
          {"m", "signal", "measurement y(t - tau)", &S::m},
          {"target", "signal", "steady state to reach: uncontrolled output without the rejected harmonics", &S::target},
          {"f_minus_f1", "signal", "disturbance f without its first harmonic", &S::f_minus_first}};
}

void run_simulate(const io::ParamSet& p, Captured* capture) {
  const control::ControlSettings c = control_settings_from(p);
  if (c.controller == ControllerKind::Smith)
    throw InvalidParameter("controller", "controller = smith is not simulated in the time domain: must be single, "
                                         "bank or infinite");
  if (c.controller == ControllerKind::Infinite && p.text("method") != "ab3")
    throw InvalidParameter("method", fmt::format("method = {} is not available for controller = infinite: must be ab3 "
                                                 "(the neutral realisation, eqs. 32-33, is stepped by AB3)",
                                                 p.text("method")));
  if (p.real("delay_variation") > p.real("delay"))
    throw InvalidParameter("delay_variation",
                           fmt::format("delay_variation = {} is out of range: must be <= delay = {} (units of T; the "
                                       "delay must stay >= 0)", p.real("delay_variation"), p.real("delay")));
  const control::RotationUnits u = c.units();
  const control::ControlSettingsSi si = control::to_si(c);
  if (p.was_set("signal") && p.was_set("signal_file"))
    throw InvalidParameter("signal_file", "signal and signal_file were both given: give the samples in one of them");
  if (p.was_set("signal_column") && !p.was_set("signal_file"))
    throw InvalidParameter("signal_column", "signal_column is given without signal_file: it chooses a column of it");
  const bool sampled = p.was_set("signal") || p.was_set("signal_file");
  const std::string signal_key = p.was_set("signal_file") ? "signal_file" : "signal";
  for (const auto& key : fourier_keys())
    if (sampled && p.was_set(key))
      throw InvalidParameter(key, fmt::format("{} and {} were both given: {} gives the disturbance f as samples, "
                                              "instead of its Fourier form (disturbance_*); give one",
                                              signal_key, key, signal_key));
  if (!sampled)
    for (const char* key : {"signal_step", "signal_step_seconds", "signal_sample_rate", "signal_harmonics"})
      if (p.was_set(key))
        throw InvalidParameter(key, fmt::format("{} is given without signal: it describes the samples of signal",
                                                key));
  std::optional<control::SampledDisturbance> from_samples;
  std::size_t signal_samples = 0;
  if (sampled) {
    const int per_period = samples_per_period(p, u);
    require_memory(signal_key, static_cast<double>(per_period), 3.0 * sizeof(double));
    const std::vector<double> samples = p.was_set("signal_file")
                                            ? io::curves::read_text_column(p.text("signal_file"), p.text("signal_column"))
                                            : p.reals("signal");
    from_samples = control::disturbance_from_samples(samples, per_period,
                                                     static_cast<int>(p.integer("signal_harmonics")),
                                                     signal_key.c_str());
    signal_samples = samples.size();
  }
  const control::Disturbance disturbance = sampled ? from_samples->disturbance : disturbance_from(p);
  control::SimulationOptions o;
  o.periods = static_cast<int>(p.integer("periods"));
  o.steps_per_period = static_cast<int>(p.integer("steps_per_period"));
  o.stepping = stepping_from(p.text("method"));
  // harmonics reported: max_order, or by default 5 above the highest of N and of f, below the Nyquist order
  const int nyquist_order = (o.steps_per_period - 1) / 2;
  const int modelled = std::max(c.controller == ControllerKind::Infinite ? 0 : c.harmonics, highest_order(disturbance));
  o.report_max_order = p.was_set("max_order") ? static_cast<int>(p.integer("max_order"))
                                              : std::min(std::max(modelled, 1) + 5, nyquist_order);
  if (o.report_max_order > nyquist_order)
    throw InvalidParameter("max_order", fmt::format("max_order = {} is out of range: must be an integer in [1, {}] "
                                                    "(below half of steps_per_period = {})",
                                                    o.report_max_order, nyquist_order, o.steps_per_period));
  io::ParamSet as_run = params_as_run(p, c, {{"max_order", o.report_max_order}});
  if (!sampled && !p.was_set("disturbance_phases"))
    as_run.record_used("disturbance_phases", phases_used(p, disturbance));
  if (!sampled && !p.was_set("disturbance_amplitudes"))
    as_run.record_used("disturbance_amplitudes", amplitudes_used(p, disturbance));
  CommandOutput out(as_run, capture, "control simulate");
  const bool keep_rows = p.flag("json") && !out.writes_file();
  o.record_every = out.writes_file() || keep_rows ? static_cast<int>(p.integer("record_every")) : 0;
  // memory: the per-period tables of the run (about 14 doubles per step of a period) and the controller's modes
  require_memory("steps_per_period", static_cast<double>(o.steps_per_period), 14.0 * sizeof(double));
  // the measurement delay line holds (delay + delay_variation)/h samples (rounded up to a power of two)
  require_memory("delay", p.real("delay") + p.real("delay_variation"),
                 2.0 * sizeof(double) * static_cast<double>(o.steps_per_period));
  // the rows --json holds without a file (a few hundred bytes each)
  if (keep_rows)
    require_memory("periods", static_cast<double>(o.periods),
                   256.0 * static_cast<double>(o.steps_per_period) / static_cast<double>(o.record_every));
  const control::Plant plant(c.plant, si.plant_rate, si.rotation_frequency, si.delay, disturbance,
                             u.delay(p.real("delay_variation")), u.rate(p.real("delay_variation_frequency")));
  const control::ClosedLoopSimulation sim(plant, control::bank_from(c), o);
  auto rows = out.open(simulate_table(u));
  // the time series is streamed as it is computed (memory bounded by a row, not by the run)
  const auto sink = [&rows](const control::TimeSample& r) { rows.add(r); };
  io::Progress progress("control simulate (periods)", o.periods, true, 1.0);
  const auto res = o.record_every > 0 ? sim.run([&](long, long) { progress.advance(); }, sink)
                                      : sim.run([&](long, long) { progress.advance(); });
  progress.finish();
  UnitTagged report = report_record(res.report, sim, u);
  report.add("loop", control::describe_in_rotation_units(control::loop_from(c)))
      .add("settings", settings_json(c))  // records with their own units
      .add("settings_si", settings_si_json(c));
  nlohmann::json notes = report_notes();
  if (from_samples) {
    const control::SampledDisturbance& d = *from_samples;
    const units::Unit signal = units::as_is("signal");
    UnitTagged from;
    from.add("samples", signal_samples, "count")
        .add("samples_per_period", d.samples_per_period, "count")
        .add("periods", d.periods, "count")
        .add("harmonics", d.harmonics, "count")
        .add("harmonics_used", d.disturbance.harmonics.size(), "count")
        .add("offset", d.disturbance.offset, signal)
        .add("rms", d.rms, signal)
        .add("non_periodic_rms", d.non_periodic_rms, signal)
        .add("unrepresented_rms", d.unrepresented_rms, signal);
    report.add("signal", from);
    notes["signal"] = "f from the samples: their period average (non_periodic_rms: what differs from "
                                "period to period) as c0 + sum F_k sin(k Omega t + phi_k), k = 1 .. harmonics "
                                "(unrepresented_rms: what these harmonics leave of the average)";
    if (d.non_periodic_rms > 1e-9 * d.rms)
      fmt::print(stderr, "afmkit: warning: signal varies from period to period (RMS {:.3g} of {:.3g} signal): the "
                         "model's f is T-periodic, the simulation uses the average over its {} periods\n",
                 d.non_periodic_rms, d.rms, d.periods);
  }
  if (res.report.diverged)
    io::message_line(fmt::format("afmkit: warning: the closed loop diverged after {} periods (|y| > 1e100); run "
                                 "stopped", res.report.periods_completed));
  if (res.report.delay_exceeds_period)
    io::message_line("afmkit: warning: the delay reaches one rotation period (the paper assumes tau < T)");
  report.add("notes", notes);
  out.finish(report.with_units(), fmt::format("|y_1| over the last period = {:.3e}, max harmonic error = {:.3e} (k <= {}), {:.3e} "
                                 "above, growth rate = {}",
                                 res.report.residual_first_harmonic, res.report.max_harmonic_error,
                                 res.report.bank_max_order, res.report.max_harmonic_error_above,
                                 rate_summary(res.report.growth_rate, u)));
}

}  // namespace

void register_control_simulate(CLI::App& control) {
  add_command(
      control, "simulate",
      "time-domain closed loop: plant (eq. 1 or 3) with delayed measurement and the harmonic-rejection controller "
      "(AB3 / exact ZOH / N = infinity neutral form); harmonic report up to max_order",
      [](io::ParamSet& p) {
        add_control_params(p);
        p.group("Simulation")
            .integer("periods", 60, "number of rotation periods to simulate", 1, 10000000)
            .integer("steps_per_period", 2000, "fixed steps (samples) per rotation period T", 8, 100000000)
            .text("method", "ab3",
                  "controller discretisation: ab3 (Adams-Bashforth 3, as in the paper), zoh (exact zero-order hold of "
                  "the controller), block_zoh (each oscillator exact for the held error; what RealtimeFilter runs)",
                  {"ab3", "zoh", "block_zoh"})
            .real("disturbance_offset", 0.2, "c0 of f (eq. 14)")
            .unit("signal")
            .reals("disturbance_amplitudes", {1.0, 0.15, 0.1, 0.075, 0.06, 0.05, 0.3 / 7.0, 0.0375},
                   "F_1, F_2, ... of f (eq. 14); default: the Fig. 5 example F1 = 1, F_k = 0.3/k (k = 2..8)",
                   io::Range::non_negative())
            .unit("signal")
            .default_text("F1 = 1, F_k = 0.3/k (k = 2..8)")  // computed: 0.3/3 is not 0.1 (recorded as used)
            .reals("disturbance_phases", {}, "phi_1, phi_2, ...")
            .unit("rad")
            .default_text("random from disturbance_seed, phi_1 = 0")
            .integer("disturbance_seed", 1, "seed of the random phases", 0, 4294967295L)
            .reals("signal", {}, "the disturbance f as samples f(0), f(h), f(2h), ... over whole rotation periods "
                                 "(sampling: signal_sample_rate, signal_step_seconds or signal_step); replaces the "
                                 "disturbance_* keys")
            .unit("signal")
            .default_text("not given: f from disturbance_*")
            .only_if_given(fourier_keys())
            .file("signal_file", "", "the samples of signal as a column of a text file (CSV, tab- or blank-separated; "
                                     "docs/curve-files.md#text-exports), instead of signal")
            .default_text("not given")
            .only_if_given(fourier_keys())
            .text("signal_column", "", "the column of signal_file: header name or 1-based position (not given: the "
                                       "file's only column)")
            .default_text("the only column")
            .only_if_given()
            .real("signal_sample_rate", 1.0, "sample rate 1/h of signal: sample_rate x T must be a whole number",
                  io::Range::positive())
            .unit("samples/s")
            .default_text("not given")
            .only_if_given()
            .real("signal_step", 1.0, "sample step h of signal: 1/signal_step must be a whole number",
                  io::Range::positive())
            .unit("T")
            .default_text("not given")
            .only_if_given();
        add_si_alternative(p, "signal_step", SiUnit::Auto, io::Range::positive());
        p.integer("signal_harmonics", 0, "highest harmonic of f taken from signal (0: every k below half the samples "
                                         "per period)", 0, 100000000)
            .only_if_given()
            .real("delay_variation", 0.0, "amplitude of a slow sinusoidal delay variation (<= delay)",
                  io::Range::non_negative())
            .unit("T");
        add_si_alternative(p, "delay_variation", SiUnit::Auto, io::Range::non_negative());
        p.real("delay_variation_frequency", 0.0, "angular frequency of the delay variation", io::Range::non_negative())
            .unit("Omega");
        add_si_alternative(p, "delay_variation_frequency", SiUnit::Auto, io::Range::non_negative());
        p.integer("record_every", 10, "keep every n-th step in the CSV", 1, 1000000000)
            .integer("max_order", 15, "highest harmonic order k in the report (above N: what the controller does to "
                                     "harmonics it does not model); below steps_per_period/2", 1, 100000000)
            .default_text("5 above the highest of N and of the harmonics of f");
        add_output_params(p, "out/control_simulate.csv", "time-series");
      },
      with_si_inputs(run_simulate));
}

}  // namespace afmkit::cli
