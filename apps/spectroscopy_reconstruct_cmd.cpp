// afmkit spectroscopy reconstruct: a measured FM (distance, Δf) or AM (separation, amplitude, phase) curve → the
// tip–sample force, a table law, and the round trip (docs/reconstruction.md).
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/spectroscopy/reconstruct_am.hpp"
#include "afmkit/spectroscopy/reconstruct_fm.hpp"
#include "afmkit/spectroscopy/reconstruct_input.hpp"
#include "afmkit/spectroscopy/reconstruct_law.hpp"
#include "cantilever_params.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "described_params.hpp"
#include "spectroscopy_params.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

/// The table-law file (3 columns, nm and nN) and its sidecar: the columns, where the law came from and the
/// hysteresis rule its round trip used (docs/reconstruction.md#round-trip).
void add_law_file(CommandOutput& out, const std::string& path, const impact::ForceCurve& law, const std::string& origin,
                  const std::string& hysteresis) {
  out.outputs().add(path, spectroscopy::table_law_text(law, ""));
  const nlohmann::json sidecar = {
      {"program", "afmkit"},
      {"command", "spectroscopy reconstruct"},
      {"what", "table law (afmkit tapping … --law table --force-curve FILE; docs/force-laws.md)"},
      {"origin", origin},
      {"hysteresis", hysteresis},
      {"columns",
       {{{"name", "distance (nm)"}, {"unit", "nm"}, {"description", "tip–sample distance (gap d; d < 0 in contact)"}},
        {{"name", "approach force (nN)"}, {"unit", "nN"}, {"description", "approach branch H_a (> 0 repulsive)"}},
        {{"name", "retract force (nN)"}, {"unit", "nN"}, {"description", "retract branch H_b (> 0 repulsive)"}}}}};
  out.outputs().add(path + ".json", sidecar.dump(2) + "\n");
}

nlohmann::json notes_json(const std::vector<std::string>& notes) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& n : notes) j.push_back(n);
  return j;
}

/// A column read from the i-th element of `values` (a curve's per-point results; rows are point indices).
auto element_of(const std::vector<double>& values) {
  return [&values](std::size_t i) { return values[i]; };
}

std::string notes_text(const std::vector<std::string>& notes) {
  std::string s;
  for (const auto& n : notes) s += "\nnote: " + n;
  return s;
}

void run_fm(const io::ParamSet& p, Captured* capture, const spectroscopy::MeasuredCurve& m) {
  std::string method = p.text("method");
  if (method == "auto") method = "sader_jarvis";
  const spectroscopy::FmSettings s(real_si(p, "spring_constant"), real_si(p, "resonance_frequency"),
                                   real_si(p, "amplitude"));
  spectroscopy::FmOptions o;
  o.method = spectroscopy::fm_method_from(method);
  o.tail = spectroscopy::tail_model_from(p.text("tail"));
  o.noise_realisations = static_cast<int>(p.integer("noise_realisations"));
  o.exact_round_trip = p.text("round_trip") == "exact";
  o.round_trip_points = static_cast<int>(p.integer("round_trip_points"));
  o.quality_factor = p.real("quality_factor");
  const auto r = spectroscopy::reconstruct_fm({m.distance, m.frequency_shift}, s, o);

  // SI results shown in nm, nN, aJ (the output edge: each column's unit converts its values)
  const units::Unit nm = units::from_si("nm"), nN = units::from_si("nN"), aJ = units::from_si("aJ"),
                    Hz = units::from_si("Hz");
  CommandOutput out(p, capture, "spectroscopy reconstruct");
  auto rows = out.open(io::TableOf<std::size_t>{
      {"distance", nm, "closest tip–sample distance of the oscillation", element_of(r.distance)},
      {"frequency_shift", Hz, "measured frequency shift", element_of(r.frequency_shift)},
      {"force", nN, "reconstructed tip–sample force (positive repulsive)", element_of(r.force)},
      {"force_uncertainty", nN, "1σ of the force from the noise estimated in the frequency shift",
       element_of(r.force_uncertainty)},
      {"energy", aJ, "interaction energy U(z) = ∫_z^∞ F dt", element_of(r.energy)},
      {"round_trip_frequency_shift", Hz,
       "frequency shift of the reconstructed law by the first-order large-amplitude formula",
       element_of(r.round_trip_frequency_shift)},
      {"residual", Hz, "round trip − measured", element_of(r.residual)}});
  for (std::size_t i = 0; i < r.distance.size(); ++i) rows.add(i);
  const std::string law_path = p.text("law_output");
  if (!law_path.empty())
    add_law_file(out, law_path, r.law, fmt::format("force reconstructed by afmkit spectroscopy reconstruct ({}, FM) "
                                                   "from {}", r.method, p.text("input")), "any (a conservative law: both branches equal)");
  double f_min = 0.0;
  for (double f : r.force) f_min = std::min(f_min, f);
  UnitTagged tagged;
  tagged.add("mode", "fm")
      .add("method", r.method)
      .add("tail", spectroscopy::to_string(r.tail.active ? spectroscopy::TailModel::exponential
                                                         : spectroscopy::TailModel::zero))
      .add("points", r.distance.size(), "count")
      .add("largest_attraction", f_min, nN)
      .add("noise", r.noise, Hz)
      .add("interaction_length", r.interaction_length, nm)
      .add("tail_sensitivity", r.tail_sensitivity, nN)
      .add("residual_rms", r.residual_rms, Hz)
      .add("residual_max", r.residual_max, Hz)
      .add("round_trip_model", r.round_trip_model)
      .add("law_output", law_path)
      .add("status", "ok")
      .add("notes", notes_json(r.notes));
  const std::string summary = fmt::format(
      "FM reconstruction ({}, {} points): largest attraction {}; round trip ({}): residual {} rms, {} max; noise "
      "{}{}",
      r.method, r.distance.size(), io::quantity(f_min, "N"), o.exact_round_trip ? "exact FM orbits" : "first-order formula",
      io::quantity(r.residual_rms, "Hz"),
      io::quantity(r.residual_max, "Hz"), io::quantity(r.noise, "Hz"), notes_text(r.notes));
  out.finish(std::move(tagged).summary(), summary);
}

void run_am(const io::ParamSet& p, Captured* capture, spectroscopy::MeasuredCurve m) {
  const std::string& file = p.text("input");
  const bool mirrored = p.text("phase_convention") == "mirrored";
  // SI results shown in nm, nN, aJ, deg (the output edge: each column's unit converts its values)
  const units::Unit nm = units::from_si("nm"), nN = units::from_si("nN"), aJ = units::from_si("aJ"),
                    deg = units::degrees_from_radians(), rad = units::from_si("rad");
  for (std::size_t i = 0; i < m.phase.size(); ++i) {
    if (mirrored) m.phase[i] = std::numbers::pi - m.phase[i];
    if (!(m.amplitude[i] > 0.0))
      throw InputError(fmt::format("{}:{}: column amplitude: {} m is out of range: the amplitude must be > 0", file,
                                   m.lines[i], m.amplitude[i]));
    if (!(m.phase[i] > 0.0 && m.phase[i] < std::numbers::pi))
      throw InputError(fmt::format("{}:{}: column phase: {}° ({}) is out of range: must be in (0°, 180°), the lag "
                                   "of the response behind the drive (phase_convention = lag; docs/conventions.md)",
                                   file, m.lines[i], deg(m.phase[i]), mirrored ? "after mirroring" : "as given"));
  }
  std::string method = p.text("method");
  if (method == "auto") method = "payam";
  const spectroscopy::AmSettings s(real_si(p, "spring_constant"), real_si(p, "resonance_frequency"),
                                   p.real("quality_factor"), real_si(p, "free_amplitude"),
                                   real_si(p, "drive_frequency"));
  spectroscopy::AmOptions o;
  o.method = spectroscopy::am_method_from(method);
  if (o.method == spectroscopy::AmMethod::katan)  // Katan's equivalent oscillator needs 1 + 2 Ω_eq > 0
    for (std::size_t i = 0; i < m.phase.size(); ++i)
      if (!(1.0 + 2.0 * spectroscopy::equivalent_frequency_shift(m.amplitude[i], m.phase[i], s) > 0.0))
        throw InputError(fmt::format("{}:{}: column phase: {}° with amplitude {} nm has no equivalent oscillator for "
                                     "method katan: 1 + (A0/(Q A)) cos φ must be > 0 (use payam or hoelscher; "
                                     "docs/reconstruction.md#am-sources)",
                                     file, m.lines[i], deg(m.phase[i]), nm(m.amplitude[i])));
  o.tail = spectroscopy::tail_model_from(p.text("tail"));
  o.round_trip_points = static_cast<int>(p.integer("round_trip_points"));
  const auto r = spectroscopy::reconstruct_am({m.distance, m.amplitude, m.phase}, s, o);

  // the per-point force lives on the points used (ascending D = ascending l among them): row i, and k of the force
  struct AmRow {
    std::size_t i;
    std::size_t k;
    bool used;
  };
  std::vector<AmRow> am_rows;
  for (std::size_t i = 0, k = 0; i < r.separation.size(); ++i) {
    const double d = r.separation[i] - r.amplitude[i];
    const bool used = k < r.gap.size() && std::abs(r.gap[k] - d) <= 1e-15;
    am_rows.push_back({i, k, used});
    if (used) ++k;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto at_used = [nan](const std::vector<double>& v) {
    return [&v, nan](const AmRow& w) { return w.used ? v[w.k] : nan; };
  };
  const auto round_trip = [nan](const std::vector<double>& v) {
    return [&v, nan](const AmRow& w) { return v.empty() ? nan : v[w.i]; };
  };
  CommandOutput out(p, capture, "spectroscopy reconstruct");
  out.open(io::TableOf<AmRow>{
               {"separation", nm, "measured separation l (rest position of the tip above the sample)",
                [&r](const AmRow& w) { return r.separation[w.i]; }},
               {"amplitude_ratio", "dimensionless", "measured A/A0",
                [&r, &s](const AmRow& w) { return r.amplitude[w.i] / s.free_amplitude; }},
               {"phase", rad, "measured phase lag (afmkit's convention)", [&r](const AmRow& w) { return r.phase[w.i]; }},
               {"dissipation", aJ, "energy dissipated per cycle (first-harmonic balance)",
                [&r](const AmRow& w) { return r.dissipation[w.i]; }},
               {"gap", nm, "lower turning point D = l − A (empty: point not used)",
                [&r, nan](const AmRow& w) { return w.used ? r.separation[w.i] - r.amplitude[w.i] : nan; }},
               {"force", nN, "reconstructed conservative force at D", at_used(r.force)},
               {"force_uncertainty", nN, "1σ of the force from the noise estimated in amplitude and phase",
                at_used(r.force_uncertainty)},
               {"approach_force", nN, "approach branch of the law at D", at_used(r.approach_force)},
               {"retract_force", nN, "retract branch of the law at D", at_used(r.retract_force)},
               {"round_trip_amplitude_ratio", "dimensionless", "A/A0 of the law's exact orbit (approach sweep)",
                round_trip(r.round_trip_amplitude_ratio)},
               {"round_trip_phase", rad, "phase of the law's exact orbit", round_trip(r.round_trip_phase)},
               {"residual_amplitude_ratio", "dimensionless", "round trip − measured",
                round_trip(r.residual_amplitude_ratio)},
               {"residual_phase", rad, "round trip − measured", round_trip(r.residual_phase)}})
      .add_all(am_rows);
  const std::string law_path = p.text("law_output");
  if (!law_path.empty())
    add_law_file(out, law_path, r.law, fmt::format("force reconstructed by afmkit spectroscopy reconstruct ({}, AM) "
                                                   "from {}", r.method, file), "velocity");
  double f_min = 0.0, e_max = 0.0;
  for (double f : r.force) f_min = std::min(f_min, f);
  for (double e : r.dissipation) e_max = std::max(e_max, e);
  UnitTagged tagged;
  tagged.add("mode", "am")
      .add("method", r.method)
      .add("points", r.separation.size(), "count")
      .add("points_used", r.gap.size(), "count")
      .add("largest_attraction", f_min, nN)
      .add("largest_dissipation", e_max, aJ)
      .add("contact_gap", r.contact_gap, nm)
      .add("rms_amplitude_ratio", r.rms_amplitude_ratio, "dimensionless")
      .add("rms_phase", r.rms_phase, rad)
      .add("round_trip_model", r.round_trip_model)
      .add("law_output", law_path)
      .add("status", "ok")
      .add("notes", notes_json(r.notes));
  const std::string summary = fmt::format(
      "AM reconstruction ({}, {} of {} points used): largest attraction {}, largest dissipation {} per cycle; round "
      "trip (exact orbits): A/A0 {:.2g} rms, phase {:.3g}° rms{}",
      r.method, r.gap.size(), r.separation.size(), io::quantity(f_min, "N"), io::quantity(e_max, "J"),
      r.rms_amplitude_ratio, deg(r.rms_phase), notes_text(r.notes));
  out.finish(std::move(tagged).summary(), summary);
}

void run_reconstruct(const io::ParamSet& p, Captured* capture) {
  if (p.text("input").empty())
    throw InvalidParameter("input", "input is empty: give the measured curve, a CSV file with 'distance (nm), "
                                    "frequency shift (Hz)' (FM) or 'separation (nm), amplitude (nm), phase (deg)' (AM)");
  const spectroscopy::MeasuredCurve m = spectroscopy::read_measured_curve(p.text("input"));
  const std::string& method = p.text("method");
  const bool fm_method = method == "sader_jarvis" || method == "matrix";
  if (m.frequency_modulation) {
    if (method != "auto" && !fm_method)
      throw InvalidParameter("method", fmt::format("method = {} is an AM method, and '{}' holds an FM curve (distance, "
                                                   "frequency shift): sader_jarvis or matrix",
                                                   method, p.text("input")));
    if (!p.was_set("amplitude"))
      throw InvalidParameter("amplitude", "an FM curve needs the oscillation amplitude: give amplitude (nm, > 0)");
    run_fm(p, capture, m);
  } else {
    if (fm_method)
      throw InvalidParameter("method", fmt::format("method = {} is an FM method, and '{}' holds an AM curve "
                                                   "(separation, amplitude, phase): katan, payam or hoelscher",
                                                   method, p.text("input")));
    if (!p.was_set("free_amplitude") || !p.was_set("quality_factor"))
      throw InvalidParameter(p.was_set("free_amplitude") ? "quality_factor" : "free_amplitude",
                             "an AM curve needs free_amplitude (nm) and quality_factor");
    run_am(p, capture, m);
  }
}

}  // namespace

void register_spectroscopy_reconstruct(CLI::App& spectroscopy) {
  add_command(
      spectroscopy, "reconstruct",
      "tip–sample force from a measured FM (distance, Δf) or AM (separation, amplitude, phase) curve, as a table law, "
      "with the round trip",
      [](io::ParamSet& p) {
        p.group("Input")
            .file("input", "", "measured curve CSV: 'distance (nm), frequency shift (Hz)' or 'separation (nm), "
                               "amplitude (nm), phase (deg)' (docs/reconstruction.md#input)")
            .positional()
            .text("method", "auto",
                  "auto (sader_jarvis for FM, payam for AM), sader_jarvis, matrix (FM); katan, payam, hoelscher (AM)",
                  {"auto", "sader_jarvis", "matrix", "katan", "payam", "hoelscher"})
            .text("tail", "zero", "the signal beyond the largest distance: zero, or exponential (fitted to the last "
                                  "points)",
                  {"zero", "exponential"})
            .text("phase_convention", "lag",
                  "AM phase: lag (afmkit's: 90° free at resonance, above 90° attractive) or mirrored (180° − phase)",
                  {"lag", "mirrored"});
        p.group("Cantilever");
        add_cantilever_param(p, CantileverKey::spring_constant, CantileverDefault::of(40.0),
                             "cantilever spring constant k");
        add_cantilever_param(p, CantileverKey::resonance_frequency, CantileverDefault::of(300.0),
                             "resonance frequency f0");
        add_cantilever_param(p, CantileverKey::amplitude, CantileverDefault::of(1.0),
                             "FM: oscillation amplitude A (required for FM curves)");
        add_cantilever_param(p, CantileverKey::free_amplitude, CantileverDefault::of(10.0),
                             "AM: free amplitude A0 at the drive frequency (required for AM curves)");
        add_cantilever_param(p, CantileverKey::quality_factor, CantileverDefault::of(400.0),
                             "quality factor Q (AM: required; FM: of the cantilever of the exact round trip, which Δf "
                             "hardly depends on)");
        add_drive_frequency_param(p);
        p.group("Reconstruction")
            .integer("noise_realisations", 8, "FM: synthetic noise realisations for the force uncertainty (0: none)",
                     0, 1000)
            .integer("round_trip_points", 40,
                     "separations (AM) or distances (FM) of the round trip through exact orbits, spread over the "
                     "curve (0: all)",
                     0, 100000)
            .text("round_trip", "exact",
                  "FM: the round trip's forward model: exact (the FM orbits of tapping fm) or first_order (Giessibl's "
                  "large-amplitude formula by quadrature)",
                  {"exact", "first_order"});
        p.group("Law output")
            .file("law_output", "out/reconstructed_law.csv",
                  "table-law file (distance, approach, retract) for --law table --force-curve (empty: none)")
            .writes();
        add_output_params(p, "out/spectroscopy_reconstruct.csv", "reconstruction");
      },
      run_reconstruct);
}

}  // namespace afmkit::cli
