// afmkit spectroscopy prepare: a measured force curve (instrument file, docs/curve-files.md) → the table law file
// that `afmkit tapping orbit --law table --force-curve FILE` reads (docs/spectroscopy.md): calibration, baseline,
// contact point (+ Hertz/DMT fit), tip–sample distance, averaging of repeated curves, binning, snap-in and pull-off.
// The law file is the command's table (4 columns, nm and nN; empty cells where a branch is shorter), its sidecar
// records the parameters as used and every result; --plot draws raw vs prepared curves with the Python package.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/io/curves/read_curves.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/spectroscopy/prepare.hpp"
#include "cantilever_params.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "described_params.hpp"
#include "law_params.hpp"
#include "python_launch.hpp"
#include "spectroscopy_prepare.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

using io::Range;
namespace sp = spectroscopy;

const std::vector<std::string> kFormats = {"auto",       "jpk-force",     "ibw",       "text",           "jpk-txt",
                                           "asylum-txt", "nanoscope-txt", "ntmdt-txt", "afmworkshop-csv"};
const std::vector<std::string> kColumnKeys = {"height",         "deflection",         "force",        "segment",
                                              "retract_height", "retract_deflection", "retract_force"};

void add_prepare_params(io::ParamSet& p) {
  p.group("Input")
      .file("input", "",
            "force-curve file: JPK .jpk-force, Asylum .ibw or a text export (docs/curve-files.md); every curve it "
            "holds is prepared and the repeated curves averaged")
      .positional()
      .text("format", "auto", "file format or text preset (auto: from the content and extension)", kFormats)
      .integer("curve", 0,
               "which curve of a file holding several (a force map, repeated curves), 1-based; 0: every curve, "
               "averaged (repeated curves of one spot)",
               0, 100000000);
  for (const std::string& c : kColumnKeys)
    p.text(c + "_column", "",
           fmt::format("text exports: the {} column, by header name or 1-based position (empty: the preset's or the "
                       "header's)",
                       c == "segment" ? "segment label" : std::string(c == "force" ? "force" : c)));
  p.text("height_unit", "header", "text exports: unit of the height columns (header: the header's)",
         {"header", "m", "mm", "um", "nm", "pm"})
      .text("deflection_unit", "header",
            "text exports: unit of the deflection columns: a length, or the detector's signal (V) or current (A)",
            {"header", "m", "mm", "um", "nm", "pm", "V", "mV", "uV", "A", "mA", "uA", "nA", "pA"})
      .text("force_unit", "header", "text exports: unit of the force columns (header: the header's)",
            {"header", "N", "mN", "uN", "nN", "pN"})
      .text("separator", "auto", "text exports: column separator", {"auto", "tab", "semicolon", "comma", "blank"})
      .text("decimal", "auto", "text exports: decimal mark", {"auto", "point", "comma"})
      .text("height_direction", "auto",
            "text exports: the height column grows away from the sample (a height) or towards it (an extension, "
            "negated); auto: the preset's",
            {"auto", "away", "towards"});
  p.group("Calibration");
  add_cantilever_param(p, CantileverKey::spring_constant, CantileverDefault::the_files(),
                       "cantilever spring constant k (> 0); not given: the file's");
  p.real("invols", 0.0,
            "inverse optical lever sensitivity (> 0), for a deflection recorded in volts; not given: the file's",
            Range::any())
      .unit("nm/V")
      .default_text("the file's");
  p.group("Baseline")
      .real("baseline_fraction", 0.3,
            "the far part of the approach's height range where the baseline (offset + tilt) is fitted",
            {0.0, 1.0, true, false})
      .unit("dimensionless");
  p.group("Contact point")
      .text("contact_method", "hertz",
            "hertz: Hertz fit of the approach; dmt: Hertz fit with an adhesion offset; threshold: where the force "
            "leaves the noise band (docs/spectroscopy.md#contact-point)",
            {"hertz", "dmt", "threshold"})
      .real("noise_multiple", 3.0, "half-width of the noise band in units of the baseline's noise sigma",
            Range::positive())
      .unit("dimensionless");
  // the tip radius of the laws (nm), here of the Hertz fit, where 0 stands for none
  add_law_key_param(p, impact::LawRegistry::builtin(), "tip_radius",
                    {.help = "tip radius R of the paraboloid Hertz fit; 0: no Young's modulus reported",
                     .default_value = 0.0,
                     .range = Range::non_negative(),
                     .unit = {}});
  p.real("poisson_ratio", 0.5, "Poisson's ratio of the sample in the Hertz fit", Range::closed(0.0, 0.5))
      .unit("dimensionless");
  p.group("Table")
      .real("bin_width", 0.0,
            "width of the distance bins the curves are averaged on; 0: automatic (approach span / 400, rounded down "
            "to 1, 2 or 5 x 10^k nm)",
            Range::non_negative())
      .unit("nm")
      .default_text("automatic")
      .flag("keep_baseline", false,
            "keep the far baseline in the table (otherwise it is trimmed 2 bins beyond the last force outside the noise "
            "band, where the table law is 0 anyway)")
      .flag("allow_energy_gain", false,
            "accept a prepared law whose retract force exceeds the approach force somewhere (noise); the orbit "
            "commands then need --allow-energy-gain too");
  add_output_params(p, "force_curve.csv", "table law (approach/retract distance in nm, force in nN)");
  p.file("plot", "", "PNG of the raw and prepared curves, drawn by the Python package (Matplotlib); empty: none")
      .writes();
}

const std::vector<std::string> kFileKeys = [] {
  std::vector<std::string> k = {"input", "format", "height_unit", "deflection_unit", "force_unit",
                                "separator", "decimal", "height_direction"};
  for (const std::string& c : kColumnKeys) k.push_back(c + "_column");
  return k;
}();

io::curves::ColumnChoice column_choice(const io::ParamSet& p, const std::string& name, const std::string& unit_key) {
  io::curves::ColumnChoice c;
  const std::string& v = p.text(name + "_column");
  if (!v.empty() && std::all_of(v.begin(), v.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) {
    if (v.size() > 6 || std::stol(v) < 1)
      throw InvalidParameter(name + "_column", fmt::format("{}_column = {} is out of range: a column position is 1 "
                                                           "to 999999", name, v));
    c.position = static_cast<int>(std::stol(v));
  } else {
    c.name = v;
  }
  if (!unit_key.empty() && p.text(unit_key) != "header") c.unit = p.text(unit_key);
  return c;
}

io::curves::ReadOptions read_options(const io::ParamSet& p) {
  io::curves::ReadOptions o;
  o.format = p.text("format");
  o.height = column_choice(p, "height", "height_unit");
  o.deflection = column_choice(p, "deflection", "deflection_unit");
  o.force = column_choice(p, "force", "force_unit");
  o.segment = column_choice(p, "segment", "");
  o.retract_height = column_choice(p, "retract_height", "height_unit");
  o.retract_deflection = column_choice(p, "retract_deflection", "deflection_unit");
  o.retract_force = column_choice(p, "retract_force", "force_unit");
  o.separator = p.text("separator");
  o.decimal = p.text("decimal");
  o.height_direction = p.text("height_direction");
  return o;  // k and InvOLS: applied by the preparation (the file's stay visible in the metadata)
}

sp::PrepareOptions prepare_options(const io::ParamSet& p) {
  sp::PrepareOptions o;
  o.calibration.spring_constant = p.was_set("spring_constant") ? p.real("spring_constant") : std::nan("");
  o.calibration.invols = p.was_set("invols") ? real_si(p, "invols") : std::nan("");
  o.baseline_fraction = p.real("baseline_fraction");
  const std::string& m = p.text("contact_method");
  o.contact.method = m == "dmt" ? sp::ContactMethod::dmt
                     : m == "threshold" ? sp::ContactMethod::threshold
                                        : sp::ContactMethod::hertz;
  o.contact.noise_multiple = p.real("noise_multiple");
  o.contact.fit.tip_radius = p.real("tip_radius") > 0 ? real_si(p, "tip_radius") : std::nan("");
  o.contact.fit.poisson_ratio = p.real("poisson_ratio");
  o.bin_width = real_si(p, "bin_width");
  o.trim_baseline = !p.flag("keep_baseline");
  return o;
}

// SI results shown in nm, nN, nm/V and SI (the output edge: each unit converts its values and names the unit)
const units::Unit kNm = units::from_si("nm"), kNn = units::from_si("nN"), kNmPerVolt = units::from_si("nm/V"),
                  kNPerM = units::from_si("N/m"), kPa = units::from_si("Pa"), kHertzCoefficient = units::as_is("N/m^1.5");

/// The units by dimension (beside those of each entry).
UnitTagged units_by_dimension() {
  UnitTagged u;
  u.unit("position", kNm.name)
      .unit("distance", kNm.name)
      .unit("force", kNn.name)
      .unit("spring_constant", kNPerM.name)
      .unit("invols", kNmPerVolt.name)
      .unit("baseline_slope", kNPerM.name)
      .unit("youngs_modulus", kPa.name)
      .unit("hertz_coefficient", kHertzCoefficient.name)
      .unit("noise", kNn.name)
      .unit("bin_width", kNm.name)
      .unit("height", kNm.name);
  return u;
}

UnitTagged fit_record(const sp::HertzFit& f) {
  UnitTagged j;
  j.add("model", sp::to_string(f.model))
      .add("contact_point", f.contact_point, kNm)
      .add("contact_point_error", f.contact_point_error, kNm)
      .add("hertz_coefficient", f.coefficient, kHertzCoefficient)
      .add("hertz_coefficient_error", f.coefficient_error, kHertzCoefficient)
      .add("adhesion_offset", f.offset, kNn)
      .add("adhesion_offset_error", f.offset_error, kNn)
      .add("youngs_modulus", f.youngs_modulus, kPa)
      .add("youngs_modulus_error", f.youngs_modulus_error, kPa)
      .add("residual_rms", f.residual_rms, kNn)
      .add("points", f.points, "count")
      .add("position_from", f.position_from, kNm)
      .add("position_to", f.position_to, kNm)
      .add("evaluations", f.evaluations, "count")
      .add("solver_status", f.solver_status);
  return j;
}

UnitTagged curve_record(const sp::CurvePreparation& c) {
  UnitTagged baseline;
  baseline.add("offset", c.baseline.offset, kNn)
      .add("slope", c.baseline.slope, kNPerM)
      .add("noise", c.baseline.residual_rms, kNn)
      .add("level_error", c.baseline.level_error, kNn)
      .add("slope_error", c.baseline.slope_error, kNPerM)
      .add("mean_height", c.baseline.mean_height, kNm)
      .add("points", c.baseline.points, "count")
      .add("height_from", c.baseline.height_from, kNm)
      .add("height_to", c.baseline.height_to, kNm);
  UnitTagged contact;
  contact.add("method", sp::to_string(c.contact.method))
      .add("position", c.contact.position, kNm)
      .add("error", c.contact.error, kNm)
      .add("baseline_error", c.contact.baseline_error, kNm)
      .add("threshold_position", c.contact.threshold_position, kNm);
  if (c.contact.fit) contact.add("fit", fit_record(*c.contact.fit));
  else contact.unit("fit", fit_record(sp::HertzFit{}).units());  // (a fit of the hertz and dmt methods)
  UnitTagged j;
  j.add("origin", c.origin)
      .add("spring_constant", c.spring_constant, kNPerM)
      .add("spring_constant_source", c.spring_constant_source)
      .add("invols", c.invols, kNmPerVolt)
      .add("invols_source", c.invols_source)
      .add("approach_samples", c.approach_samples, "count")
      .add("retract_samples", c.retract_samples, "count")
      .add("baseline", baseline)
      .add("contact", contact)
      .add("notes", c.notes);
  return j;
}

UnitTagged event_record(const sp::CurveEvent& e) {
  UnitTagged j;
  j.add("detected", e.detected, "boolean (0/1)").add("distance", e.distance, kNm).add("force", e.force, kNn);
  return j;
}

/// The law file's text, as the table writer writes it (shortest round-trip numbers, empty cells past a branch).
std::string law_text(const impact::ForceCurve& c) {
  std::string t = fmt::format("{},{},{},{}\n", sp::law_columns[0], sp::law_columns[1], sp::law_columns[2],
                              sp::law_columns[3]);
  for (std::size_t i = 0; i < std::max(c.approach_gap.size(), c.retract_gap.size()); ++i) {
    t += i < c.approach_gap.size() ? fmt::format("{},{},", c.approach_gap[i], c.approach_force[i]) : ",,";
    t += i < c.retract_gap.size() ? fmt::format("{},{}\n", c.retract_gap[i], c.retract_force[i]) : ",\n";
  }
  return t;
}

/// The plot's data for the Python package (SI units).
nlohmann::json plot_json(const sp::PreparedCurve& r, const nlohmann::json& results) {
  nlohmann::json curves = nlohmann::json::array();
  for (const auto& c : r.curves) {
    nlohmann::json j = {
        {"origin", c.origin},
        {"approach", {{"height", c.approach.height}, {"raw_force", c.approach_raw_force},
                      {"distance", c.approach_distance}, {"force", c.approach.force}}},
        {"retract", {{"height", c.retract.height}, {"raw_force", c.retract_raw_force},
                     {"distance", c.retract_distance}, {"force", c.retract.force}}},
        {"baseline", {{"offset", c.baseline.offset}, {"slope", c.baseline.slope},
                      {"height_from", c.baseline.height_from}, {"height_to", c.baseline.height_to}}},
        {"contact", c.contact.position}};
    if (c.contact.fit)
      j["fit"] = {{"model", sp::to_string(c.contact.fit->model)},
                  {"contact_point", c.contact.fit->contact_point},
                  {"coefficient", c.contact.fit->coefficient},
                  {"offset", c.contact.fit->offset}};
    curves.push_back(j);
  }
  return {{"curves", curves},
          {"approach", {{"distance", r.approach.distance}, {"force", r.approach.force}}},
          {"retract", {{"distance", r.retract.distance}, {"force", r.retract.force}}},
          {"snap_in", {{"detected", r.snap_in.detected}, {"distance", r.snap_in.distance}, {"force", r.snap_in.force}}},
          {"pull_off",
           {{"detected", r.pull_off.detected}, {"distance", r.pull_off.distance}, {"force", r.pull_off.force}}},
          {"noise", r.noise},
          {"status", results.value("status", "ok")}};
}

/// Draws the plot with the Python package into a temporary file and stages it for `path` (committed with the
/// table). InvalidParameter "plot" when Python cannot draw it.
void stage_plot(const std::string& path, const nlohmann::json& data, io::OutputSet& outputs) {
  namespace fs = std::filesystem;
  std::string dir_template = (fs::temp_directory_path() / "afmkit-plot-XXXXXX").string();
  if (::mkdtemp(dir_template.data()) == nullptr)
    throw InputError(fmt::format("plot: cannot create a temporary folder: {}", std::strerror(errno)));
  const fs::path dir = dir_template;
  struct Remove {
    fs::path dir;
    ~Remove() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } remove{dir};
  const fs::path data_path = dir / "data.json", png_path = dir / "plot.png";
  {
    std::ofstream f(data_path);
    f << data.dump();
    if (!f) throw InputError(fmt::format("plot: cannot write its data to {}", data_path.string()));
  }
  const int status = run_python_function("spectroscopy", "plot_main", {data_path.string(), png_path.string()});
  std::ifstream png(png_path, std::ios::binary);
  if (status != 0 || !png)
    throw InvalidParameter("plot", fmt::format("plot '{}': the Python package could not draw it (exit status {}; its "
                                               "message is above; it needs Matplotlib: Debian python3-matplotlib)",
                                               path, status));
  std::ostringstream bytes;
  bytes << png.rdbuf();
  outputs.add(path, bytes.str());
}

std::string modulus_text(double e) {
  if (!std::isfinite(e)) return fmt::format("{} Pa", e);
  if (std::abs(e) >= 1e9) return fmt::format("{:.4g} GPa", e / 1e9);
  if (std::abs(e) >= 1e6) return fmt::format("{:.4g} MPa", e / 1e6);
  if (std::abs(e) >= 1e3) return fmt::format("{:.4g} kPa", e / 1e3);
  return fmt::format("{:.4g} Pa", e);
}

std::string summary_text(const sp::PreparedCurve& r, const nlohmann::json& results, const std::string& check) {
  auto q = [](double v, const char* unit) { return io::quantity(v, unit, 4); };
  std::string s = fmt::format("spectroscopy prepare: {} curve(s), status {}\n", r.curves.size(),
                              results.at("status").get<std::string>());
  for (const auto& c : r.curves) {
    s += fmt::format("  {}: k = {:.6g} N/m ({}), InvOLS = {}\n", c.origin, c.spring_constant, c.spring_constant_source,
                     std::isnan(c.invols) ? std::string("not needed")
                                          : fmt::format("{:.6g} {} ({})", kNmPerVolt(c.invols), kNmPerVolt.name, c.invols_source));
    s += fmt::format("    baseline: offset {} at z = 0, tilt {:.4g} N/m, noise sigma {} ({} samples)\n",
                     q(c.baseline.offset, "N"), c.baseline.slope, q(c.baseline.residual_rms, "N"), c.baseline.points);
    s += fmt::format("    contact point ({}): tip position {} +- {}\n", sp::to_string(c.contact.method),
                     q(c.contact.position, "m"), q(c.contact.error, "m"));
    if (c.contact.fit) {
      const auto& f = *c.contact.fit;
      s += fmt::format("    {} fit: {} samples, residual {}", f.model == sp::ContactModel::dmt ? "DMT" : "Hertz",
                       f.points, q(f.residual_rms, "N"));
      if (std::isfinite(f.youngs_modulus))
        s += fmt::format(", E = {} +- {}", modulus_text(f.youngs_modulus), modulus_text(f.youngs_modulus_error));
      if (f.model == sp::ContactModel::dmt) s += fmt::format(", adhesion offset {} +- {}", q(f.offset, "N"), q(f.offset_error, "N"));
      s += "\n";
    }
    for (const std::string& n : c.notes) s += fmt::format("    note: {}\n", n);
  }
  s += fmt::format("  bins of {}: approach {} points, retract {} points{}\n", q(r.bin_width, "m"), r.approach.size(),
                   r.retract.size(),
                   std::isfinite(r.trimmed_at) ? fmt::format(" (trimmed beyond {})", q(r.trimmed_at, "m")) : "");
  s += r.snap_in.detected ? fmt::format("  snap-in: {} at distance {}\n", q(r.snap_in.force, "N"), q(r.snap_in.distance, "m"))
                          : "  snap-in: none above the noise\n";
  s += r.pull_off.detected
           ? fmt::format("  pull-off: {} at distance {}\n", q(r.pull_off.force, "N"), q(r.pull_off.distance, "m"))
           : "  pull-off: none above the noise\n";
  s += fmt::format("  table law check: {}", check);
  return s;
}

void run_prepare(const io::ParamSet& p, Captured* capture) {
  const std::string& input = p.text("input");
  if (input.empty()) throw InvalidParameter("input", "input: give the force-curve file (afmkit spectroscopy prepare FILE)");
  const std::vector<io::curves::RawCurve> curves = io::curves::read_curves(input, read_options(p));
  run_prepare_curves(p, curves, capture);
}

}  // namespace

const std::vector<std::string>& prepare_file_keys() { return kFileKeys; }

void run_prepare_curves(const io::ParamSet& p, const std::vector<io::curves::RawCurve>& curves, Captured* capture) {
  const std::string& plot = p.text("plot");
  if (!plot.empty() && !python_module_found("spectroscopy"))
    throw InvalidParameter("plot", "plot: drawing needs the Python package afmkit (with Matplotlib), which is not "
                                   "next to this program (docs/python.md); leave --plot out");
  const long pick = p.integer("curve");
  if (pick > static_cast<long>(curves.size()))
    throw InvalidParameter("curve", fmt::format("curve = {} is out of range: the input holds {} curve{} (1 to {}, or 0 "
                                                "for all)",
                                                pick, curves.size(), curves.size() == 1 ? "" : "s", curves.size()));
  const sp::PreparedCurve r =
      pick > 0 ? sp::prepare({curves[static_cast<std::size_t>(pick - 1)]}, prepare_options(p))
               : sp::prepare(curves, prepare_options(p));
  io::ParamSet as_run = p;  // the sidecar records the values used (computed defaults filled in)
  record_used_si(as_run, "bin_width", r.bin_width);
  // k and InvOLS taken from the file: recorded when every curve used the same (else each curve's are in the results)
  const auto same = [&](auto value) {
    return std::all_of(r.curves.begin(), r.curves.end(), [&](const auto& c) { return value(c) == value(r.curves[0]); });
  };
  if (!r.curves.empty()) {
    if (!p.was_set("spring_constant") && same([](const auto& c) { return c.spring_constant; }))
      as_run.record_used("spring_constant", r.curves[0].spring_constant);
    if (!p.was_set("invols") && std::isfinite(r.curves[0].invols) && same([](const auto& c) { return c.invols; }))
      record_used_si(as_run, "invols", r.curves[0].invols);
  }

  // the check: the table as written, read back by the table law's reader and law
  const std::string origin = p.text("output").empty() ? std::string("prepared table") : p.text("output");
  const impact::ForceCurve curve = sp::to_force_curve(r, origin);
  std::string status = "ok", note, check = "accepted by the table law";
  try {
    const impact::TableLaw law(impact::parse_force_curve(law_text(curve), origin), p.flag("allow_energy_gain"));
    if (!p.flag("allow_energy_gain")) law.require_dissipative();
  } catch (const InvalidParameter& e) {
    status = "law_refused";
    const std::string why = e.what();
    const std::string advice =
            fmt::format("a larger --bin-width averages the noise down{}, or --allow-energy-gain accepts it (give "
                          "it to the orbit commands as well)",
                          p.flag("keep_baseline") ? ", leaving out --keep-baseline trims the far baseline" : "");
    note = fmt::format("the prepared table is refused by the table law: {} — {}", why, advice);
    check = "refused (see the note)";
  }

  std::vector<UnitTagged> curve_records;
  for (const auto& c : r.curves) curve_records.push_back(curve_record(c));
  UnitTagged tagged = units_by_dimension();
  tagged.add("status", status)
      .add("curves", curve_records, curve_record(sp::CurvePreparation{}))
      .add("noise", r.noise, kNn)
      .add("bin_width", r.bin_width, kNm)
      .add("approach_points", r.approach.size(), "count")
      .add("retract_points", r.retract.size(), "count")
      .add("trimmed_at", r.trimmed_at, kNm)
      .add("snap_in", event_record(r.snap_in))
      .add("pull_off", event_record(r.pull_off));
  if (!note.empty()) tagged.add("note", note);
  const nlohmann::json results = tagged.with_units();

  CommandOutput out(as_run, capture, "spectroscopy prepare");
  out.open({{sp::law_columns[0], "nm", "approach branch: tip-sample distance (bin centre; < 0: indentation)"},
            {sp::law_columns[1], "nN", "approach branch: mean force of the bin (> 0 repulsive)"},
            {sp::law_columns[2], "nm", "retract branch: tip-sample distance (bin centre)"},
            {sp::law_columns[3], "nN", "retract branch: mean force of the bin"}});
  if (out.keeps_rows())
    for (std::size_t i = 0; i < std::max(curve.approach_gap.size(), curve.retract_gap.size()); ++i) {
      const bool a = i < curve.approach_gap.size(), b = i < curve.retract_gap.size();
      if (a && b) out.row(curve.approach_gap[i], curve.approach_force[i], curve.retract_gap[i], curve.retract_force[i]);
      else if (a) out.row(curve.approach_gap[i], curve.approach_force[i], "", "");
      else out.row("", "", curve.retract_gap[i], curve.retract_force[i]);
    }
  if (!plot.empty()) stage_plot(plot, plot_json(r, results), out.outputs());
  if (!p.flag("json") && capture == nullptr) fmt::print("{}\n", summary_text(r, results, check));
  out.finish(results, "");
}

void register_spectroscopy_prepare(CLI::App& spectroscopy) {
  add_command(spectroscopy, "prepare",
              "a measured force curve -> the table law of --law table: calibration, baseline, contact point (+ Hertz "
              "fit), tip-sample distance, averaging, binning, snap-in and pull-off (docs/spectroscopy.md)",
              add_prepare_params, run_prepare);
}

}  // namespace afmkit::cli
