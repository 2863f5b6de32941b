// afmkit demo: the Quick-start main job. A tapping-mode demonstration on the repulsive–attractive hysteresis
// law of seed 1 (eq. 26) where attraction makes the separation–amplitude curve fold: an instrument-like
// approach–retract sweep (with its jumps and hysteresis) and the harmonic-balance curve, written to out/.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "commands.hpp"
#include "tapping_params.hpp"
#include "tapping_tables.hpp"

namespace afmkit::cli {

namespace {

void run_demo(const io::ParamSet& p) {
  const double l_min = p.real("separation_min"), l_max = p.real("separation_max");
  if (!(l_min < l_max))
    throw InvalidParameter("separation_max",
                           fmt::format("separation_max = {} is out of range: must be > separation_min = {}", l_max, l_min));
  const tapping::TappingModel model = tapping_model_from(p);
  const TappingScales scales = tapping_scales_from(p);
  const std::string dir = p.text("output_dir");
  const int points = static_cast<int>(p.integer("points"));
  // Both directions are held in memory (then streamed out).
  memory::require_fits("points", static_cast<double>(points), 2.0 * sizeof(tapping::SweepPoint));

  // 1. Harmonic balance: the parametric curve and its folds (jump points).
  tapping::HbCurveOptions hb_options;
  hb_options.q_min = -1.0;
  hb_options.q_max = 1.5;
  hb_options.points = 4000;
  const auto curve = tapping::harmonic_balance_curve(model, hb_options);
  const tapping::HarmonicBalance balance(model);
  nlohmann::json folds = nlohmann::json::array();
  for (const auto& f : balance.folds())
    folds.push_back({{"separation", f.point.separation * scales.length}, {"amplitude", f.point.amplitude * scales.length},
                     {"q", f.point.q}});

  // 2. Approach–retract sweep, each orbit continued from the previous one (shooting).
  io::Progress progress("demo sweep", 2L * points, true, 1.0);
  tapping::SweepOptions options;
  options.progress = [&progress](long n) { progress.advance(n); };
  const tapping::SweepResult sweep = tapping::sweep_instrument(model, l_min, l_max, points, options);
  progress.finish();

  nlohmann::json jumps = {{"approach", sweep.approach_jumps}, {"retract", sweep.retract_jumps}};
  for (auto& side : {"approach", "retract"})
    for (auto& v : jumps[side]) v = v.get<double>() * scales.length;
  const nlohmann::json results = {{"hb_folds", folds},
                                  {"sweep_jumps", jumps},
                                  {"free_amplitude", model.free_amplitude() * scales.length}};
  io::TableWriter hb(dir + "/demo_hb.csv", hb_columns());
  write_hb_rows(hb, curve, scales);
  io::TableWriter table(dir + "/demo_sweep.csv", sweep_columns());
  write_sweep_rows(table, sweep.approach, scales);
  write_sweep_rows(table, sweep.retract, scales);
  hb.commit(io::make_sidecar("demo (harmonic balance)", p.to_json(), results));
  table.commit(io::make_sidecar("demo (sweep)", p.to_json(), results));

  const char* unit = p.text("units") == "physical" ? " nm" : "";
  fmt::print("afmkit demo: tapping cantilever, law '{}', Q = {}, drive at {} x resonance\n", model.law.name(),
             model.cantilever.quality_factor, p.real("frequency_ratio"));
  fmt::print("  free amplitude {:.4f}{}\n", model.free_amplitude() * scales.length, unit);
  for (const auto& f : folds)
    fmt::print("  harmonic balance fold (jump point) at separation {:.4f}{}, amplitude {:.4f}{}\n",
               f["separation"].get<double>(), unit, f["amplitude"].get<double>(), unit);
  for (double l : jumps["approach"]) fmt::print("  sweep: approach jumped at separation {:.4f}{}\n", l, unit);
  for (double l : jumps["retract"]) fmt::print("  sweep: retract jumped at separation {:.4f}{}\n", l, unit);
  fmt::print("  wrote {}/demo_sweep.csv ({} orbits) and {}/demo_hb.csv ({} HB points), with .json sidecars\n", dir,
             table.size(), dir, hb.size());
}

}  // namespace

void register_demo(CLI::App& app) {
  auto params = std::make_shared<io::ParamSet>();
  add_tapping_model_params(*params);
  // The demonstration case of docs/theory-tapping.md#hb-accuracy: attraction makes the amplitude curve fold and jump.
  params->set_default("law", "attractive");
  params->set_default("approach_adhesion", "0.5");
  params->set_default("departure_adhesion", "1.0");
  params->set_default("frequency_ratio", "0.99");
  params->group("Sweep")
      .real("separation_min", 7.0, "smallest separation of the sweep", io::Range::any())
      .real("separation_max", 12.0, "largest separation of the sweep (> separation_min)", io::Range::any())
      .integer("points", 101, "separations per direction (>= 2)", 2, 1000000)
      .group("Output")
      .text("output_dir", "out", "folder for demo_sweep.csv and demo_hb.csv (+ .json sidecars)");
  auto* cmd = app.add_subcommand("demo",
                                 "tapping-mode demonstration: approach-retract sweep with jumps and the harmonic-balance "
                                 "curve, written to out/ (the Quick-start main job)");
  params->add_options(*cmd);
  cmd->callback([params] {
    params->resolve();
    run_demo(*params);
  });
}

}  // namespace afmkit::cli
