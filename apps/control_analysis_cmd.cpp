// afmkit control roots | margin | chart | tune: closed-loop spectra of the seed-2 harmonic-rejection loop under
// delay (docs/theory-control.md#spectrum, #delay-margin), delay margins, stability charts (Figs. 2, 4) and robust tuning.
// Units follow control_params.hpp: rates and frequencies in units of Ω, delays in units of T = 2π/Ω; every CSV
// column and JSON value below uses the same units (roots in units of Ω, delays in units of T).
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/delay_margin.hpp"
#include "afmkit/control/loop_family.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/control/stability_chart.hpp"
#include "afmkit/control/stability_tau0.hpp"
#include "afmkit/control/tuning.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/progress.hpp"
#include "commands.hpp"
#include "control_params.hpp"

namespace afmkit::cli {

namespace {
using io::Range;

nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf")); }

// τ = 0 verdicts of stability_tau0.hpp (pass-through; basis K = γ, static plant).
nlohmann::json tau0_summary(const ControlSettings& c) {
  nlohmann::json j;
  const double w = c.rotation_frequency;
  const std::string inner = c.controller == "smith" ? c.smith_bank : c.controller;
  if (inner == "single") {
    j["eq13_stable"] = control::single_oscillator_stable_tau0(w, c.a, c.b, c.gain, c.plant_rate);
    j["eq13_b_limit_over_omega"] = c.plant_rate / c.gain;
  } else {
    const bool inf = inner == "infinite";
    const auto bc = inf ? control::critical_beta_limit(w) : control::critical_beta(c.harmonics, w);
    j["beta_critical_over_omega"] = bc.beta / w;
    j["design_point_stable"] = inf ? control::infinite_bank_stable_tau0(w, c.alpha, c.beta)
                                   : control::couplings_stable_tau0(c.harmonics, w, c.alpha, c.beta);
    j["basis"] = "K = gamma, static plant, tau = 0 (stability_tau0.hpp)";
  }
  return j;
}

// ------------------------------------------------------------------------------------------------ roots
void run_roots(const io::ParamSet& p) {
  const ControlSettings c = control_settings_from(p);
  const control::LoopSpec loop = control_loop_from(c);
  const double w = c.rotation_frequency;
  control::SpectrumOptions o;
  if (p.was_set("min_real")) o.min_real = p.real("min_real") * w;
  if (p.was_set("max_imag")) o.max_imag = p.real("max_imag") * w;
  o.count = static_cast<int>(p.integer("count"));
  o.collocation_nodes = static_cast<int>(p.integer("nodes"));
  const control::Spectrum sp = control::rightmost_roots(loop, o);

  nlohmann::json res;
  res["loop"] = loop.describe();
  res["delay_exceeds_period"] = loop.delay >= loop.period();
  res["box"] = {{"real_min", sp.box.real_min / w}, {"real_max", sp.box.real_max / w}, {"imag_min", sp.box.imag_min / w},
                {"imag_max", sp.box.imag_max / w}};
  res["box_count"] = sp.box_count;
  res["complete"] = sp.complete;
  res["box_is_proven"] = sp.box_is_proven;
  res["spectral_abscissa"] = num(sp.spectral_abscissa / w);
  res["decay_rate"] = num(-sp.spectral_abscissa / w);
  res["unstable_roots"] = sp.unstable_count;
  if (sp.neutral_bound) res["neutral_bound"] = num(*sp.neutral_bound / w);
  nlohmann::json st = nlohmann::json::array();
  for (const auto& s : sp.structural)
    st.push_back({{"real", s.value.real() / w}, {"imag", s.value.imag() / w}, {"multiplicity", s.multiplicity},
                  {"origin", s.origin}});
  res["structural_roots"] = st;
  res["notes"] = sp.notes;
  res["columns"] = {{"real", "Re s / Omega"}, {"imag", "Im s / Omega"},
                    {"multiplicity", "argument-principle count in a box isolating the root"},
                    {"certified", "multiplicity confirmed by that count (1) or not counted (0)"},
                    {"correction", "last Newton correction / Omega"},
                    {"kind", "root (in the certified box) | near_chain (N = inf, left of the box, Newton from the "
                             "chain asymptotics) | structural (docs/theory-control.md#neutral-realisation; neutral realisation only)"}};
  if (p.flag("json")) {
    res["roots"] = nlohmann::json::array();
    for (const auto& r : sp.roots)
      res["roots"].push_back({{"real", r.value.real() / w}, {"imag", r.value.imag() / w}, {"multiplicity", r.multiplicity}});
    res["near_chain"] = nlohmann::json::array();
    for (const auto& s : sp.near_chain) res["near_chain"].push_back({{"real", s.real() / w}, {"imag", s.imag() / w}});
    fmt::print("{}\n", res.dump(2));
    return;
  }
  const std::string out = p.text("output");
  io::TableWriter t(out, {"real", "imag", "multiplicity", "certified", "correction", "kind"});
  for (const auto& r : sp.roots)
    t.row(r.value.real() / w, r.value.imag() / w, static_cast<long>(r.multiplicity), r.certified, r.correction / w,
          "root");
  for (const auto& s : sp.near_chain) {
    t.row(s.real() / w, s.imag() / w, 1L, false, 0.0, "near_chain");
    if (s.imag() != 0.0) t.row(s.real() / w, -s.imag() / w, 1L, false, 0.0, "near_chain");
  }
  for (const auto& s : sp.structural)
    t.row(s.value.real() / w, s.value.imag() / w, static_cast<long>(s.multiplicity), true, 0.0, "structural");
  t.commit(io::make_sidecar("control roots", p.to_json(), res));
  fmt::print("{} roots in the box (argument principle: {}{}); spectral abscissa {:.10g} Omega, {} unstable -> {}\n",
             sp.roots.size(), sp.box_count, sp.complete ? ", complete" : ", INCOMPLETE", sp.spectral_abscissa / w,
             sp.unstable_count, out);
}

// ------------------------------------------------------------------------------------------------ margin
nlohmann::json margin_json(const control::DelayMargin& m, double w, double period) {
  nlohmann::json j;
  j["method"] = m.method;
  j["reference_delay"] = m.reference_delay / period;
  j["stable_at_reference"] = m.stable_at_reference;
  j["unstable_at_reference"] = m.unstable_at_reference;
  j["critical_delay"] = num(m.upper / period);
  j["crossing_frequency"] = num(m.upper_frequency / w);
  j["lower_delay"] = num(m.lower / period);
  j["lower_crossing_frequency"] = num(m.lower_frequency / w);
  j["critical_delay_exceeds_period"] = m.upper_exceeds_period;
  j["note"] = m.note;
  return j;
}

// τ_c of variants of the loop (beyond the paper): other rejected harmonics, N = ∞, Smith predictor.
void run_margin_compare(const io::ParamSet& p, const ControlSettings& base) {
  const double w = base.rotation_frequency, period = base.period;
  struct Row {
    std::string name;
    double upper, frequency, lower;
    bool stable;
  };
  std::vector<Row> table;
  nlohmann::json rows = nlohmann::json::array();
  const auto add = [&](const std::string& name, const ControlSettings& c) {
    const control::DelayMargin m = control::delay_margin(control_loop_from(c));
    table.push_back({name, m.upper / period, m.upper_frequency / w, m.lower / period, m.stable_at_reference});
    nlohmann::json j = margin_json(m, w, period);
    j["variant"] = name;
    rows.push_back(j);
  };
  ControlSettings c = base;
  c.controller = "bank";
  for (const std::vector<int>& rej : std::vector<std::vector<int>>{{1}, {1, 2}, {1, 3}, {2}, {1, 2, 3}, {1, 3, 5}}) {
    if (rej.back() > c.harmonics) continue;
    c.rejected = rej;
    std::string name = "bank N=" + std::to_string(c.harmonics) + " rejected=";
    for (std::size_t i = 0; i < rej.size(); ++i) name += (i ? "," : "") + std::to_string(rej[i]);
    add(name, c);
  }
  c = base;
  c.controller = "infinite";
  c.rejected = {1};
  add("infinite bank", c);
  c = base;
  c.controller = "single";
  add("single oscillator (a, b)", c);
  for (auto structure : {control::SmithPredictor::Structure::Periodic, control::SmithPredictor::Structure::Classic}) {
    c = base;
    c.controller = "smith";
    c.smith_bank = base.controller == "smith" ? base.smith_bank : base.controller;
    if (c.smith_bank == "infinite") c.rejected = {1};
    c.smith_structure = structure;
    add(fmt::format("Smith {} (model delay {:.4g} T) around {}",
                    structure == control::SmithPredictor::Structure::Periodic ? "periodic" : "classic",
                    c.model_delay / period, c.smith_bank),
        c);
  }
  nlohmann::json res;
  res["variants"] = rows;
  res["columns"] = {{"critical_delay", "upper end of the stability interval / T"},
                    {"crossing_frequency", "nu at the critical delay / Omega"},
                    {"lower_delay", "lower end / T (Smith: below the model delay)"}};
  if (p.flag("json")) {
    fmt::print("{}\n", res.dump(2));
    return;
  }
  const std::string out = p.text("output");
  io::TableWriter t(out, {"variant", "critical_delay", "crossing_frequency", "lower_delay", "stable_at_reference"});
  for (const Row& r : table) t.row(r.name, r.upper, r.frequency, r.lower, r.stable);
  t.commit(io::make_sidecar("control margin --compare", p.to_json(), res));
  fmt::print("wrote {} variants to {}\n", table.size(), out);
}

void run_margin(const io::ParamSet& p) {
  const ControlSettings c = control_settings_from(p);
  if (p.flag("compare")) return run_margin_compare(p, c);
  const control::LoopSpec loop = control_loop_from(c);
  const double w = c.rotation_frequency, period = c.period;
  control::MarginOptions o;
  if (p.was_set("reference_delay")) o.reference_delay = p.real("reference_delay") * period;
  o.grid_points_per_omega = static_cast<int>(p.integer("points_per_omega"));
  const control::DelayMargin m = control::delay_margin(loop, o);
  nlohmann::json res = margin_json(m, w, period);
  res["loop"] = loop.describe();
  res["tau0"] = tau0_summary(c);
  if (p.flag("json")) {
    fmt::print("{}\n", res.dump(2));
    return;
  }
  res["columns"] = {{"frequency", "crossing frequency nu / Omega (roots at +-i nu)"},
                    {"first_delay", "smallest delay with these roots on the axis / T"},
                    {"delay_period", "2 pi / nu / T (crossings repeat)"}};
  const std::string out = p.text("output");
  io::TableWriter t(out, {"frequency", "first_delay", "delay_period"});
  for (const auto& x : m.crossings) t.row(x.frequency / w, x.first_delay / period, x.delay_period / period);
  t.commit(io::make_sidecar("control margin", p.to_json(), res));
  if (m.stable_at_reference)
    fmt::print("critical delay tau_c = {:.6g} T (crossing at {:.6g} Omega, method {}) -> {}\n", m.upper / period,
               m.upper_frequency / w, m.method, out);
  else
    fmt::print("{} -> {}\n", m.note, out);
}

// ------------------------------------------------------------------------------------------------ chart
struct Window {
  double x_min, x_max, y_min, y_max;
};
Window window_from(const io::ParamSet& p, const control::LoopFamily& f, double w, Window single, Window couplings) {
  const Window d = f.kind == control::LoopFamily::Kind::SingleOscillator ? single : couplings;
  Window r;
  r.x_min = (p.was_set("x_min") ? p.real("x_min") : d.x_min) * w;
  r.x_max = (p.was_set("x_max") ? p.real("x_max") : d.x_max) * w;
  r.y_min = (p.was_set("y_min") ? p.real("y_min") : d.y_min) * w;
  r.y_max = (p.was_set("y_max") ? p.real("y_max") : d.y_max) * w;
  if (!(r.x_max > r.x_min))
    throw InvalidParameter("x_max", fmt::format("x_max = {} is out of range: must be > x_min = {}", r.x_max / w, r.x_min / w));
  if (!(r.y_max > r.y_min))
    throw InvalidParameter("y_max", fmt::format("y_max = {} is out of range: must be > y_min = {}", r.y_max / w, r.y_min / w));
  return r;
}

// The parameters as run: the window bounds replaced by the values actually used (the family defaults apply when
// x_min … y_max are not given), in units of Ω like the flags.
nlohmann::json params_as_run(const io::ParamSet& p, const Window& win, double w) {
  nlohmann::json j = p.to_json();
  j["x_min"] = win.x_min / w;
  j["x_max"] = win.x_max / w;
  j["y_min"] = win.y_min / w;
  j["y_max"] = win.y_max / w;
  return j;
}
nlohmann::json window_json(const Window& win, double w) {
  return {{"x_min", win.x_min / w}, {"x_max", win.x_max / w}, {"y_min", win.y_min / w}, {"y_max", win.y_max / w}};
}

void run_chart(const io::ParamSet& p) {
  const ControlSettings c = control_settings_from(p);
  const control::LoopSpec loop = control_loop_from(c);
  const double w = c.rotation_frequency, period = c.period;
  const control::LoopFamily family = control::LoopFamily::from_loop(loop);
  const Window win = window_from(p, family, w, {-0.5, 2.0, -2.0, 1.5}, {-0.1, 1.0, -0.4, 1.0});
  const int nx = static_cast<int>(p.integer("x_points")), ny = static_cast<int>(p.integer("y_points"));
  const int threads = static_cast<int>(p.integer("threads"));
  const std::string out = p.text("output");
  // memory of the grid (values, counts, labels and the tracked roots of each point), before any work
  require_memory("x_points", static_cast<double>(nx), static_cast<double>(ny) * 64.0);
  io::Progress progress("control chart (grid points)", static_cast<long>(nx) * ny, p.flag("progress"));
  const auto tick = [&progress](long n, long) { progress.advance(n); };
  nlohmann::json res;
  res["family"] = family.describe();
  res["x"] = family.x_name();
  res["y"] = family.y_name();
  res["delay_exceeds_period"] = loop.delay >= loop.period();
  res["window"] = window_json(win, w);
  res["x_points"] = nx;
  res["y_points"] = ny;
  const nlohmann::json params = params_as_run(p, win, w);
  if (p.text("quantity") == "margin") {
    const control::MarginMap m = control::delay_margin_map(family, win.x_min, win.x_max, nx, win.y_min, win.y_max, ny,
                                                           threads, tick);
    progress.finish();
    res["columns"] = {{"x", std::string(family.x_name()) + " / Omega"}, {"y", std::string(family.y_name()) + " / Omega"},
                      {"critical_delay", "tau_c / T (inf: no crossing, nan: unstable at tau = 0)"},
                      {"crossing_frequency", "nu at tau_c / Omega"}};
    io::TableWriter t(out, {"x", "y", "critical_delay", "crossing_frequency"});
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const std::size_t k = static_cast<std::size_t>(j) * nx + i;
        t.row(m.x[i] / w, m.y[j] / w, m.critical_delay[k] / period, m.crossing_frequency[k] / w);
      }
    t.commit(io::make_sidecar("control chart --quantity margin", params, res));
    fmt::print("wrote the {}x{} delay-margin map to {}\n", nx, ny, out);
    return;
  }
  control::ChartSpec spec;
  spec.family = family;
  spec.x_min = win.x_min;
  spec.x_max = win.x_max;
  spec.y_min = win.y_min;
  spec.y_max = win.y_max;
  spec.x_points = nx;
  spec.y_points = ny;
  spec.threads = threads;
  const control::StabilityChart chart = control::stability_chart(spec, tick);
  progress.finish();
  nlohmann::json regions = nlohmann::json::array();
  for (const auto& r : chart.regions)
    regions.push_back({{"id", r.id}, {"unstable_roots", r.unstable_roots}, {"tracked_roots", r.tracked_roots},
                       {"points", r.points}, {"x", r.x / w}, {"y", r.y / w}, {"certified", r.certified}});
  res["regions"] = regions;
  res["mismatched_points"] = chart.mismatched_points;
  res["recomputed_points"] = chart.recomputed_points;
  res["lower_bound_points"] = chart.lower_bound_points;
  const std::string bout = p.text("boundaries_output");
  res["boundaries_file"] = bout;
  res["columns"] = {{"x", std::string(family.x_name()) + " / Omega"}, {"y", std::string(family.y_name()) + " / Omega"},
                    {"spectral_abscissa", "max Re s / Omega (= -decay rate)"},
                    {"unstable_roots", "roots with Re s > 0 (region label, argument-principle count; -1: infinitely many)"},
                    {"region", "region id (connected set of equal counts)"}};
  io::TableWriter t(out, {"x", "y", "spectral_abscissa", "unstable_roots", "region"});
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * nx + i;
      t.row(chart.x[i] / w, chart.y[j] / w, chart.abscissa[k] / w, static_cast<long>(chart.unstable_roots[k]),
            static_cast<long>(chart.region[k]));
    }
  t.commit(io::make_sidecar("control chart", params, res));
  nlohmann::json bres;
  bres["family"] = family.describe();
  bres["columns"] = {{"curve", "polyline id"}, {"frequency", "crossing frequency nu / Omega (0: root at s = 0)"},
                     {"x", std::string(family.x_name()) + " / Omega"}, {"y", std::string(family.y_name()) + " / Omega"}};
  bres["window"] = window_json(win, w);
  io::TableWriter b(bout, {"curve", "frequency", "x", "y"});
  for (std::size_t ci = 0; ci < chart.boundaries.size(); ++ci)
    for (const auto& q : chart.boundaries[ci]) b.row(static_cast<long>(ci), q.frequency / w, q.x / w, q.y / w);
  b.commit(io::make_sidecar("control chart (D-subdivision boundaries)", params, bres));
  fmt::print("wrote the {}x{} chart ({} regions) to {} and {} boundary curves to {}\n", nx, ny, chart.regions.size(), out,
             chart.boundaries.size(), bout);
}

// ------------------------------------------------------------------------------------------------ tune
void run_tune(const io::ParamSet& p) {
  const ControlSettings c = control_settings_from(p);
  const control::LoopSpec loop = control_loop_from(c);
  const double w = c.rotation_frequency, period = c.period;
  control::RobustTuningSpec s;
  s.family = control::LoopFamily::from_loop(loop);
  const Window win = window_from(p, s.family, w, {0.01, 2.0, -2.0, 0.9}, {0.01, 0.6, -0.24, 0.3});
  s.x_min = win.x_min;
  s.x_max = win.x_max;
  s.y_min = win.y_min;
  s.y_max = win.y_max;
  s.delay_max = p.real("delay_max") * period;
  s.delay_points = static_cast<int>(p.integer("delay_points"));
  s.gain_ratio_min = p.real("gain_ratio_min");
  s.gain_ratio_max = p.real("gain_ratio_max");
  if (s.gain_ratio_max < s.gain_ratio_min)
    throw InvalidParameter("gain_ratio_max", fmt::format("gain_ratio_max = {} is out of range: must be >= "
                                                         "gain_ratio_min = {}", s.gain_ratio_max, s.gain_ratio_min));
  s.gain_points = static_cast<int>(p.integer("gain_points"));
  s.coarse_points = static_cast<int>(p.integer("coarse_points"));
  s.max_evaluations = static_cast<int>(p.integer("max_evaluations"));
  s.threads = static_cast<int>(p.integer("threads"));
  require_memory("coarse_points", static_cast<double>(s.coarse_points), s.coarse_points * 32.0);
  io::Progress progress("control tune (objective evaluations)",
                        static_cast<long>(s.coarse_points) * s.coarse_points + s.max_evaluations, p.flag("progress"));
  const control::RobustTuning r = control::robust_tuning(s, [&progress](long n, long) { progress.advance(n); });
  progress.finish();
  nlohmann::json res;
  res["family"] = s.family.describe();
  res["x"] = s.family.x_name();
  res["y"] = s.family.y_name();
  res["optimum"] = {{s.family.x_name(), r.x / w}, {s.family.y_name(), r.y / w}};
  res["worst_decay_rate"] = r.worst_decay / w;
  res["certified_worst_decay_rate"] = r.certified_worst_decay / w;
  res["worst_delay"] = r.worst_delay / period;
  res["worst_gain_ratio"] = r.worst_gain_ratio;
  nlohmann::json ms = nlohmann::json::array();
  for (const auto& m : r.margins)
    ms.push_back({{"gain_ratio", m.gain_ratio}, {"critical_delay", num(m.critical_delay / period)},
                  {"crossing_frequency", num(m.crossing_frequency / w)}});
  res["margins"] = ms;
  res["window"] = window_json(win, w);
  res["evaluations"] = r.evaluations;
  res["converged"] = r.converged;
  res["objective"] = "max over (x, y) of min over tau in [0, delay_max], rho in [gain_ratio_min, gain_ratio_max] "
                     "of the decay rate -max Re s (units of Omega)";
  if (p.flag("json")) {
    fmt::print("{}\n", res.dump(2));
    return;
  }
  res["columns"] = {{"x", std::string(s.family.x_name()) + " / Omega"}, {"y", std::string(s.family.y_name()) + " / Omega"},
                    {"worst_decay_rate", "coarse-grid objective / Omega"}};
  const std::string out = p.text("output");
  io::TableWriter t(out, {"x", "y", "worst_decay_rate"});
  const int n = s.coarse_points;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      t.row(r.coarse_x[i] / w, r.coarse_y[j] / w, r.coarse_worst_decay[static_cast<std::size_t>(j) * n + i] / w);
  t.commit(io::make_sidecar("control tune", params_as_run(p, win, w), res));
  fmt::print("robust optimum {} = {:.5g} Omega, {} = {:.5g} Omega: worst-case decay rate {:.5g} Omega (certified {:.5g}) -> {}\n",
             s.family.x_name(), r.x / w, s.family.y_name(), r.y / w, r.worst_decay / w, r.certified_worst_decay / w, out);
}

template <class Run>
void add_command(CLI::App& control, const std::string& name, const std::string& help,
                 const std::function<void(io::ParamSet&)>& extra, Run run) {
  auto params = std::make_shared<io::ParamSet>();
  add_control_params(*params);
  extra(*params);
  auto* cmd = control.add_subcommand(name, help);
  params->add_options(*cmd);
  cmd->callback([params, run] {
    params->resolve();
    run(*params);
  });
}
}  // namespace

void register_control_analysis(CLI::App& control) {
  add_command(
      control, "roots",
      "rightmost closed-loop roots under delay (Newton on the exact characteristic function, certified by the "
      "argument principle; N = inf: neutral chain bound and the structural diagnosis of docs/theory-control.md#neutral-realisation). Cost: O(N) per evaluation "
      "of the characteristic function; initial guesses by collocation (dense, N <= 40) or from the delay-free poles "
      "(Aberth, O(N^2)); certification O(N) evaluations along the box: O(N^2) in all",
      [](io::ParamSet& p) {
        p.group("Root search")
            .real("min_real", 0.0, "left edge of the search box [units of Omega]")
            .default_text("automatic")
            .real("max_imag", 1.0, "half-height of the search box [units of Omega]", Range::positive())
            .default_text("proven bound")
            .integer("count", 12, "automatic box: about this many rightmost roots", 1, 10000)
            .integer("nodes", 0, "Chebyshev collocation nodes per delay for the initial guesses (0: automatic)", 0, 400)
            .group("Output")
            .flag("json", false, "print the result as JSON to stdout instead of writing the CSV")
            .text("output", "out/control_roots.csv", "output CSV path (JSON sidecar next to it)");
      },
      run_roots);
  add_command(
      control, "margin",
      "delay margin tau_c (largest delay keeping the loop stable; crossing formulas of docs/theory-control.md#delay-margin). Cost: "
      "O(N) per crossing-function evaluation on points_per_omega x (N + 1) frequencies, O(N^2) stability check",
      [](io::ParamSet& p) {
        p.group("Delay margin")
            .real("reference_delay", 0.0, "delay where stability is required [units of T]", Range::non_negative())
            .default_text("0; Smith predictor: model_delay")
            .integer("points_per_omega", 64, "crossing-frequency bracketing grid density (points per Omega)", 4, 100000)
            .flag("compare", false, "tabulate tau_c for variants: rejected harmonics {1},{1,2},{1,3},{2},{1,2,3},"
                                    "{1,3,5}, N = inf, single oscillator, Smith predictor (periodic, classic)")
            .group("Output")
            .flag("json", false, "print the one-shot answer as JSON to stdout instead of writing the CSV")
            .text("output", "out/control_margin.csv", "output CSV path (crossings; JSON sidecar next to it)");
      },
      run_margin);
  add_command(
      control, "chart",
      "stability chart in the coupling plane (a, b) or (alpha, beta): spectral abscissa grid, certified region "
      "labels, exact D-subdivision boundaries (paper Figs. 2, 4). Cost: O(N) per Newton step of each tracked root per "
      "grid point, O(N^2) per fresh spectrum and per certified region",
      [](io::ParamSet& p) {
        p.group("Chart")
            .text("quantity", "abscissa", "abscissa: spectral abscissa + unstable roots; margin: tau_c map",
               {"abscissa", "margin"})
            .real("x_min", 0.0, "a or alpha lower bound [units of Omega]")
            .default_text("-0.5 single, -0.1 otherwise")
            .real("x_max", 1.0, "a or alpha upper bound [units of Omega]")
            .default_text("2 single, 1 otherwise")
            .real("y_min", 0.0, "b or beta lower bound [units of Omega]")
            .default_text("-2 single, -0.4 otherwise")
            .real("y_max", 1.0, "b or beta upper bound [units of Omega]")
            .default_text("1.5 single, 1 otherwise")
            .integer("x_points", 200, "grid points along x", 2, 100000)
            .integer("y_points", 200, "grid points along y", 2, 100000)
            .integer("threads", 0, "OpenMP threads (0: default)", 0, 1024)
            .group("Output")
            .flag("progress", true, "show progress on stderr")
            .text("output", "out/control_chart.csv", "grid CSV path (JSON sidecar next to it)")
            .text("boundaries_output", "out/control_chart_boundaries.csv", "boundary curves CSV path");
      },
      run_chart);
  add_command(
      control, "tune",
      "robust couplings: maximise the worst-case decay rate over delays [0, delay_max] and gain errors "
      "rho = K/gamma in [gain_ratio_min, gain_ratio_max] (coarse grid + Nelder-Mead). Cost: per objective evaluation "
      "O(N^2) per gain ratio (fresh spectrum) plus O(N) per tracked-root Newton step",
      [](io::ParamSet& p) {
        p.group("Tuning")
            .real("delay_max", 0.25, "largest delay [units of T]", Range::non_negative())
            .integer("delay_points", 6, "delay grid points on [0, delay_max]", 1, 10000)
            .real("gain_ratio_min", 0.5, "smallest rho = K/gamma", Range::positive())
            .real("gain_ratio_max", 2.0, "largest rho = K/gamma", Range::positive())
            .integer("gain_points", 3, "rho grid points (geometric)", 1, 10000)
            .real("x_min", 0.01, "a or alpha lower bound [units of Omega]")
            .real("x_max", 0.6, "a or alpha upper bound [units of Omega]")
            .default_text("2 single, 0.6 otherwise")
            .real("y_min", -0.24, "b or beta lower bound [units of Omega]")
            .default_text("-2 single, -0.24 otherwise")
            .real("y_max", 0.3, "b or beta upper bound [units of Omega]")
            .default_text("0.9 single, 0.3 otherwise")
            .integer("coarse_points", 12, "coarse grid points per axis", 2, 10000)
            .integer("max_evaluations", 150, "Nelder-Mead budget", 0, 1000000)
            .integer("threads", 0, "OpenMP threads (0: default)", 0, 1024)
            .group("Output")
            .flag("progress", true, "show progress on stderr")
            .flag("json", false, "print the optimum as JSON to stdout instead of writing the CSV")
            .text("output", "out/control_tune.csv", "coarse-grid CSV path (JSON sidecar next to it)");
      },
      run_tune);
}

}  // namespace afmkit::cli
