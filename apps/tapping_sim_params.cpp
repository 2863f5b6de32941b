#include "tapping_sim_params.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "work_budget.hpp"

namespace afmkit::cli {

void add_tapping_sim_params(io::ParamSet& p) {
  p.group("Numerics");
  p.text("integrator", "automatic",
         "time integration: closed_form (exact, piecewise-linear laws), adaptive (DOP853, order 8, events located on "
         "its dense output; any law) or automatic",
         {"automatic", "closed_form", "adaptive"})
      .real("relative_tolerance", 1e-10, "adaptive integrator relative tolerance", {0.0, 1.0, true, true})
      .unit("dimensionless")
      .real("absolute_tolerance", 1e-12, "adaptive integrator absolute tolerance of the model state",
            io::Range::positive())
      .unit("L (= nm in physical runs)")
      .real("shooting_tolerance", 1e-11, "Newton convergence of periodic orbits |P(y) - y| / |y|",
            {0.0, 1.0, true, true})
      .unit("dimensionless")
      .integer("max_newton_iterations", 30, "Newton iterations per shooting solve", 1, 1000)
      .integer("max_period_multiple", 4, "look for period-n responses up to this n", 1, 16)
      .integer("max_transient_periods", 20000, "drive periods a transient may take to settle", 24, 100000000)
      .real("time_budget", 30.0, "wall-clock budget of one shooting solve", io::Range::positive())
      .unit("s");
}

tapping::ShootingOptions shooting_options_from(const io::ParamSet& p) {
  tapping::ShootingOptions o;
  const std::string& integrator = p.text("integrator");
  o.simulation.integrator = integrator == "closed_form" ? tapping::Integrator::closed_form
                            : integrator == "adaptive"  ? tapping::Integrator::adaptive
                                                        : tapping::Integrator::automatic;
  o.simulation.relative_tolerance = p.real("relative_tolerance");
  o.simulation.absolute_tolerance = p.real("absolute_tolerance");
  o.tolerance = p.real("shooting_tolerance");
  o.max_iterations = static_cast<int>(p.integer("max_newton_iterations"));
  o.time_budget_seconds = p.real("time_budget");
  return o;
}

tapping::TransientOptions transient_options_from(const io::ParamSet& p) {
  tapping::TransientOptions o;
  o.max_period_multiple = static_cast<int>(p.integer("max_period_multiple"));
  o.max_periods = static_cast<int>(p.integer("max_transient_periods"));
  return o;
}

double require_transient_work(const io::ParamSet& p, const tapping::TransientOptions& transient, double transients,
                              const std::string& what) {
  const double quality = p.real("quality_factor");
  const double periods = static_cast<double>(transient.max_periods);
  return require_work("max_transient_periods", periods,
                      transients * kTransientPeriodSeconds * std::min(1.0, quality / periods),
                      fmt::format("{} of min(max_transient_periods, quality_factor) drive periods, quality_factor = {}, "
                                  "at least {:.2g} s per period",
                                  what, quality, kTransientPeriodSeconds));
}

}  // namespace afmkit::cli
