// afmkit demo: the quick command-line demonstration of the README. A tapping-mode demonstration on the repulsive–attractive hysteresis
// law of seed 1 (eq. 26) where attraction makes the separation–amplitude curve fold: an instrument-like
// approach–retract sweep (with its jumps and hysteresis) and the harmonic-balance curve, written to out/.
#include <cmath>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "tapping_params.hpp"
#include "tapping_tables.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

// The demonstration case in normalised units (docs/theory-tapping.md#hb-accuracy): attraction makes the amplitude
// curve fold and jump. Γ = 0.2, K_a = 10, K_b = 8, F_a = 0.5, F_b = 1, ω/ω_n = 0.99, l in [7, 12].
constexpr double demo_drive = 0.2, demo_approach_adhesion = 0.5, demo_departure_adhesion = 1.0;
constexpr double demo_approach_stiffness = 10.0, demo_departure_stiffness = 8.0;
constexpr double demo_separation_min = 7.0, demo_separation_max = 12.0;

/// The parameters with the demonstration case's defaults. In physical units the same dimensionless case: lengths
/// scaled by s = A_free / A_free(normalised case) (the model is linear in the lengths), forces by s·k, sample
/// stiffnesses by k — so the fold the demo exists to show is kept whatever k and A_free the user gives. Values
/// the user gives win.
io::ParamSet with_demo_defaults(const io::ParamSet& given) {
  io::ParamSet p = given;
  auto fill = [&](const std::string& key, double value) {
    if (!p.was_set(key)) p.set_default(key, fmt::format("{}", value));
  };
  double s = 1.0;
  if (p.text("units") == "physical") {
    const double r = p.real("frequency_ratio"), q = p.real("quality_factor"), k = p.real("spring_constant");
    const double gain = 1.0 / std::hypot(1.0 - r * r, r / q);  // |L(iω)| of the normalised cantilever
    s = p.real("free_amplitude") / (demo_drive * gain);
    fill("adhesion_approach", demo_approach_adhesion * s * k);
    fill("adhesion_departure", demo_departure_adhesion * s * k);
    fill("sample_stiffness_approach", demo_approach_stiffness * k);
    fill("sample_stiffness_departure", demo_departure_stiffness * k);
  }
  fill("separation_min", demo_separation_min * s);
  fill("separation_max", demo_separation_max * s);
  fill("separation", 0.5 * (demo_separation_min + demo_separation_max) * s);
  return p;
}

void run_demo(const io::ParamSet& given, Captured* capture) {
  const io::ParamSet p = with_demo_defaults(given);
  const double l_min = p.real("separation_min"), l_max = p.real("separation_max");
  if (!(l_min < l_max))
    throw InvalidParameter("separation_max",
                           fmt::format("separation_max = {} is out of range: must be > separation_min = {}", l_max, l_min));
  const tapping::TappingModel model = tapping_model_from(p, law_object_of(capture));
  const TappingUnits u(tapping_scales_from(p));
  const std::string dir = p.text("output_dir");
  const int points = static_cast<int>(p.integer("points"));
  // Both directions are held in memory (then streamed out).
  memory::require_fits("points", static_cast<double>(points), 2.0 * sizeof(tapping::SweepPoint));

  // 1. Harmonic balance: the parametric curve and its folds (jump points).
  tapping::HbCurveOptions hb_options;
  hb_options.q_min = -1.0;
  hb_options.q_max = 1.5;
  hb_options.points = 4000;
  // the input is checked (the model; the options are the demo's own): what is refused from here on was computed,
  // a numerical failure naming the computation (exit 1), never the user's error (core/computed.hpp)
  const auto curve =
      computed("demo: the harmonic-balance curve", [&] { return tapping::harmonic_balance_curve(model, hb_options); });
  const tapping::HarmonicBalance balance =
      computed("demo: harmonic balance", [&] { return tapping::HarmonicBalance(model); });
  const std::vector<UnitTagged> folds =  // sorted by separation, as `tapping hb`
      computed("demo: the harmonic-balance folds", [&] { return hb_fold_records(balance, u); });

  // 2. Approach–retract sweep, each orbit continued from the previous one (shooting).
  io::Progress progress("demo sweep", 2L * points, true, 1.0);
  tapping::SweepOptions options;
  options.progress = [&progress](long n) { progress.advance(n); };
  options.validate();
  const tapping::SweepResult sweep = computed(
      "demo: instrument sweep", [&] { return tapping::sweep_instrument(model, l_min, l_max, points, options); });
  progress.finish();

  // each entry with its unit, and the unit of lengths
  UnitTagged jumps;
  jumps.add("approach", sweep.approach_jumps, u.length).add("retract", sweep.retract_jumps, u.length);
  UnitTagged tagged;
  tagged.add("hb_folds", folds, hb_fold_record(tapping::HbFold{}, u))
      .add("sweep_jumps", jumps)
      .add("free_amplitude", model.free_amplitude(), u.length)
      .unit("length", u.length.name);
  const nlohmann::json results = tagged.with_units();
  const io::TableOf<tapping::HbPoint> hb_rows = hb_table(u);
  io::TableWriter hb(dir + "/demo_hb.csv", hb_rows.columns());
  for (const tapping::HbPoint& pt : curve) io::write_row(hb, hb_rows, pt);
  const io::TableOf<tapping::SweepPoint> sweep_rows = sweep_table(u);
  io::TableWriter table(dir + "/demo_sweep.csv", sweep_rows.columns());
  for (const auto* points : {&sweep.approach, &sweep.retract})
    for (const tapping::SweepPoint& pt : *points) io::write_row(table, sweep_rows, pt);
  io::OutputSet set;  // both tables and their sidecars, or none
  hb.stage(io::make_sidecar("demo (harmonic balance)", p, results), set);
  table.stage(io::make_sidecar("demo (sweep)", p, results), set);
  set.commit();
  if (capture != nullptr) {
    capture->results = results;
    return;
  }

  // lengths by magnitude in physical units, said to be normalised otherwise (docs/units.md#summaries): the values
  // written, in their unit
  const std::string& unit = u.length.name;
  fmt::print("afmkit demo: tapping cantilever, law '{}', Q = {}, drive at {} x resonance ({} units)\n",
             model.law.name(), model.cantilever.quality_factor, p.real("frequency_ratio"), p.text("units"));
  fmt::print("  free amplitude {}\n", io::summary_value(results.at("free_amplitude").get<double>(), unit, 6));
  for (const auto& f : results.at("hb_folds"))
    fmt::print("  harmonic balance fold (jump point) at separation {}, amplitude {}\n",
               io::summary_value(f["separation"].get<double>(), unit, 6),
               io::summary_value(f["amplitude"].get<double>(), unit, 6));
  for (double l : results.at("sweep_jumps").at("approach"))
    fmt::print("  sweep: approach jumped at separation {}\n", io::summary_value(l, unit, 6));
  for (double l : results.at("sweep_jumps").at("retract"))
    fmt::print("  sweep: retract jumped at separation {}\n", io::summary_value(l, unit, 6));
  fmt::print("  wrote {}/demo_sweep.csv ({} orbits) and {}/demo_hb.csv ({} HB points); columns, units and results "
             "in the .json sidecars\n",
             dir, table.size(), dir, hb.size());
}

}  // namespace

void register_demo(CLI::App& app) {
  add_command(
      app, "demo",
      "tapping-mode demonstration: approach-retract sweep with jumps and the harmonic-balance curve, written to out/ "
      "(the README's quick command-line look)",
      [](io::ParamSet& p) {
        add_tapping_model_params(p);
        // The demonstration case (with_demo_defaults above; physical defaults follow the cantilever).
        p.set_default("law", "attractive");
        p.set_default("approach_adhesion", fmt::format("{}", demo_approach_adhesion));
        p.set_default("departure_adhesion", fmt::format("{}", demo_departure_adhesion));
        p.set_default("frequency_ratio", "0.99");
        p.group("Sweep");
        // any finite value: the physical defaults scale with the cantilever (with_demo_defaults)
        add_separation_range_params(
            p, demo_separation_min, demo_separation_max,
            {.min_help = "smallest separation of the sweep",
             .max_help = "largest separation of the sweep (> separation_min)",
             .range = io::Range::any(),
             .min_default_text = "7 normalised; physical: the same case scaled to free_amplitude",
             .max_default_text = "12 normalised; physical: the same case scaled to free_amplitude"});
        add_separation_points_param(p, 101, 2, 1000000, "separations per direction (>= 2)");
        p.group("Output")
            .file("output_dir", "out", "folder for demo_sweep.csv and demo_hb.csv (+ .json sidecars)")
            .writes([](const std::string& dir) {
              std::vector<io::WrittenPath> files = io::table_and_sidecar(dir + "/demo_sweep.csv");
              for (io::WrittenPath& f : io::table_and_sidecar(dir + "/demo_hb.csv")) files.push_back(std::move(f));
              return files;
            });
      },
      run_demo);
}

}  // namespace afmkit::cli
