// afmkit tapping sweep: separation sweeps of periodic orbits — as an instrument does (approach then retract,
// each orbit continued from the previous one, transients where a branch ends: jumps and hysteresis) and/or by
// pseudo-arclength continuation through folds (unstable branches included). HB value beside each point.
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/tapping/continuation.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "commands.hpp"
#include "tapping_params.hpp"
#include "tapping_sim_params.hpp"
#include "tapping_tables.hpp"

namespace afmkit::cli {

namespace {

nlohmann::json scaled(const std::vector<double>& v, double f) {
  nlohmann::json j = nlohmann::json::array();
  for (double x : v) j.push_back(x * f);
  return j;
}

void run_sweep(const io::ParamSet& p) {
  const tapping::TappingModel base = tapping_model_from(p);
  const TappingScales scales = tapping_scales_from(p);
  const double l_min = p.real("separation_min") / scales.length, l_max = p.real("separation_max") / scales.length;
  if (!(l_min < l_max))
    throw InvalidParameter("separation_min", fmt::format("separation_min = {} is out of range: must be < "
                                                         "separation_max = {}",
                                                         p.real("separation_min"), p.real("separation_max")));
  const int points = static_cast<int>(p.integer("points"));
  // Both directions are held in memory (then streamed out).
  memory::require_fits("points", static_cast<double>(points), 2.0 * sizeof(tapping::SweepPoint));
  const std::string& mode = p.text("mode");
  const bool instrument = mode == "instrument" || mode == "both";
  const bool continuation = mode == "continuation" || mode == "both";
  const bool quiet = p.flag("json") || p.flag("quiet");

  const std::string output = p.text("output");
  std::optional<io::TableWriter> table;
  if (!output.empty()) table.emplace(output, sweep_columns());
  long rows = 0;
  const auto write_rows = [&](const std::vector<tapping::SweepPoint>& points) {
    rows += static_cast<long>(points.size());
    if (table) write_sweep_rows(*table, points, scales);
  };
  nlohmann::json results = nlohmann::json::object();
  if (instrument) {
    io::Progress progress("tapping sweep (approach + retract)", 2L * points, !quiet);
    tapping::SweepOptions options;
    options.shooting = shooting_options_from(p);
    options.transient = transient_options_from(p);
    options.progress = [&progress](long n) { progress.advance(n); };
    const tapping::SweepResult r = tapping::sweep_instrument(base, l_min, l_max, points, options);
    progress.finish();
    write_rows(r.approach);
    write_rows(r.retract);
    results["approach_jumps"] = scaled(r.approach_jumps, scales.length);
    results["retract_jumps"] = scaled(r.retract_jumps, scales.length);
  }
  if (continuation) {
    tapping::ContinuationOptions options;
    options.shooting = shooting_options_from(p);
    options.max_step = p.real("max_arclength_step") / scales.length;
    options.initial_step = std::min(options.initial_step, options.max_step);
    options.max_points = static_cast<int>(p.integer("max_continuation_points"));
    const tapping::ContinuationResult c = tapping::sweep_continuation(base, l_min, l_max, options);
    write_rows(c.points);
    results["folds"] = scaled(c.folds, scales.length);
    results["grazing"] = scaled(c.grazing, scales.length);
    results["continuation_stop"] = c.stop_reason;
    results["continuation_points"] = c.points.size();
  }
  results["free_amplitude"] = base.free_amplitude() * scales.length;
  results["rows"] = rows;
  if (table) table->commit(io::make_sidecar("tapping sweep", p.to_json(), results));
  if (p.flag("json")) {
    fmt::print("{}\n", results.dump(2));
    return;
  }
  if (instrument)
    fmt::print("instrument sweep: jumps on approach at {}, on retract at {}\n", results["approach_jumps"].dump(),
               results["retract_jumps"].dump());
  if (continuation)
    fmt::print("continuation: {} points, folds at {}, grazing at {} ({})\n", results["continuation_points"].dump(),
               results["folds"].dump(), results["grazing"].dump(), results["continuation_stop"].get<std::string>());
  if (!output.empty()) fmt::print("wrote {} rows to {} (details in {}.json)\n", rows, output, output);
}

}  // namespace

void register_tapping_sweep(CLI::App& tapping) {
  auto params = std::make_shared<io::ParamSet>();
  add_tapping_model_params(*params);
  add_tapping_sim_params(*params);
  params->group("Sweep")
      .real("separation_min", 5.0, "smallest separation of the sweep (nm)", io::Range::any())
      .real("separation_max", 15.0, "largest separation of the sweep (nm), > separation_min", io::Range::any())
      .integer("points", 200, "separations per direction of the instrument sweep (>= 2)", 2, 10000000)
      .text("mode", "instrument",
            "instrument (approach then retract, jumps and hysteresis), continuation (pseudo-arclength through "
            "folds, unstable branches) or both",
            {"instrument", "continuation", "both"})
      .real("max_arclength_step", 0.2, "largest continuation step (nm, scaled arclength)", io::Range::positive())
      .integer("max_continuation_points", 5000, "continuation point budget", 2, 100000000)
      .group("Output")
      .flag("json", false, "print the summary (jumps, folds) as JSON")
      .flag("quiet", false, "no progress output")
      .text("output", "out/tapping_sweep.csv", "output CSV path (JSON sidecar next to it); empty: no file");
  auto* cmd = tapping.add_subcommand(
      "sweep", "separation sweep of periodic orbits: instrument approach/retract (jumps, hysteresis) and/or "
               "continuation through folds; HB beside each point");
  params->add_options(*cmd);
  cmd->callback([params] {
    params->resolve();
    run_sweep(*params);
  });
}

}  // namespace afmkit::cli
