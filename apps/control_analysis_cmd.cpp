// afmkit control roots | margin (and the registration of chart | tune): closed-loop spectra of the seed-2
// harmonic-rejection loop under delay (docs/theory-control.md#spectrum) and delay margins (#delay-margin).
// Units follow control_params.hpp: rates, roots and frequencies in units of Ω, delays in units of T = 2π/Ω; every
// CSV column and JSON value below uses them (the sidecar's "columns" and the results' "units" name each one).
#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/delay_margin.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/control/stability_tau0.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/table.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "control_analysis.hpp"
#include "control_params.hpp"
#include "control_units.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

using control::ControllerKind;
using io::Range;

Window window_from(const io::ParamSet& p, const control::LoopFamily& f, Window single, Window couplings) {
  const Window d = f.kind == control::LoopFamily::Kind::SingleOscillator ? single : couplings;
  Window r;
  r.x_min = p.was_set("x_min") ? p.real("x_min") : d.x_min;
  r.x_max = p.was_set("x_max") ? p.real("x_max") : d.x_max;
  r.y_min = p.was_set("y_min") ? p.real("y_min") : d.y_min;
  r.y_max = p.was_set("y_max") ? p.real("y_max") : d.y_max;
  if (!(r.x_max > r.x_min))
    throw InvalidParameter("x_max", fmt::format("x_max = {} is out of range: must be > x_min = {}", r.x_max, r.x_min));
  if (!(r.y_max > r.y_min))
    throw InvalidParameter("y_max", fmt::format("y_max = {} is out of range: must be > y_min = {}", r.y_max, r.y_min));
  return r;
}

void add_window_params(io::ParamSet& p, const Window& single, const Window& couplings) {
  const auto bound = [&](const char* key, double Window::*field, const char* help) {
    p.real(key, couplings.*field, help).unit("Omega");
    if (single.*field != couplings.*field)
      p.default_text(fmt::format("{:g} single, {:g} otherwise", single.*field, couplings.*field));
    add_si_alternative(p, key);
  };
  bound("x_min", &Window::x_min, "a or alpha lower bound");
  bound("x_max", &Window::x_max, "a or alpha upper bound");
  bound("y_min", &Window::y_min, "b or beta lower bound");
  bound("y_max", &Window::y_max, "b or beta upper bound");
}

nlohmann::json window_json(const Window& w) {
  return {{"x_min", w.x_min}, {"x_max", w.x_max}, {"y_min", w.y_min}, {"y_max", w.y_max}, {"unit", "Omega"}};
}

std::vector<std::pair<std::string, double>> window_values(const Window& w) {
  return {{"x_min", w.x_min}, {"x_max", w.x_max}, {"y_min", w.y_min}, {"y_max", w.y_max}};
}

std::string describe_family(const control::LoopFamily& f) {
  const control::RotationUnits u(f.rotation_frequency);
  const std::string k = f.kind == control::LoopFamily::Kind::SingleOscillator ? "single oscillator (a, b)"
                        : f.kind == control::LoopFamily::Kind::Infinite       ? "N = infinity bank (alpha, beta)"
                                                                              : fmt::format("bank N={} (alpha, beta)", f.harmonics);
  std::string smith;
  if (f.smith)
    smith = fmt::format(" in a Smith predictor ({}, model {} gamma_hat={:g} Omega tau_hat={:g} T)",
                        control::to_string(f.smith->structure), control::to_string(f.smith->model_kind),
                        u.in_omega(f.smith->model_rate), u.in_periods(f.smith->model_delay));
  return fmt::format("{}{}, K={:g} Omega, {} plant gamma={:g} Omega, tau={:g} T (Omega = {:g} rad/s)", k, smith,
                     u.in_omega(f.gain), control::to_string(f.plant_kind), u.in_omega(f.plant_rate),
                     u.in_periods(f.delay), u.rotation_frequency());
}

namespace {

// τ = 0 verdicts of stability_tau0.hpp (pass-through; basis K = γ, static plant), in units of Ω: a record with its
// own units.
nlohmann::json tau0_summary(const control::ControlSettings& c) {
  UnitTagged j;
  const control::ControlSettingsSi si = control::to_si(c);
  const double w = si.rotation_frequency;
  const ControllerKind inner = c.bank_kind();
  if (inner == ControllerKind::Single) {
    j.add("eq13_stable", control::single_oscillator_stable_tau0(w, si.a, si.b, si.gain, si.plant_rate),
          "boolean (0/1)")
        .add("eq13_b_limit", si.plant_rate / si.gain, control::RotationUnits::rate_unit);  // γΩ/K in units of Ω
  } else {
    const bool inf = inner == ControllerKind::Infinite;
    const auto bc = inf ? control::critical_beta_limit(w) : control::critical_beta(c.harmonics, w);
    j.add("beta_critical", bc.beta, ControlUnits(c.units()).omega)
        .add("design_point_stable", inf ? control::infinite_bank_stable_tau0(w, si.alpha, si.beta)
                                        : control::couplings_stable_tau0(c.harmonics, w, si.alpha, si.beta),
             "boolean (0/1)")
        .add("basis", "K = gamma, static plant, tau = 0 (stability_tau0.hpp)");
  }
  return j.with_units();
}

// ------------------------------------------------------------------------------------------------ roots
// A row of `control roots`: a root s [rad/s] found in the box, near the chain or structural.
struct RootRow {
  std::complex<double> value;
  long multiplicity;
  bool certified;
  double correction;  // rad/s
  const char* kind;
};

io::TableOf<RootRow> roots_table(const control::RotationUnits& u) {
  const ControlUnits cu(u);
  using R = RootRow;
  return {{"real", cu.omega, "Re s of the root", [](const R& r) { return r.value.real(); }},
          {"imag", cu.omega, "Im s of the root", [](const R& r) { return r.value.imag(); }},
          {"multiplicity", "count", "argument-principle count in a box isolating the root", &R::multiplicity},
          {"certified", "boolean (0/1)", "multiplicity confirmed by that count (1) or not counted (0)", &R::certified},
          {"correction", cu.omega, "last Newton correction |ds|", [](const R& r) { return r.correction; }},
          {"kind", "label",
           "root (in the certified box) | near_chain (N = inf, left of the box, Newton from the chain "
           "asymptotics) | structural (docs/theory-control.md#neutral-realisation; neutral realisation only)",
           &R::kind}};
}

void run_roots(const io::ParamSet& p, Captured* capture) {
  const control::ControlSettings c = control_settings_from(p);
  const control::LoopSpec loop = control::loop_from(c);
  const control::RotationUnits u = c.units();
  control::SpectrumOptions o;
  if (p.was_set("min_real")) o.min_real = u.rate(p.real("min_real"));
  if (p.was_set("max_imag")) o.max_imag = u.rate(p.real("max_imag"));
  o.count = static_cast<int>(p.integer("count"));
  o.collocation_nodes = static_cast<int>(p.integer("nodes"));
  if (c.controller == ControllerKind::Smith && c.model_delay_value() > c.delay)
    require_delay_work(p, "model_delay", c.model_delay_value(), u, 1.0, c.harmonics, "one spectrum");
  else
    require_delay_work(p, "delay", c.delay, u, 1.0, c.harmonics, "one spectrum");
  const control::Spectrum sp = control::rightmost_roots(loop, o);
  // the record holds the box searched: the automatic edge and the proven half-height when not given
  io::ParamSet as_run = params_as_run(p, c);
  if (!p.was_set("min_real")) as_run.record_used("min_real", u.in_omega(sp.box.real_min));
  if (!p.was_set("max_imag")) as_run.record_used("max_imag", u.in_omega(sp.box.imag_max));
  CommandOutput out(as_run, capture, "control roots");

  const ControlUnits cu(u);
  const auto structural_root = [&](const control::StructuralRoot& s) {
    UnitTagged r;
    r.add("real", s.value.real(), cu.omega)
        .add("imag", s.value.imag(), cu.omega)
        .add("multiplicity", s.multiplicity, "count")
        .add("origin", s.origin);
    return r;
  };
  std::vector<UnitTagged> structural;
  for (const auto& s : sp.structural) structural.push_back(structural_root(s));
  UnitTagged res;
  res.add("loop", control::describe_in_rotation_units(loop))
      .add("settings", settings_json(c))  // records with their own units
      .add("settings_si", settings_si_json(c))
      .add("delay_exceeds_period", loop.delay >= loop.period(), "boolean (0/1)")
      .add("box",
           {{"real_min", sp.box.real_min}, {"real_max", sp.box.real_max}, {"imag_min", sp.box.imag_min},
            {"imag_max", sp.box.imag_max}},
           cu.omega)
      .add("box_count", sp.box_count, "count")
      .add("complete", sp.complete, "boolean (0/1)")
      .add("box_is_proven", sp.box_is_proven, "boolean (0/1)")
      .add("spectral_abscissa", sp.spectral_abscissa, cu.omega)
      .add("decay_rate", -sp.spectral_abscissa, cu.omega)
      .add("unstable_roots", sp.unstable_count, "count")
      .add("structural_roots", structural, structural_root(control::StructuralRoot{}))
      .add("notes", sp.notes);
  UnitTagged neutral;  // N = inf only; its unit listed always
  neutral.add("neutral_bound", sp.neutral_bound.value_or(0.0), cu.omega);
  if (sp.neutral_bound) res.merge(neutral);
  else res.units_of(neutral);
  auto rows = out.open(roots_table(u));
  for (const auto& r : sp.roots)
    rows.add({r.value, static_cast<long>(r.multiplicity), r.certified, r.correction, "root"});
  for (const auto& s : sp.near_chain) {
    rows.add({s, 1L, false, 0.0, "near_chain"});
    if (s.imag() != 0.0) rows.add({std::conj(s), 1L, false, 0.0, "near_chain"});
  }
  for (const auto& s : sp.structural)
    rows.add({s.value, static_cast<long>(s.multiplicity), true, 0.0, "structural"});
  out.finish(res.with_units(), fmt::format("{} roots in the box (argument principle: {}{}); spectral abscissa {}, {} unstable",
                              sp.roots.size(), sp.box_count, sp.complete ? ", complete" : ", INCOMPLETE",
                              rate_summary(sp.spectral_abscissa, u, 10), sp.unstable_count));
}

// ------------------------------------------------------------------------------------------------ margin
UnitTagged margin_record(const control::DelayMargin& m, const ControlUnits& u) {
  UnitTagged j;
  j.add("method", m.method)
      .add("reference_delay", m.reference_delay, u.period)
      .add("stable_at_reference", m.stable_at_reference, "boolean (0/1)")
      .add("unstable_at_reference", m.unstable_at_reference, "count")
      .add("critical_delay", m.upper, u.period)
      .add("crossing_frequency", m.upper_frequency, u.omega)
      .add("lower_delay", m.lower, u.period)
      .add("lower_crossing_frequency", m.lower_frequency, u.omega)
      .add("critical_delay_exceeds_period", m.upper_exceeds_period, "boolean (0/1)")
      .add("note", m.note);
  return j;
}

// A row of `control margin --compare`: a variant of the loop and its delay margin.
struct MarginVariant {
  const std::string& name;
  const control::DelayMargin& margin;
};

io::TableOf<MarginVariant> margin_compare_table(const control::RotationUnits& u) {
  const ControlUnits cu(u);
  using V = MarginVariant;
  return {{"variant", "label", "controller of the row", [](const V& v) { return v.name; }},
          {"critical_delay", cu.period, "upper end tau_c of the stability interval of delays (inf: no crossing)",
           [](const V& v) { return v.margin.upper; }},
          {"crossing_frequency", cu.omega, "crossing frequency nu at the critical delay (roots at +-i nu)",
           [](const V& v) { return v.margin.upper_frequency; }},
          {"lower_delay", cu.period, "lower end of the stability interval (0 plain loop; Smith: below the model delay)",
           [](const V& v) { return v.margin.lower; }},
          {"stable_at_reference", "boolean (0/1)", "stable at the reference delay",
           [](const V& v) { return v.margin.stable_at_reference; }}};
}

// τ_c of variants of the loop (beyond the paper): other rejected harmonics, N = ∞, Smith predictor.
void run_margin_compare(const io::ParamSet& p, const control::ControlSettings& base, Captured* capture) {
  const control::RotationUnits u = base.units();
  const io::ParamSet as_run = params_as_run(p, base);
  CommandOutput out(as_run, capture, "control margin --compare");
  auto table = out.open(margin_compare_table(u));
  const ControlUnits cu(u);
  std::vector<UnitTagged> rows;
  const auto add = [&](const std::string& name, const control::ControlSettings& c) {
    const control::DelayMargin m = control::delay_margin(control::loop_from(c));
    table.add({name, m});
    rows.push_back(margin_record(m, cu).add("variant", name));
  };
  control::ControlSettings c = base;
  c.controller = ControllerKind::Bank;
  for (const std::vector<int>& rej : std::vector<std::vector<int>>{{1}, {1, 2}, {1, 3}, {2}, {1, 2, 3}, {1, 3, 5}}) {
    if (rej.back() > c.harmonics) continue;
    c.rejected = rej;
    std::string name = "bank N=" + std::to_string(c.harmonics) + " rejected=";
    for (std::size_t i = 0; i < rej.size(); ++i) name += (i ? "+" : "") + std::to_string(rej[i]);  // no comma: CSV cell
    add(name, c);
  }
  c = base;
  c.controller = ControllerKind::Infinite;
  c.rejected = {1};
  add("infinite bank", c);
  c = base;
  c.controller = ControllerKind::Single;
  add("single oscillator", c);  // no comma: one CSV cell
  for (auto structure : {control::SmithPredictor::Structure::Periodic, control::SmithPredictor::Structure::Classic}) {
    c = base;
    c.controller = ControllerKind::Smith;
    c.smith_bank = base.bank_kind();
    if (c.smith_bank == ControllerKind::Infinite) c.rejected = {1};
    c.smith_structure = structure;
    add(fmt::format("Smith {} (model delay {:.4g} T) around {}", control::to_string(structure),
                    c.model_delay_value(), control::to_string(c.smith_bank)),
        c);
  }
  UnitTagged res;
  res.add("settings", settings_json(base))  // records with their own units
      .add("settings_si", settings_si_json(base))
      .add("variants", rows, margin_record(control::DelayMargin{}, cu));
  out.finish(res.with_units(), fmt::format("delay margins of {} variants", out.rows()));
}

io::TableOf<control::DelayCrossing> crossings_table(const control::RotationUnits& u) {
  const ControlUnits cu(u);
  using X = control::DelayCrossing;
  return {{"frequency", cu.omega, "crossing frequency nu (roots at +-i nu)",
           [](const X& x) { return x.frequency; }},
          {"first_delay", cu.period, "smallest delay with these roots on the imaginary axis",
           [](const X& x) { return x.first_delay; }},
          {"delay_period", cu.period, "2 pi/nu: the crossings repeat at first_delay + m delay_period",
           [](const X& x) { return x.delay_period; }}};
}

void run_margin(const io::ParamSet& p, Captured* capture) {
  const control::ControlSettings c = control_settings_from(p);
  if (p.flag("compare")) return run_margin_compare(p, c, capture);
  const control::LoopSpec loop = control::loop_from(c);
  const control::RotationUnits u = c.units();
  control::MarginOptions o;
  if (p.was_set("reference_delay")) o.reference_delay = u.delay(p.real("reference_delay"));
  // the stability check at the reference delay is one spectrum (0, or the Smith predictor's model delay)
  if (p.was_set("reference_delay"))
    require_delay_work(p, "reference_delay", p.real("reference_delay"), u, 1.0, c.harmonics, "stability at the "
                       "reference delay");
  else if (c.controller == ControllerKind::Smith)
    require_delay_work(p, "model_delay", c.model_delay_value(), u, 1.0, c.harmonics, "stability at the model delay");
  o.grid_points_per_omega = static_cast<int>(p.integer("points_per_omega"));
  const control::DelayMargin m = control::delay_margin(loop, o);
  io::ParamSet as_run = params_as_run(p, c);
  as_run.record_used("reference_delay", u.in_periods(m.reference_delay));  // 0, or model_delay (Smith predictor)
  CommandOutput out(as_run, capture, "control margin");
  UnitTagged res = margin_record(m, ControlUnits(u));
  res.add("loop", control::describe_in_rotation_units(loop))
      .add("settings", settings_json(c))  // records with their own units
      .add("settings_si", settings_si_json(c))
      .add("tau0", tau0_summary(c));
  out.open(crossings_table(u)).add_all(m.crossings);
  out.finish(res.with_units(), m.stable_at_reference
                      ? fmt::format("critical delay tau_c = {} (crossing at {}, method {})",
                                    delay_summary(m.upper, u, 6), rate_summary(m.upper_frequency, u, 6), m.method)
                      : m.note);
}

}  // namespace

void register_control_analysis(CLI::App& control) {
  add_command(
      control, "roots",
      "rightmost closed-loop roots under delay (Newton on the exact characteristic function, certified by the "
      "argument principle; N = inf: neutral chain bound and the structural diagnosis of "
      "docs/theory-control.md#neutral-realisation). Cost: O(N) per evaluation of the characteristic function; initial "
      "guesses by collocation (dense, N <= 40) or from the delay-free poles (Aberth, O(N^2)); certification O(N) "
      "evaluations along the box: O(N^2) in all",
      [](io::ParamSet& p) {
        add_control_params(p);
        p.group("Root search")
            .real("min_real", 0.0, "left edge of the search box")
            .unit("Omega")
            .default_text("automatic");
        add_si_alternative(p, "min_real");
        p.real("max_imag", 1.0, "half-height of the search box", Range::positive())
            .unit("Omega")
            .default_text("proven bound");
        add_si_alternative(p, "max_imag", SiUnit::Auto, Range::positive());
        p.integer("count", 12, "automatic box: about this many rightmost roots", 1, 10000)
            .integer("nodes", 0, "Chebyshev collocation nodes per delay for the initial guesses (0: automatic)", 0, 400);
        add_output_params(p, "out/control_roots.csv", "roots");
      },
      with_si_inputs(run_roots));
  add_command(
      control, "margin",
      "delay margin tau_c (largest delay keeping the loop stable; crossing formulas of "
      "docs/theory-control.md#delay-margin). Cost: O(N) per crossing-function evaluation on points_per_omega x (N + 1) "
      "frequencies, O(N^2) stability check",
      [](io::ParamSet& p) {
        add_control_params(p);
        p.group("Delay margin")
            .real("reference_delay", 0.0, "delay where stability is required", Range::non_negative())
            .unit("T")
            .default_text("0; Smith predictor: model_delay");
        add_si_alternative(p, "reference_delay", SiUnit::Auto, Range::non_negative());
        p.integer("points_per_omega", 64, "crossing-frequency bracketing grid density (points per Omega)", 4, 100000)
            .flag("compare", false, "tabulate tau_c for variants: rejected harmonics {1},{1,2},{1,3},{2},{1,2,3},"
                                    "{1,3,5}, N = inf, single oscillator, Smith predictor (periodic, classic)");
        add_output_params(p, "out/control_margin.csv", "crossings (with --compare: variants)");
      },
      with_si_inputs(run_margin));
  add_control_chart(control);
  add_control_tune(control);
}

}  // namespace afmkit::cli
