// afmkit control chart: stability charts of the seed-2 loop in the coupling plane (paper Figs. 2, 4) at one delay or
// several (`delays`: one chart per delay in the same table, column `delay`), with the exact D-subdivision
// boundaries in a second table; or (quantity = margin) the delay-margin map τ_c(x, y). Units: control_params.hpp
// (couplings, abscissa and frequencies in units of Ω, delays in units of T).
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/stability_chart.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/table.hpp"
#include "command.hpp"
#include "control_analysis.hpp"
#include "control_params.hpp"
#include "control_units.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

// The default chart windows (units of Ω): the single oscillator's (a, b) plane, the couplings' (alpha, beta) plane.
constexpr Window kSingleWindow{-0.5, 2.0, -2.0, 1.5};
constexpr Window kCouplingsWindow{-0.1, 1.0, -0.4, 1.0};

using io::Range;

// The settings at each delay of the run: `delays` when given (validated entry by entry, naming `delays`), else
// `delay`.
std::vector<control::ControlSettings> settings_per_delay(const io::ParamSet& p, const control::ControlSettings& c) {
  if (p.reals("delays").empty()) return {c};
  if (p.text("quantity") == "margin" && p.reals("delays").size() > 1)
    throw InvalidParameter("delays", fmt::format("delays has {} entries: must have one with quantity = margin (the "
                                                 "delay-margin map does not depend on the delay)",
                                                 p.reals("delays").size()));
  std::vector<control::ControlSettings> out;
  for (double d : p.reals("delays")) {
    control::ControlSettings at = c;
    at.delay = d;
    try {
      at.validate();
    } catch (const InvalidParameter& e) {
      if (e.parameter() != "delay") throw;
      throw InvalidParameter("delays", fmt::format("delays contains {}: {}", d, e.what()));
    }
    out.push_back(at);
  }
  return out;
}

// Description of the x or y column: the coupling of the family's chart plane.
std::string axis_text(const control::LoopFamily& f, char axis) {
  const bool single = f.kind == control::LoopFamily::Kind::SingleOscillator;
  if (axis == 'x') return single ? "coupling a (eq. 5) of the grid point" : "coupling alpha (eq. 20) of the grid point";
  return single ? "coupling b (eq. 5) of the grid point" : "coupling beta (eq. 20) of the grid point";
}

// A point of the delay-margin map: (x[i], y[j]).
struct MarginMapPoint {
  const control::MarginMap& map;
  int i, j;
  std::size_t k() const { return static_cast<std::size_t>(j) * map.x.size() + static_cast<std::size_t>(i); }
};

// The margin map's table: the rows are the (y, x) grid, x fastest.
io::TableOf<MarginMapPoint> margin_map_table(const control::LoopFamily& family, const control::RotationUnits& u,
                                             int nx, int ny) {
  const ControlUnits cu(u);
  using P = MarginMapPoint;
  io::TableOf<P> table{
      {"x", cu.omega, axis_text(family, 'x'), [](const P& p) { return p.map.x[p.i]; }},
      {"y", cu.omega, axis_text(family, 'y'), [](const P& p) { return p.map.y[p.j]; }},
      {"critical_delay", cu.period, "delay margin tau_c (inf: no crossing, nan: unstable at tau = 0)",
       [](const P& p) { return p.map.critical_delay[p.k()]; }},
      {"crossing_frequency", cu.omega, "crossing frequency nu at tau_c",
       [](const P& p) { return p.map.crossing_frequency[p.k()]; }}};
  table.grid({{"y", family.y_name(), static_cast<std::size_t>(ny)}, {"x", family.x_name(), static_cast<std::size_t>(nx)}});
  return table;
}

// A point of one stability chart: (x[i], y[j]) at its delay.
struct ChartPoint {
  const control::StabilityChart& chart;
  int i, j;
  double delay;
  std::size_t k() const { return static_cast<std::size_t>(j) * chart.x.size() + static_cast<std::size_t>(i); }
};

// The charts' table: the rows are the (delay, y, x) grid, x fastest (one chart after the other).
io::TableOf<ChartPoint> chart_table(const control::LoopFamily& family, const control::RotationUnits& u,
                                    std::size_t delays, int nx, int ny) {
  const ControlUnits cu(u);
  using P = ChartPoint;
  io::TableOf<P> table{
      {"x", cu.omega, axis_text(family, 'x'), [](const P& p) { return p.chart.x[p.i]; }},
      {"y", cu.omega, axis_text(family, 'y'), [](const P& p) { return p.chart.y[p.j]; }},
      {"spectral_abscissa", cu.omega, "largest real part of the closed-loop roots (= -decay rate)",
       [](const P& p) { return p.chart.abscissa[p.k()]; }},
      {"unstable_roots", "count", "roots with Re s > 0 (region label, argument-principle count; -1: infinitely many)",
       [](const P& p) { return static_cast<long>(p.chart.unstable_roots[p.k()]); }},
      {"region", "label", "region id (connected set of grid points with equal counts, within its delay)",
       [](const P& p) { return static_cast<long>(p.chart.region[p.k()]); }},
      {"delay", "T", "measurement delay tau of the chart", &P::delay}};
  table.grid({{"delay", "delay", delays},
              {"y", family.y_name(), static_cast<std::size_t>(ny)},
              {"x", family.x_name(), static_cast<std::size_t>(nx)}});
  return table;
}

void run_margin_map(const io::ParamSet& p, const control::ControlSettings& c, const Window& win, Captured* capture) {
  const control::RotationUnits u = c.units();
  const control::LoopFamily family = control::LoopFamily::from_loop(control::loop_from(c));
  const int nx = static_cast<int>(p.integer("x_points")), ny = static_cast<int>(p.integer("y_points"));
  const io::ParamSet as_run = params_as_run(p, c, window_values(win));
  CommandOutput out(as_run, capture, "control chart --quantity margin");
  require_memory("x_points", static_cast<double>(nx), static_cast<double>(ny) * (out.writes_file() ? 64.0 : 320.0));
  auto rows = out.open(margin_map_table(family, u, nx, ny));
  io::Progress progress("control chart (grid points)", static_cast<long>(nx) * ny, p.flag("progress"));
  const control::MarginMap m =
      control::delay_margin_map(family, u.rate(win.x_min), u.rate(win.x_max), nx, u.rate(win.y_min), u.rate(win.y_max),
                                ny, static_cast<int>(p.integer("threads")),
                                [&progress](long n, long) { progress.advance(n); }, cancellation_of(capture));
  progress.finish();
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) rows.add({m, i, j});
  UnitTagged res;
  res.add("family", describe_family(family))
      .add("x", family.x_name())
      .add("y", family.y_name())
      .add("window", window_json(win), control::RotationUnits::rate_unit)  // given in units of Ω
      .add("x_points", nx, "count")
      .add("y_points", ny, "count")
      .add("settings", settings_json(c))  // records with their own units
      .add("settings_si", settings_si_json(c));
  out.finish(res.with_units(), fmt::format("the {}x{} delay-margin map", nx, ny));
}

// A point of a D-subdivision boundary curve (curve: its id within its delay).
struct BoundaryRow {
  long curve;
  const control::BoundaryPoint& point;
  double delay;
};

io::TableOf<BoundaryRow> boundaries_table(const control::LoopFamily& family, const control::RotationUnits& u) {
  const ControlUnits cu(u);
  using B = BoundaryRow;
  return {{"curve", "label", "polyline id (within its delay)", &B::curve},
          {"frequency", cu.omega, "crossing frequency nu of the imaginary-axis roots on the curve (0: root at s = 0)",
           [](const B& b) { return b.point.frequency; }},
          {"x", cu.omega, axis_text(family, 'x'), [](const B& b) { return b.point.x; }},
          {"y", cu.omega, axis_text(family, 'y'), [](const B& b) { return b.point.y; }},
          {"delay", "T", "measurement delay tau of the chart", &B::delay}};
}

void run_chart(const io::ParamSet& p, Captured* capture) {
  const control::ControlSettings c = control_settings_from(p);
  const std::vector<control::ControlSettings> runs = settings_per_delay(p, c);
  const control::LoopFamily first = control::LoopFamily::from_loop(control::loop_from(runs.front()));
  const Window win = window_from(p, first, kSingleWindow, kCouplingsWindow);
  if (p.text("quantity") == "margin") return run_margin_map(p, runs.front(), win, capture);
  const control::RotationUnits u = c.units();
  const int nx = static_cast<int>(p.integer("x_points")), ny = static_cast<int>(p.integer("y_points"));
  std::vector<std::pair<std::string, double>> values = window_values(win);
  io::ParamSet as_run = params_as_run(p, c, values);
  std::string delays_text;
  for (const auto& r : runs) delays_text += fmt::format("{}{}", delays_text.empty() ? "" : ",", r.delay);
  as_run.set_from_string("delays", delays_text);
  CommandOutput out(as_run, capture, "control chart");
  const bool json = p.flag("json");
  const std::string bout = p.text("boundaries_output");
  // memory of one chart (values, counts, labels and the tracked roots of each point), and of the rows --json keeps
  require_memory("x_points", static_cast<double>(nx), static_cast<double>(ny) * 64.0);
  if (json && !out.writes_file())
    require_memory("x_points", static_cast<double>(nx), static_cast<double>(ny) * 320.0 * runs.size());
  {
    // each grid point tracks the spectrum at its delay: the work grows with the largest delay
    double largest = 0;
    for (const auto& r : runs) largest = std::max({largest, r.delay, r.controller == control::ControllerKind::Smith
                                                                          ? r.model_delay_value() : 0.0});
    require_delay_work(p, p.reals("delays").empty() ? "delay" : "delays", largest, u,
                       static_cast<double>(nx) * ny * static_cast<double>(runs.size()), c.harmonics,
                       "x_points x y_points per delay");
  }
  const io::TableOf<BoundaryRow> boundary_table = boundaries_table(first, u);
  std::optional<io::TableWriter> boundaries;
  if (!bout.empty()) boundaries.emplace(bout, boundary_table.columns());
  nlohmann::json boundary_rows = nlohmann::json::array();  // --json without a boundaries file
  auto rows = out.open(chart_table(first, u, runs.size(), nx, ny));
  io::Progress progress("control chart (grid points)", static_cast<long>(nx) * ny * static_cast<long>(runs.size()),
                        p.flag("progress"));
  const ControlUnits cu(u);
  // a region of a chart and a chart, each number with its unit
  const auto region_record = [&](const control::ChartRegion& r) {
    UnitTagged j;
    j.add("id", r.id, "label")
        .add("unstable_roots", r.unstable_roots, "count")
        .add("tracked_roots", r.tracked_roots, "count")
        .add("points", r.points, "count")
        .add("x", r.x, cu.omega)
        .add("y", r.y, cu.omega)
        .add("certified", r.certified, "boolean (0/1)");
    return j;
  };
  const auto chart_record = [&](const control::StabilityChart& chart, double delay, const std::string& family,
                                bool delay_exceeds_period) {
    std::vector<UnitTagged> regions;
    for (const auto& r : chart.regions) regions.push_back(region_record(r));
    UnitTagged j;
    j.add("delay", delay, control::RotationUnits::delay_unit)  // given in units of T
        .add("family", family)
        .add("delay_exceeds_period", delay_exceeds_period, "boolean (0/1)")
        .add("regions", regions, region_record(control::ChartRegion{}))
        .add("boundary_curves", chart.boundaries.size(), "count")
        .add("mismatched_points", chart.mismatched_points, "count")
        .add("recomputed_points", chart.recomputed_points, "count")
        .add("lower_bound_points", chart.lower_bound_points, "count");
    return j;
  };
  std::vector<UnitTagged> charts;
  long curves = 0;
  for (const control::ControlSettings& at : runs) {
    const control::LoopSpec loop = control::loop_from(at);
    control::ChartSpec spec;
    spec.family = control::LoopFamily::from_loop(loop);
    spec.x_min = u.rate(win.x_min);
    spec.x_max = u.rate(win.x_max);
    spec.y_min = u.rate(win.y_min);
    spec.y_max = u.rate(win.y_max);
    spec.x_points = nx;
    spec.y_points = ny;
    spec.threads = static_cast<int>(p.integer("threads"));
    spec.cancellation = cancellation_of(capture);
    const control::StabilityChart chart =
        control::stability_chart(spec, [&progress](long n, long) { progress.advance(n); });
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) rows.add({chart, i, j, at.delay});
    for (std::size_t ci = 0; ci < chart.boundaries.size(); ++ci)
      for (const control::BoundaryPoint& q : chart.boundaries[ci]) {
        const BoundaryRow row{static_cast<long>(ci), q, at.delay};
        if (boundaries) {
          io::write_row(*boundaries, boundary_table, row);
        } else if (json) {
          nlohmann::json cells = nlohmann::json::array();
          for (const auto& c : boundary_table.entries()) cells.push_back(io::cell_json(c.value(row)));
          boundary_rows.push_back(std::move(cells));
        }
      }
    curves += static_cast<long>(chart.boundaries.size());
    charts.push_back(chart_record(chart, at.delay, describe_family(spec.family), loop.delay >= loop.period()));
  }
  progress.finish();
  nlohmann::json delays = nlohmann::json::array();  // given in units of T
  for (const auto& at : runs) delays.push_back(at.delay);
  UnitTagged tagged;
  tagged.add("x", first.x_name())
      .add("y", first.y_name())
      .add("window", window_json(win), control::RotationUnits::rate_unit)  // given in units of Ω
      .add("x_points", nx, "count")
      .add("y_points", ny, "count")
      .add("delays", delays, control::RotationUnits::delay_unit)
      .add("charts", charts, chart_record(control::StabilityChart{}, 0.0, "", false))
      .add("boundaries_file", bout)
      .add("settings", settings_json(c))  // records with their own units
      .add("settings_si", settings_si_json(c));
  nlohmann::json res = tagged.with_units();
  if (boundaries) {
    nlohmann::json bres;
    bres["x"] = first.x_name();
    bres["y"] = first.y_name();
    bres["window"] = window_json(win);
    bres["delays"] = res["delays"];
    bres["grid_file"] = out.path();
    boundaries->stage(io::make_sidecar("control chart (D-subdivision boundaries)", as_run, bres), out.outputs());
  } else if (json) {
    res["boundaries"] = {{"columns", io::columns_json(boundary_table.columns())}, {"rows", boundary_rows}};
  }
  out.finish(res, fmt::format("{} {}x{} chart{} ({} boundary curves{})", runs.size(), nx, ny, runs.size() > 1 ? "s" : "",
                              curves, bout.empty() ? "" : " in " + bout));
}

}  // namespace

void add_control_chart(CLI::App& control) {
  add_command(
      control, "chart",
      "stability chart in the coupling plane (a, b) or (alpha, beta): spectral abscissa grid, certified region "
      "labels, exact D-subdivision boundaries (paper Figs. 2, 4), at one delay or several (delays). Cost: O(N) per "
      "Newton step of each tracked root per grid point, O(N^2) per fresh spectrum and per certified region",
      [](io::ParamSet& p) {
        add_control_params(p);
        p.group("Chart")
            .text("quantity", "abscissa", "abscissa: spectral abscissa + unstable roots; margin: tau_c map",
                  {"abscissa", "margin"})
            .reals("delays", {}, "several delays: one chart per delay in the same table (column delay), boundaries "
                                 "likewise; replaces delay", Range::non_negative())
            .unit("T")
            .default_text("= delay");
        add_si_alternative(p, "delays", SiUnit::Auto, Range::non_negative());
        add_window_params(p, kSingleWindow, kCouplingsWindow);
        p.integer("x_points", 200, "grid points along x", 2, 100000)
            .integer("y_points", 200, "grid points along y", 2, 100000);
        add_threads_param(p);
        add_output_params(p, "out/control_chart.csv", "grid");
        add_progress_flag(p);
        p.file("boundaries_output", "out/control_chart_boundaries.csv",
                  "boundary curves CSV path (JSON sidecar next to it); empty: no file (with --json: in the printed "
                  "document)")
            .writes(io::table_and_sidecar);
      },
      with_si_inputs(run_chart));
}

}  // namespace afmkit::cli
