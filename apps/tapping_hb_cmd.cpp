// afmkit tapping hb: the harmonic-balance separation–amplitude curve (seed-1 eqs. 18–19, 32–33, docs/theory-tapping.md#two-branch-solution; any
// force law, issue 7.2) sampled over the penetration parameter q, as CSV (q, separation, amplitude, offset, phase,
// branch) with a JSON sidecar holding the folds (jump points), the free amplitude and the solutions at `separation`;
// --json prints them (with the curve when --output "" writes no file).
#include <algorithm>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/hb_approximations.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "table_cache.hpp"
#include "tapping_params.hpp"
#include "tapping_tables.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

/// Memory of one row held as JSON and printed (the row's JSON array of 6 cells, the copy made for the printed
/// document and its indented text; measured 990 bytes a row with --json --output '' at 2·10^5 rows).
constexpr double kHeldRowBytes = 1024.0;
/// Points of the curve in memory at once when it is streamed.
constexpr std::size_t kChunkPoints = 4096;

/// What the run found (docs/conventions.md#statuses): "ok" (a curve), "empty_curve" (no point of the curve in
/// the q range, but solutions at `separation`), "no_solution" (neither).
const char* hb_status(bool empty_curve, bool no_solution_at_separation) {
  if (!empty_curve) return "ok";
  return no_solution_at_separation ? "no_solution" : "empty_curve";
}
std::string hb_note(bool empty_curve, bool no_solution_at_separation, double q_min, double q_max,
                    const std::string& separation) {
  if (!empty_curve) return "";
  return fmt::format("no harmonic-balance solution for q in [{}, {}]: the curve is empty; {} at separation {}", q_min,
                     q_max, no_solution_at_separation ? "no solution either" : "solutions (results)", separation);
}

using HbTables = TableCache<tapping::HbPoint, TappingUnits>;

void run_hb(const io::ParamSet& p, Captured* capture, HbTables& tables) {
  const double q_min = p.real("q_min");
  const double q_max = p.real("q_max");
  if (!(q_min < q_max))
    throw InvalidParameter("q_max", fmt::format("q_max = {} is out of range: must be > q_min = {}", q_max, q_min));
  const tapping::TappingModel model = tapping_model_from(p, law_object_of(capture));
  const TappingUnits u(tapping_scales_from(p));

  tapping::HbCurveOptions options;
  options.q_min = q_min;
  options.q_max = q_max;
  options.points = static_cast<std::size_t>(p.integer("points"));
  options.spacing = p.text("spacing") == "uniform" ? tapping::HbCurveSpacing::Uniform
                                                   : tapping::HbCurveSpacing::RefinedGrazing;
  options.min_gap = p.real("min_gap");
  options.include_minus = p.flag("minus_branch");
  options.cancellation = cancellation_of(capture);
  // The curve is streamed to the file in chunks (memory bounded by a chunk whatever `points`); only rows printed
  // as JSON or handed to Python are held, up to 2 per q sample (both branches).
  CommandOutput out(p, capture, "tapping hb");
  // (the streamed chunk is checked too: a malformed AFMKIT_MEMORY_LIMIT is refused as on every run)
  if (out.holds_rows()) memory::require_fits("points", static_cast<double>(options.points), 2.0 * kHeldRowBytes);
  else memory::require_fits("points", static_cast<double>(std::min(options.points, kChunkPoints)), sizeof(tapping::HbPoint));
  auto rows = out.open(tables.get(u));
  const std::size_t count = tapping::harmonic_balance_curve_chunks(
      model, options, [&](std::span<const tapping::HbPoint> chunk) { rows.add_all(chunk); }, kChunkPoints);

  // the model and options are checked: what is refused from here on was computed (core/computed.hpp)
  const tapping::HarmonicBalance hb = computed("harmonic balance", [&] { return tapping::HarmonicBalance(model); });
  // folds as records sorted by separation (as `tapping sweep` reports its folds and jumps)
  const std::vector<UnitTagged> folds =
      computed("harmonic balance: its folds", [&] { return hb_fold_records(hb, u); });
  std::vector<UnitTagged> solutions;
  for (const tapping::HbPoint& s :
       computed("harmonic balance: the solutions at separation", [&] { return hb.solutions(model.separation); }))
    solutions.push_back(hb_point_record(s, u));
  // each entry with its unit (the units of study outputs, docs/study.md#outputs), and the units by dimension
  UnitTagged results;
  results.add("folds", folds, hb_fold_record(tapping::HbFold{}, u))
      .add("free_amplitude", hb.free_amplitude(), u.length)
      .add("solutions_at_separation", solutions, hb_point_record(tapping::HbPoint{}, u))
      .add("rows", out.rows(), "count")
      .add("status", hb_status(count == 0, solutions.empty()))
      .add("note", hb_note(count == 0, solutions.empty(), q_min, q_max, summary_value(p.real("separation"), u.length, 6)))
      .unit("length", u.length.name)
      .unit("phase", "rad")
      .unit("q", "dimensionless");
  // ext. E8 is a closed-form limit of the laws (10), (11), (26); its unit is listed for every law
  UnitTagged limit;
  const auto limit_value = model.law.piecewise_linear() != nullptr ? tapping::minimum_separation_limit(model)
                                                                    : std::nullopt;
  limit.add("minimum_separation_limit", limit_value.value_or(0.0), u.length);  // −∞ is written "-inf"
  if (limit_value) results.merge(limit);
  else results.units_of(limit);
  out.finish(results.with_units(), fmt::format("{} fold(s), {} solution(s) at separation {}", folds.size(), solutions.size(),
                                  summary_value(p.real("separation"), u.length, 6)));
}

}  // namespace

void register_tapping_hb(CLI::App& tapping) {
  add_command(
      tapping, "hb",
      "harmonic-balance separation-amplitude curve over q (closed form for piecewise-linear laws, numerical "
      "describing functions for the others), with folds (jump points)",
      [](io::ParamSet& p) {
        add_tapping_model_params(p);
        p.group("Harmonic balance curve")
            .real("q_min", -1.0, "smallest penetration parameter q = (A + l)/B of the curve", io::Range::any())
            .unit("dimensionless")
            .real("q_max", 1.5, "largest q (> q_min); q >= 1 is the free oscillation", io::Range::any())
            .unit("dimensionless")
            .integer("points", 2000, "number of q samples (>= 2; the curve is streamed to the file, in bounded "
                                     "memory)", 2, 10000000)
            .text("spacing", "refined",
                  "q sampling: uniform, or refined (half the samples log-spaced in 1 - q near grazing)",
                  {"uniform", "refined"})
            .real("min_gap", 1e-10, "smallest 1 - q of the refined samples", {0.0, 1.0, true, true})
            .unit("dimensionless")
            .flag("minus_branch", true,
                  "also write the '-' root of the quadratic (docs/theory-tapping.md#two-branch-solution) where it "
                  "exists");
        add_output_params(p, "out/tapping_hb.csv", "harmonic-balance curve");
      },
      // the table declared once per units, shared by this registration's runs
      [tables = std::make_shared<HbTables>(hb_table)](const io::ParamSet& p, Captured* capture) {
        run_hb(p, capture, *tables);
      });
}

}  // namespace afmkit::cli
