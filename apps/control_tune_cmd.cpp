// afmkit control tune: robust couplings of the seed-2 loop: maximise the worst-case decay rate over a delay range
// and a gain-error range (tuning.hpp). Units: control_params.hpp (couplings and decay rates in units of Ω, delays
// in units of T, gain ratios dimensionless).
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/tuning.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/progress.hpp"
#include "afmkit/io/table.hpp"
#include "command.hpp"
#include "control_analysis.hpp"
#include "control_params.hpp"
#include "control_units.hpp"
#include "unit_tagged.hpp"
#include "work_budget.hpp"

namespace afmkit::cli {

namespace {
// Time of one objective evaluation per gain point per (harmonics + 1): measured 3.5e-4 … 7.5e-4 s (N = 20 … 200,
// default delay_points, one thread, 2-core test machine under load, Release; it grows faster than N), taken as
// 1e-4 s: the estimate is a lower bound, so only requests that cannot fit are refused.
constexpr double kEvaluationSeconds = 1e-4;
}  // namespace

namespace {

// The default search windows (units of Ω): the single oscillator's (a, b), the couplings' (alpha, beta).
constexpr Window kSingleWindow{0.01, 2.0, -2.0, 0.9};
constexpr Window kCouplingsWindow{0.01, 0.6, -0.24, 0.3};

using io::Range;

// A point (x[i], y[j]) of the tuning's coarse grid.
struct CoarsePoint {
  const control::RobustTuning& tuning;
  int i, j;
};

// The coarse grid's table: the rows are the (y, x) grid of n x n points, x fastest.
io::TableOf<CoarsePoint> coarse_grid_table(const control::LoopFamily& family, const control::RotationUnits& u, int n) {
  const ControlUnits cu(u);
  using P = CoarsePoint;
  io::TableOf<P> table{
      {"x", cu.omega, std::string(family.x_name()) + " of the coarse grid point",
       [](const P& p) { return p.tuning.coarse_x[p.i]; }},
      {"y", cu.omega, std::string(family.y_name()) + " of the coarse grid point",
       [](const P& p) { return p.tuning.coarse_y[p.j]; }},
      {"worst_decay_rate", cu.omega,
       "objective: smallest decay rate -max Re s over the delays and gain ratios (tracked spectra)",
       [n](const P& p) {
         return p.tuning.coarse_worst_decay[static_cast<std::size_t>(p.j) * n + p.i];
       }}};
  table.grid({{"y", family.y_name(), static_cast<std::size_t>(n)}, {"x", family.x_name(), static_cast<std::size_t>(n)}});
  return table;
}

void run_tune(const io::ParamSet& p, Captured* capture) {
  const control::ControlSettings c = control_settings_from(p);
  const control::LoopSpec loop = control::loop_from(c);
  const control::RotationUnits u = c.units();
  control::RobustTuningSpec s;
  s.family = control::LoopFamily::from_loop(loop);
  const Window win = window_from(p, s.family, kSingleWindow, kCouplingsWindow);
  s.x_min = u.rate(win.x_min);
  s.x_max = u.rate(win.x_max);
  s.y_min = u.rate(win.y_min);
  s.y_max = u.rate(win.y_max);
  s.delay_max = u.delay(p.real("delay_max"));
  s.delay_points = static_cast<int>(p.integer("delay_points"));
  s.gain_ratio_min = p.real("gain_ratio_min");
  s.gain_ratio_max = p.real("gain_ratio_max");
  if (s.gain_ratio_max < s.gain_ratio_min)
    throw InvalidParameter("gain_ratio_max", fmt::format("gain_ratio_max = {} is out of range: must be >= "
                                                         "gain_ratio_min = {}", s.gain_ratio_max, s.gain_ratio_min));
  s.gain_points = static_cast<int>(p.integer("gain_points"));
  s.coarse_points = static_cast<int>(p.integer("coarse_points"));
  s.max_evaluations = static_cast<int>(p.integer("max_evaluations"));
  s.threads = static_cast<int>(p.integer("threads"));
  s.cancellation = cancellation_of(capture);
  const io::ParamSet as_run = params_as_run(p, c, window_values(win));
  CommandOutput out(as_run, capture, "control tune");
  require_memory("coarse_points", static_cast<double>(s.coarse_points),
                 s.coarse_points * (out.writes_file() ? 32.0 : 256.0));
  {
    // cost model (docs/development.md#work-and-time): coarse_points² + max_evaluations objective evaluations, each
    // gain_points spectra of the (2N + 2)-dimensional loop with its tracked roots, at least kEvaluationSeconds·(N + 1)
    const double n = static_cast<double>(c.harmonics) + 1.0;
    const double evaluation = static_cast<double>(s.gain_points) * kEvaluationSeconds * n;
    require_work("coarse_points", static_cast<double>(s.coarse_points), evaluation,
                 fmt::format("coarse_points^2 objective evaluations of gain_points = {} spectra each, with harmonics "
                             "= {}: at least {:.2g} s per evaluation",
                             s.gain_points, c.harmonics, evaluation),
                 2.0);
    // each spectrum's roots grow with the delay: delay_points x gain_points spectra per evaluation up to delay_max
    const double spectra = (static_cast<double>(s.coarse_points) * s.coarse_points + s.max_evaluations) *
                           s.delay_points * s.gain_points;
    require_delay_work(p, "delay_max", p.real("delay_max"), u, spectra, c.harmonics,
                       "(coarse_points^2 + max_evaluations) x delay_points x gain_points");
    require_work("max_evaluations", static_cast<double>(s.max_evaluations), evaluation,
                 fmt::format("objective evaluations of gain_points = {} spectra each, with harmonics = {}: at least "
                             "{:.2g} s per evaluation",
                             s.gain_points, c.harmonics, evaluation));
  }
  auto rows = out.open(coarse_grid_table(s.family, u, s.coarse_points));
  io::Progress progress("control tune (objective evaluations)",
                        static_cast<long>(s.coarse_points) * s.coarse_points + s.max_evaluations, p.flag("progress"));
  const control::RobustTuning r = control::robust_tuning(s, [&progress](long n, long) { progress.advance(n); });
  progress.finish();
  const int n = s.coarse_points;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) rows.add({r, i, j});
  const ControlUnits cu(u);
  const auto margin_record = [&](const control::GainMargin& m) {
    UnitTagged j;
    j.add("gain_ratio", m.gain_ratio, "dimensionless")
        .add("critical_delay", m.critical_delay, cu.period)
        .add("crossing_frequency", m.crossing_frequency, cu.omega);
    return j;
  };
  std::vector<UnitTagged> margins;
  for (const auto& m : r.margins) margins.push_back(margin_record(m));
  UnitTagged res;
  res.add("family", describe_family(s.family))
      .add("x", s.family.x_name())
      .add("y", s.family.y_name())
      .add("optimum", {{s.family.x_name(), r.x}, {s.family.y_name(), r.y}}, cu.omega)
      .add("worst_decay_rate", r.worst_decay, cu.omega)
      .add("certified_worst_decay_rate", r.certified_worst_decay, cu.omega)
      .add("worst_delay", r.worst_delay, cu.period)
      .add("worst_gain_ratio", r.worst_gain_ratio, "dimensionless")
      .add("margins", margins, margin_record(control::GainMargin{}))
      .add("window", window_json(win), control::RotationUnits::rate_unit)  // given in units of Ω
      .add("evaluations", r.evaluations, "count")
      .add("converged", r.converged, "boolean (0/1)")
      .add("objective", "max over (x, y) of min over tau in [0, delay_max], rho in [gain_ratio_min, gain_ratio_max] "
                        "of the decay rate -max Re s")
      .add("settings", settings_json(c))  // records with their own units
      .add("settings_si", settings_si_json(c));
  out.finish(res.with_units(), fmt::format("robust optimum {} = {}, {} = {}: worst-case decay rate {} (certified {})",
                              s.family.x_name(), rate_summary(r.x, u, 5), s.family.y_name(), rate_summary(r.y, u, 5),
                              rate_summary(r.worst_decay, u, 5), rate_summary(r.certified_worst_decay, u, 5)));
}

}  // namespace

void add_control_tune(CLI::App& control) {
  add_command(
      control, "tune",
      "robust couplings: maximise the worst-case decay rate over delays [0, delay_max] and gain errors "
      "rho = K/gamma in [gain_ratio_min, gain_ratio_max] (coarse grid + Nelder-Mead). Cost: per objective evaluation "
      "O(N^2) per gain ratio (fresh spectrum) plus O(N) per tracked-root Newton step",
      [](io::ParamSet& p) {
        add_control_params(p);
        p.group("Tuning")
            .real("delay_max", 0.25, "largest delay", Range::non_negative())
            .unit("T");
        add_si_alternative(p, "delay_max", SiUnit::Auto, Range::non_negative());
        p.integer("delay_points", 6, "delay grid points on [0, delay_max]", 1, 10000)
            .real("gain_ratio_min", 0.5, "smallest rho = K/gamma", Range::positive())
            .unit("dimensionless")
            .real("gain_ratio_max", 2.0, "largest rho = K/gamma", Range::positive())
            .unit("dimensionless")
            .integer("gain_points", 3, "rho grid points (geometric)", 1, 10000);
        add_window_params(p, kSingleWindow, kCouplingsWindow);
        p.integer("coarse_points", 12, "coarse grid points per axis", 2, 10000)
            .integer("max_evaluations", 150, "Nelder-Mead budget", 0, 1000000);
        add_threads_param(p);
        add_output_params(p, "out/control_tune.csv", "coarse-grid");
        add_progress_flag(p);
      },
      with_si_inputs(run_tune));
}

}  // namespace afmkit::cli
