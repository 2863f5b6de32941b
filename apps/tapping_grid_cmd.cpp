// afmkit tapping grid: every periodic orbit at each of `points` separations, the separations computed in parallel
// (tapping::sweep_grid, OpenMP), written as a Zarr store in the layout of a parameter study (docs/study.md#the-store):
// the same arrays as the study `tapping.orbit` over the axis `separation` with the outputs
// max/min(amplitude | stable), count(amplitude | stable) and count(amplitude), for machines without Python.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/core/version.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/io/zarr_store.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "tapping_params.hpp"
#include "tapping_sim_params.hpp"

namespace afmkit::cli {

namespace {

constexpr int kStudyFormat = 1;         // afmkit_study_format of the store (docs/study.md#the-store)
constexpr std::size_t kChunk = 256;     // separations per chunk of the stored arrays

/// `points` values from `start` to `stop` inclusive, computed as numpy.linspace does (start + i·step, the last
/// exactly stop), so that a study over the same axis has the same coordinates bit for bit.
std::vector<double> linspace(double start, double stop, std::size_t points) {
  std::vector<double> v(points);
  const double step = (stop - start) / static_cast<double>(points - 1);
  for (std::size_t i = 0; i < points; ++i) v[i] = static_cast<double>(i) * step + start;
  v.back() = stop;
  return v;
}

/// FNV-1a (64 bit) of the definition's text, in hex: names the definition (a store of `tapping grid` is not
/// resumed by the study runner, whose fingerprint is a SHA-256 of its own definition).
std::string fingerprint(const std::string& text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ULL;
  return fmt::format("tapping-grid-{:016x}", h);
}

void run_grid(const io::ParamSet& p, Captured* capture) {
  const TappingUnits u(tapping_scales_from(p));
  const double lo = p.real("separation_min"), hi = p.real("separation_max");
  if (!(lo < hi))
    throw InvalidParameter("separation_min", fmt::format("separation_min = {} is out of range: must be < "
                                                         "separation_max = {}", lo, hi));
  const auto points = static_cast<std::size_t>(p.integer("points"));
  // every point's search result is kept until the store is written: ~50 seeds, its orbits and transients, about
  // 6 kB measured; 16 kB each leaves room
  memory::require_fits("points", static_cast<double>(points), 16384.0);
  io::ZarrStoreWriter store(p.text("store"), "store");  // checked before anything is computed
  const tapping::TappingModel base = tapping_model_from(p);
  const std::vector<double> separations = linspace(lo, hi, points);
  std::vector<double> normalised(points);
  for (std::size_t i = 0; i < points; ++i) normalised[i] = u.length.internal(separations[i]);

  tapping::OrbitSearchOptions options;
  options.shooting = shooting_options_from(p);
  options.transient = transient_options_from(p);
  options.cancellation = cancellation_of(capture);
  // at least 2 full transients per separation (the free response and rest: find_orbits); nothing computed yet
  require_transient_work(p, options.transient, 2.0 * static_cast<double>(points),
                         fmt::format("2 transients at each of {} separations", points));
  io::Progress progress("tapping grid", static_cast<long>(points), !p.flag("quiet"));
  const std::vector<tapping::OrbitSearchResult> results =
      tapping::sweep_grid(base, normalised, options, [&](long n) { progress.advance(n); });
  progress.finish();

  // the outputs, as the study tapping.orbit names them (docs/study.md#outputs), each at every separation
  // each with its unit, which converts its values (in the model's units) where the store is written
  struct Output {
    const char* name;
    const char* selector;
    units::Unit unit;
    std::vector<double> values;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const units::Unit count = units::as_is("count");
  std::array<Output, 5> outputs = {{{"max_amplitude_stable", "max(amplitude | stable)", u.length, {}},
                                    {"min_amplitude_stable", "min(amplitude | stable)", u.length, {}},
                                    {"count_amplitude_stable", "count(amplitude | stable)", count, {}},
                                    {"count_amplitude", "count(amplitude)", count, {}},
                                    {"count_amplitude_trapped", "count(amplitude | trapped)", count, {}}}};
  auto& [max_stable, min_stable, stable, all, trapped_orbits] = outputs;
  for (Output& o : outputs) o.values.assign(points, 0.0);                           // the counts start at 0
  for (Output* o : {&max_stable, &min_stable}) o->values.assign(points, nan);  // no stable orbit yet: undefined
  for (std::size_t i = 0; i < points; ++i)
    for (const tapping::FoundOrbit& f : results[i].orbits) {
      const double amplitude = f.metrics.amplitude;
      all.values[i] += 1;
      if (tapping::tip_trapped(f.metrics)) trapped_orbits.values[i] += 1;
      if (!f.orbit.stable) continue;
      const bool first = stable.values[i] == 0;
      max_stable.values[i] = first ? amplitude : std::max(max_stable.values[i], amplitude);
      min_stable.values[i] = first ? amplitude : std::min(min_stable.values[i], amplitude);
      stable.values[i] += 1;
    }

  const std::string& length = u.length.name;
  nlohmann::json parameters = p.to_json();
  parameters.erase("store");
  parameters.erase("quiet");
  parameters.erase("separation");  // the axis
  nlohmann::json selectors = nlohmann::json::array();
  for (const Output& o : outputs) selectors.push_back(o.selector);
  const std::string definition = nlohmann::json{{"computation", "tapping.orbit"},
                                                {"parameters", parameters},
                                                {"axes", {{"separation", separations}}},
                                                {"outputs", selectors}}
                                     .dump();
  // separations without a tapping answer (docs/conventions.md#statuses), counted as `tapping sweep` counts its
  // trapped rows: every orbit found has the tip trapped, or no orbit was found; said in the store, the summary and
  // the exit status (1 when no separation has a tapping orbit)
  long trapped = 0, no_orbit = 0;
  for (std::size_t i = 0; i < points; ++i) {
    if (all.values[i] == 0) ++no_orbit;
    else if (trapped_orbits.values[i] == all.values[i]) ++trapped;
  }
  const auto n_points = static_cast<long>(points);
  const std::string status = no_orbit == n_points          ? "no_orbit"
                             : trapped + no_orbit == n_points ? "tip_trapped"
                                                              : "ok";
  std::string note;
  if (trapped > 0)
    note = fmt::format("at {} of {} separations the tip is trapped on every orbit found (sticks to the sample or "
                       "stays in contact over the whole period: no tapping; count_amplitude_trapped = count_amplitude "
                       "there)",
                       trapped, points);
  if (no_orbit > 0)
    note += fmt::format("{}at {} of {} separations no periodic orbit was found (count_amplitude = 0)",
                        note.empty() ? "" : "; ", no_orbit, points);
  store.attribute("status", status);
  store.attribute("note", note);
  store.attribute("trapped_separations", trapped);
  store.attribute("no_orbit_separations", no_orbit);
  store.attribute("afmkit_study_format", kStudyFormat);
  store.attribute("study_name", "tapping_grid");
  store.attribute("study_definition", definition);
  store.attribute("study_fingerprint", fingerprint(definition));
  store.attribute("computation", "tapping.orbit");
  store.attribute("command", "afmkit tapping grid");
  store.attribute("afmkit_version", afmkit::version);
  store.coordinate("separation", separations,
                   {{"units", length}, {"description", "separation l: sample surface at x = -l"}});
  const std::vector<std::size_t> shape = {points}, chunks = {std::min(points, kChunk)};
  for (const Output& o : outputs) {
    std::vector<double> shown(o.values.size());
    std::transform(o.values.begin(), o.values.end(), shown.begin(), o.unit);
    store.variable(o.name, {"separation"}, shape, chunks, shown,
                   {{"units", o.unit.name},
                    {"selector", o.selector},
                    {"description", std::string(o.selector) + " of afmkit tapping orbit at each point"}});
  }
  const std::size_t chunk_count = (points + chunks[0] - 1) / chunks[0];
  store.integer_variable("chunk_done", {"chunk"}, {chunk_count}, {1}, std::vector<std::int64_t>(chunk_count, 1), "<i1",
                         {{"units", "count"}, {"description", "1 when the chunk's outputs are written"}});
  store.integer_variable("chunk_failed", {"chunk"}, {chunk_count}, {1}, std::vector<std::int64_t>(chunk_count, 0),
                         "<i4", {{"units", "count"},
                                 {"description", "points of the chunk whose computation failed numerically"}});
  store.commit();
  if (!note.empty()) fmt::print("tapping grid: {}\n", note);
  const auto bands = std::count_if(stable.values.begin(), stable.values.end(), [](double n) { return n > 1; });
  fmt::print("tapping grid: {} separations from {} to {}, {} with more than one stable orbit; written to {} "
             "(Zarr; xarray: xr.open_zarr)\n",
             points, io::summary_value(lo, length, 6), io::summary_value(hi, length, 6), bands, store.path());
  require_answer({{"status", status}, {"note", note}});  // exit 1 when no separation has a tapping orbit
}

}  // namespace

void register_tapping_grid(CLI::App& tapping) {
  add_command(
      tapping, "grid",
      "every periodic orbit at each separation of a grid, computed in parallel (OpenMP) without Python; a Zarr "
      "store in the layout of a parameter study (largest/smallest stable amplitude, stable and all orbits)",
      [](io::ParamSet& p) {
        add_tapping_model_params(p);
        add_tapping_sim_params(p);
        p.group("Grid");
        add_separation_range_params(p, 5.0, 15.0);
        add_separation_points_param(p, 41, 2, 100000000,
                                    "separations, equally spaced from separation_min to separation_max");
        p.group("Output")
            .file("store", "out/tapping_grid.zarr",
                  "Zarr store the grid is written to (a folder, complete or not at all; an existing afmkit store "
                  "there is replaced, anything else refused)")
            .writes([](const std::string& store) { return std::vector<io::WrittenPath>{{store, true}}; });
        add_quiet_flag(p);
      },
      run_grid);
}

}  // namespace afmkit::cli
