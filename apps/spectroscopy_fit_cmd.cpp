// afmkit spectroscopy fit: a registered force law (and the calibration: distance offset, amplitude scale, phase
// offset; FM: distance offset, frequency shift offset) fitted to a measured AM-AFM amplitude/phase-versus-distance
// curve, or to an FM-AFM frequency-shift (/dissipation) curve — chosen by the file's columns — by weighted nonlinear
// least squares over afmkit's periodic orbits (docs/fitting.md). The plot (--plot) is drawn by the Python package.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/spectroscopy/fit_input.hpp"
#include "cantilever_params.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "described_params.hpp"
#include "law_params.hpp"
#include "python_launch.hpp"
#include "spectroscopy_params.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

constexpr const char* kFmParameters = "hamaker,effective_modulus,distance_offset";  // FM default of `parameters`

/// The keys of one mode that the other does not read (refused when given).
const std::vector<std::string> kAmOnly = {"free_amplitude", "drive_frequency", "amplitude_scale", "phase_offset",
                                          "amplitude_noise", "phase_noise"};
const std::vector<std::string> kFmOnly = {"amplitude", "frequency_shift_offset", "frequency_shift_noise",
                                          "dissipation_noise"};

void refuse_other_mode(const io::ParamSet& p, spectroscopy::FitMode mode) {
  const bool fm = mode == spectroscopy::FitMode::fm;
  for (const std::string& key : fm ? kAmOnly : kFmOnly)
    if (p.was_set(key))
      throw InvalidParameter(key, fmt::format("{} does not apply to {} curve: file '{}' holds {} (the {} keys are {})",
                                              key, fm ? "an FM" : "an AM", p.text("file"),
                                              fm ? "a frequency shift column (FM-AFM)" : "an amplitude column (AM-AFM)",
                                              fm ? "FM" : "AM", fmt::join(fm ? kFmOnly : kAmOnly, ", ")));
}

/// The record of a run (sidecar, Python r.params): without the other mode's keys, which the run did not read (a
/// replay would give them, and be refused).
io::ParamSet record_of(const io::ParamSet& p, spectroscopy::FitMode mode) {
  io::ParamSet as_run = p;
  for (const std::string& key : mode == spectroscopy::FitMode::fm ? kAmOnly : kFmOnly)
    as_run.recorded_only_if_given(key);
  return as_run;
}

/// The fitted names of `parameters` (comma-separated, blanks ignored).
std::vector<std::string> parameter_list(const std::string& text) {
  std::vector<std::string> out;
  if (!text.empty() && text.back() == ',')
    throw InvalidParameter("parameters", fmt::format("parameters = '{}' ends with a comma: write names separated by "
                                                     "commas, e.g. hamaker,effective_modulus,distance_offset",
                                                     text));
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    if (b == std::string::npos)
      throw InvalidParameter("parameters", fmt::format("parameters = '{}' has an empty name: write names separated "
                                                       "by commas, e.g. hamaker,effective_modulus,distance_offset",
                                                       text));
    out.push_back(item.substr(b, e - b + 1));
  }
  return out;
}

/// A required measured setting (> 0), in SI.
double required_si(const io::ParamSet& p, const std::string& key, const std::string& unit) {
  if (!(p.real(key) > 0.0))
    throw InvalidParameter(key, fmt::format("{} is required (the measured setting, {}): must be > 0", key, unit));
  return real_si(p, key);
}

/// Every parameter of the run in the options of the library (SI).
spectroscopy::FitOptions fit_options(const io::ParamSet& p, spectroscopy::FitMode mode) {
  const bool fm = mode == spectroscopy::FitMode::fm;
  const impact::LawRegistry registry = impact::LawRegistry::builtin();
  spectroscopy::FitOptions o;
  o.law = p.text("law");
  const impact::LawSpec& spec = registry.find(o.law);
  o.force_curve = p.text("force_curve");
  o.allow_energy_gain = p.flag("allow_energy_gain");
  o.parameters = parameter_list(fm && !p.was_set("parameters") ? std::string(kFmParameters) : p.text("parameters"));
  for (const auto& k : registry.keys()) {
    const bool reads = std::find(spec.keys.begin(), spec.keys.end(), k.key) != spec.keys.end();
    if (p.was_set(k.key) && !reads)
      throw InvalidParameter(k.key, fmt::format("{} does not apply to law = {} (it is a parameter of law {})", k.key,
                                                o.law, fmt::join(registry.laws_using(k.key), ", ")));
    // given values, and the command's defaults of keys that neither follow another nor are alternatives
    if (reads && (p.was_set(k.key) || (k.follows.empty() && !k.only_if_given)))
      o.law_values[k.key] = p.real(k.key) * spectroscopy::law_unit_to_si(k.unit);
  }
  o.initial["distance_offset"] = real_si(p, "distance_offset");
  if (fm) {
    o.initial["frequency_shift_offset"] = p.real("frequency_shift_offset");
    o.frequency_shift_noise = p.real("frequency_shift_noise");
    o.dissipation_noise = real_si(p, "dissipation_noise");
  } else {
    o.initial["amplitude_scale"] = p.real("amplitude_scale");
    o.initial["phase_offset"] = real_si(p, "phase_offset");
  }
  o.direction = p.text("direction") == "retract" ? spectroscopy::CurveDirection::retract
                                                 : spectroscopy::CurveDirection::approach;
  o.amplitude_noise = p.real("amplitude_noise");
  o.phase_noise = real_si(p, "phase_noise");
  read_fields(p, o);  // huber … flat_column
  o.validate();
  return o;
}

/// The unit a fitted parameter is shown in (m -> nm, rad -> deg, Pa -> GPa, others SI).
units::Unit shown(const std::string& si_unit) {
  if (si_unit == "m") return units::from_si("nm");
  if (si_unit == "rad") return units::degrees_from_radians();
  if (si_unit == "Pa") return units::from_si("GPa");  // the registry's unit of moduli
  return units::as_is(si_unit);
}

/// The summary's and the sidecar's account of the estimates, shared by the modes (each entry with its unit; an
/// estimate's value, standard error and initial value in the parameter's unit, its `identifiable` flag its own);
/// returns the summary's lines.
std::string estimates_of(const spectroscopy::FitResult& r, UnitTagged& results) {
  UnitTagged estimates;
  std::vector<std::string> names;
  std::string summary;
  for (std::size_t j = 0; j < r.parameters.size(); ++j) {
    const auto& info = r.parameters[j];
    const units::Unit u = shown(info.unit);
    names.push_back(info.name);
    UnitTagged estimate;
    estimate.add("value", r.estimates[j], u)
        .add("standard_error", r.standard_errors[j], u)
        .add("initial", info.initial, u)
        .add("identifiable", static_cast<bool>(r.identifiable[j]), "boolean (0/1)")
        .add("transform", spectroscopy::transform_name(info.transform));
    estimates.add(info.name, std::move(estimate));
    summary += fmt::format("\n  {} = {} ± {}", info.name, io::quantity(u(r.estimates[j]), u.name),
                           io::quantity(u(r.standard_errors[j]), u.name));
  }
  UnitTagged law;  // every law value used, SI
  {
    const impact::LawRegistry registry = impact::LawRegistry::builtin();
    for (const auto& [k, v] : r.law_values) {
      bool known = false;  // a key of the registry: its SI unit
      for (const auto& key : registry.keys())
        if (key.key == k && !known) {
          law.add(k, v, units::as_is(spectroscopy::law_si_unit(key.unit)));
          known = true;
        }
      if (!known) law.add(k, v);
    }
  }
  results.add("mode", spectroscopy::fit_mode_name(r.mode))
      .add("status", spectroscopy::fit_status_name(r.status))
      .add("note", r.status == spectroscopy::FitStatus::ok
                       ? std::string()
                       : fmt::format("the fit did not converge: {} (estimates at the best point found)",
                                     r.solver_status))
      .add("solver_status", r.solver_status)
      .add("estimates", std::move(estimates))
      .add("parameters", names)
      .add("correlation", r.correlation, "dimensionless")
      .add("warnings", r.warnings)
      .add("condition_number", r.condition_number, "dimensionless")
      .add("reduced_chi2", r.reduced_chi2, "dimensionless")
      .add("iterations", r.iterations, "count")
      .add("curve_evaluations", r.curve_evaluations, "count")
      .add("orbit_evaluations", r.orbit_evaluations, "count")
      .add("failed_evaluations", r.failed_evaluations, "count")
      .add("seconds", r.seconds, "s")
      .add("law_values", std::move(law));
  return summary;
}

/// --plot: data vs fit, drawn by Matplotlib from the table just written (the process becomes the interpreter).
void draw_plot(const io::ParamSet& p) {
  if (!p.text("plot").empty()) exec_python_module("_fit_plot", {"--plot", p.text("output"), p.text("plot")});
}

std::string closing_lines(const spectroscopy::FitResult& r) {
  std::string summary = fmt::format("\n  {} iterations, {} curve evaluations, {} orbit evaluations, {}", r.iterations,
                                    r.curve_evaluations, r.orbit_evaluations, io::quantity(r.seconds, "s", 3));
  for (const std::string& w : r.warnings) summary += "\n  warning: " + w;
  return summary;
}

/// The FM fit: settings, table and summary of a frequency-shift curve.
void run_fm_fit(const io::ParamSet& p, Captured* capture, const spectroscopy::FmFitCurve& curve) {
  spectroscopy::FmFitSettings s;
  s.spring_constant = required_si(p, "spring_constant", "N/m");
  s.resonance_frequency = required_si(p, "resonance_frequency", "kHz");
  s.quality_factor = required_si(p, "quality_factor", "dimensionless");
  s.amplitude = required_si(p, "amplitude", "nm, the oscillation amplitude held by the amplitude loop");
  s.validate();
  spectroscopy::FitOptions options = fit_options(p, spectroscopy::FitMode::fm);
  spectroscopy::fit_parameter_info(options, spectroscopy::FitMode::fm);
  curve.validate();
  options.cancellation = cancellation_of(capture);
  const spectroscopy::FitResult r = spectroscopy::fit_fm_curve(curve, s, options);

  io::ParamSet as_run = record_of(p, spectroscopy::FitMode::fm);  // the FM default of `parameters`: the list fitted
  if (!p.was_set("parameters")) as_run.record_used("parameters", std::string(kFmParameters));
  CommandOutput out(as_run, capture, "spectroscopy fit");
  const bool diss = !r.dissipation.empty();
  // SI results shown in nm and eV (the output edge: each column's unit converts its values); rows: point indices
  const units::Unit nm = units::from_si("nm"), Hz = units::from_si("Hz"), eV = units::from_si("eV");
  using I = std::size_t;
  std::vector<io::ColumnOf<I>> columns = {
      {"distance", nm, "measured distance (piezo separation; model separation = distance + distance_offset)",
       [&r](I i) { return r.distance[i]; }},
      {"frequency_shift", Hz, "measured frequency shift Δf", [&r](I i) { return r.frequency_shift[i]; }},
      {"fitted_frequency_shift", Hz, "model frequency shift at the estimates + frequency_shift_offset",
       [&r](I i) { return r.fitted_frequency_shift[i]; }},
      {"frequency_shift_residual", Hz, "measured − fitted frequency shift",
       [&r](I i) { return r.frequency_shift[i] - r.fitted_frequency_shift[i]; }}};
  if (diss) {
    columns.push_back({"dissipation", eV, "measured energy dissipated per cycle", [&r](I i) { return r.dissipation[i]; }});
    columns.push_back({"fitted_dissipation", eV, "model energy taken by the tip–sample force per cycle",
                       [&r](I i) { return r.fitted_dissipation[i]; }});
    columns.push_back({"dissipation_residual", eV, "measured − fitted dissipation",
                       [&r](I i) { return r.dissipation[i] - r.fitted_dissipation[i]; }});
  }
  columns.push_back({"contact", "boolean (0/1)", "the orbit reaches the law's contact gap",
                     [&r](I i) { return static_cast<bool>(r.contact[i]); }});
  columns.push_back({"jumped", "boolean (0/1)", "the FM orbit was reached past a fold of the branch",
                     [&r](I i) { return static_cast<bool>(r.jumped[i]); }});
  auto rows = out.open(io::TableOf<I>(std::move(columns)));
  for (I i = 0; i < r.distance.size(); ++i) rows.add(i);
  UnitTagged results;
  std::string summary = fmt::format("fit of law {} to {} points (FM-AFM frequency shift{}, {}): status {} ({})",
                                    options.law, r.distance.size(), diss ? " and dissipation" : "",
                                    p.text("direction"), spectroscopy::fit_status_name(r.status), r.solver_status);
  summary += estimates_of(r, results);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  UnitTagged noise_estimated;
  noise_estimated.add("frequency_shift", r.noise_estimated_frequency_shift, "boolean (0/1)")
      .add("dissipation", r.noise_estimated_dissipation, "boolean (0/1)");
  results.add("rms_frequency_shift", r.rms_frequency_shift, Hz)
      .add("rms_dissipation", diss ? r.rms_dissipation : nan, eV)
      .add("frequency_shift_noise", r.frequency_shift_noise, Hz)
      .add("dissipation_noise", diss ? r.dissipation_noise : nan, eV)
      .add("noise_estimated", std::move(noise_estimated));
  summary += fmt::format("\n  residual RMS: {}{}; noise σ: {}{}{}", io::quantity(r.rms_frequency_shift, "Hz"),
                         diss ? ", " + io::quantity(eV(r.rms_dissipation), eV.name) : std::string(),
                         io::quantity(r.frequency_shift_noise, "Hz"),
                         r.noise_estimated_frequency_shift ? " (estimated)" : "",
                         diss ? fmt::format(", {}{}", io::quantity(eV(r.dissipation_noise), eV.name),
                                            r.noise_estimated_dissipation ? " (estimated)" : "")
                              : std::string());
  summary += closing_lines(r);
  out.finish(std::move(results).summary(), summary);
  draw_plot(p);
}

void run_fit(const io::ParamSet& p, Captured* capture) {
  if (p.text("file").empty())
    throw InvalidParameter("file", "file is required: the measured curve file (AM: distance, amplitude, phase; FM: "
                                    "distance, frequency shift, dissipation; units in the header; "
                                    "docs/fitting.md#input)");
  if (!p.text("plot").empty() && p.text("output").empty())
    throw InvalidParameter("plot", "plot needs output: the plot is drawn from the fitted curve's CSV file");
  if (!p.text("plot").empty() && capture)
    throw InvalidParameter("plot", "plot is drawn by the command line; in Python call afmkit.spectroscopy_fit.plot");
  // the file's columns choose the mode: a frequency shift column is an FM curve, an amplitude column an AM curve
  const spectroscopy::FitCurveFile file = spectroscopy::read_fit_curve(p.text("file"));
  refuse_other_mode(p, file.mode);
  if (file.mode == spectroscopy::FitMode::fm) return run_fm_fit(p, capture, file.fm);
  spectroscopy::FitSettings s;
  s.spring_constant = required_si(p, "spring_constant", "N/m");
  s.resonance_frequency = required_si(p, "resonance_frequency", "kHz");
  s.quality_factor = required_si(p, "quality_factor", "dimensionless");
  s.free_amplitude = required_si(p, "free_amplitude", "nm");
  s.drive_frequency = real_si(p, "drive_frequency");
  s.validate();
  const spectroscopy::FitOptions options = fit_options(p, spectroscopy::FitMode::am);
  spectroscopy::fit_parameter_info(options);  // refuses unknown names before the fit
  const spectroscopy::FitCurve& curve = file.am;
  curve.validate();
  spectroscopy::FitOptions run = options;
  run.cancellation = cancellation_of(capture);
  const spectroscopy::FitResult r = spectroscopy::fit_am_curve(curve, s, run);

  const io::ParamSet as_run = record_of(p, spectroscopy::FitMode::am);  // CommandOutput keeps a reference
  CommandOutput out(as_run, capture, "spectroscopy fit");
  const bool phase = !r.phase.empty();
  // SI results shown in nm and deg (the output edge: each column's unit converts its values); rows: point indices
  const units::Unit nm = units::from_si("nm"), deg = units::degrees_from_radians();
  using I = std::size_t;
  std::vector<io::ColumnOf<I>> columns = {
      {"distance", nm, "measured distance (piezo separation; model separation = distance + distance_offset)",
       [&r](I i) { return r.distance[i]; }},
      {"amplitude", nm, "measured amplitude", [&r](I i) { return r.amplitude[i]; }},
      {"fitted_amplitude", nm, "model amplitude at the estimates, as measured (A_model / amplitude_scale)",
       [&r](I i) { return r.fitted_amplitude[i]; }},
      {"amplitude_residual", "dimensionless", "(measured − fitted) amplitude / free_amplitude",
       [&r, &s](I i) { return (r.amplitude[i] - r.fitted_amplitude[i]) / s.free_amplitude; }}};
  if (phase) {
    columns.push_back({"phase", deg, "measured phase", [&r](I i) { return r.phase[i]; }});
    columns.push_back({"fitted_phase", deg, "model phase at the estimates + phase_offset",
                       [&r](I i) { return r.fitted_phase[i]; }});
    columns.push_back({"phase_residual", deg, "measured − fitted phase, wrapped to (−180, 180]", [&r](I i) {
                         return std::remainder(r.phase[i] - r.fitted_phase[i], 2.0 * 3.14159265358979323846);
                       }});
  }
  columns.push_back({"contact", "boolean (0/1)", "the orbit reaches the law's contact gap",
                     [&r](I i) { return static_cast<bool>(r.contact[i]); }});
  columns.push_back({"jumped", "boolean (0/1)", "the response jumped to another branch before this point",
                     [&r](I i) { return static_cast<bool>(r.jumped[i]); }});
  auto rows = out.open(io::TableOf<I>(std::move(columns)));
  for (I i = 0; i < r.distance.size(); ++i) rows.add(i);

  UnitTagged results;
  std::string summary = fmt::format("fit of law {} to {} points ({}): status {} ({})", options.law, r.distance.size(),
                                    p.text("direction"), spectroscopy::fit_status_name(r.status), r.solver_status);
  summary += estimates_of(r, results);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  UnitTagged noise_estimated;
  noise_estimated.add("amplitude", r.noise_estimated_amplitude, "boolean (0/1)")
      .add("phase", r.noise_estimated_phase, "boolean (0/1)");
  results.add("rms_amplitude", r.rms_amplitude, "dimensionless (A/A0)")
      .add("rms_phase", phase ? r.rms_phase : nan, deg)
      .add("amplitude_noise", r.amplitude_noise, "dimensionless (A/A0)")
      .add("phase_noise", phase ? r.phase_noise : nan, deg)
      .add("noise_estimated", std::move(noise_estimated));
  summary += fmt::format("\n  residual RMS: {:.4g} (A/A0){}; noise σ: {:.3g} (A/A0{}){}", r.rms_amplitude,
                         phase ? fmt::format(", {:.4g} deg", deg(r.rms_phase)) : std::string(), r.amplitude_noise,
                         r.noise_estimated_amplitude ? ", estimated" : "",
                         phase ? fmt::format(", {:.3g} deg{}", deg(r.phase_noise),
                                             r.noise_estimated_phase ? " (estimated)" : "")
                               : std::string());
  summary += closing_lines(r);
  out.finish(std::move(results).summary(), summary);
  draw_plot(p);
}

}  // namespace

void register_spectroscopy_fit(CLI::App& spectroscopy) {
  add_command(
      spectroscopy, "fit",
      "fit a force law (and the calibration: distance offset, amplitude scale, phase offset; FM: distance offset, "
      "frequency shift offset) to a measured AM-AFM amplitude/phase-versus-distance curve or an FM-AFM frequency-shift "
      "curve (the file's columns decide) by weighted least squares over afmkit's periodic orbits",
      [](io::ParamSet& p) {
        p.group("Measured curve");
        p.file("file", "", "measured curve: CSV of distance, amplitude and (optionally) phase (AM), or distance, "
                            "frequency shift and (optionally) dissipation (FM), with units in the header "
                            "(docs/fitting.md#input)")
            .positional()
            .default_text("required");
        const auto required = CantileverDefault::required();
        add_cantilever_param(p, CantileverKey::spring_constant, required, "cantilever spring constant k (required)");
        add_cantilever_param(p, CantileverKey::resonance_frequency, required, "resonance frequency f0 (required)");
        add_cantilever_param(p, CantileverKey::quality_factor, required, "quality factor Q (required)");
        add_cantilever_param(p, CantileverKey::free_amplitude, required,
                             "AM: free amplitude A0 at the drive frequency (required)");
        add_cantilever_param(p, CantileverKey::amplitude, required,
                             "FM: oscillation amplitude A held by the amplitude loop (required)");
        add_drive_frequency_param(p);
        p.text("direction", "approach", "the branch the curve is: approach (from the largest distance down) or "
                                           "retract (after the approach down to the smallest distance)",
                  {"approach", "retract"});
        p.group("Fit")
            .text("parameters", "hamaker,effective_modulus,distance_offset,phase_offset",
                  "fitted parameters, comma-separated: keys of the law and/or distance_offset, amplitude_scale, "
                  "phase_offset (AM) or distance_offset, frequency_shift_offset (FM; default there "
                  "hamaker,effective_modulus,distance_offset); the others stay at their given values")
            .real("distance_offset", 0.0, "d0: model separation = distance + d0 (initial or fixed value)",
                  io::Range::closed(-1e6, 1e6))
            .unit("nm")
            .real("frequency_shift_offset", 0.0, "FM: Δf0, measured Δf = model Δf + Δf0 (initial or fixed)",
                  io::Range::closed(-1e9, 1e9))
            .unit("Hz")
            .real("frequency_shift_noise", 0.0, "FM: σ of the measured Δf (0: estimated from the data's scatter)",
                  io::Range::non_negative())
            .unit("Hz")
            .real("dissipation_noise", 0.0, "FM: σ of the measured dissipation (0: estimated from the data's scatter)",
                  io::Range::non_negative())
            .unit("eV")
            .real("amplitude_scale", 1.0, "s: true amplitude = s × measured (an InvOLS error; initial or fixed)",
                  io::Range::positive())
            .unit("dimensionless")
            .real("phase_offset", 0.0, "φ0: measured phase = model phase + φ0 (initial or fixed)",
                  io::Range::closed(-360.0, 360.0))
            .unit("deg")
            .real("amplitude_noise", 0.0, "σ of the measured A/A0 (0: estimated from the data's scatter)",
                  io::Range::non_negative())
            .unit("dimensionless")
            .real("phase_noise", 0.0, "σ of the measured phase (0: estimated from the data's scatter)",
                  io::Range::non_negative())
            .unit("deg");
        declare_fields(p, spectroscopy::FitOptions{});  // huber … flat_column, as the library declares them
        add_law_params(p, impact::LawRegistry::builtin(), "dmt");
        add_output_params(p, "out/spectroscopy_fit.csv", "measured and fitted curve");
        p.file("plot", "", "PNG of data vs fit (Matplotlib, through the Python package; needs output); empty: none")
            .writes();
      },
      run_fit);
}

}  // namespace afmkit::cli
