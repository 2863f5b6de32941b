#pragma once
// Numerical parameters shared by `afmkit tapping orbit` and `afmkit tapping sweep` (integrator, shooting,
// transients). Owned by the tapping-simulation helper.
#include <string>

#include "afmkit/io/params.hpp"
#include "afmkit/tapping/transient.hpp"

namespace afmkit::cli {

/// The "Numerics" group: the fields of tapping::ShootingOptions (with its SimulationOptions) and
/// tapping::TransientOptions, as their describe() declares them (apps/described_params.hpp).
void add_tapping_sim_params(io::ParamSet& p);
/// The resolved values of those fields (read_fields).
tapping::ShootingOptions shooting_options_from(const io::ParamSet& p);
tapping::TransientOptions transient_options_from(const io::ParamSet& p);

/// Refuses (work_budget.hpp: InvalidParameter naming max_transient_periods, exit 2) a run whose `transients` full
/// transients cannot fit in the work limit — each lasts min(max_transient_periods, quality_factor) drive periods
/// (a response decaying at Q settles in about Q periods) of at least kTransientPeriodSeconds — and returns that
/// lower bound in seconds (progress is shown above kProgressAfterSeconds). `what` names the transients in the
/// message ("2 transients", "2 transients at each of 33 separations").
double require_transient_work(const io::ParamSet& p, const tapping::TransientOptions& transient, double transients,
                              const std::string& what);

/// Time of one drive period of a transient: measured 4.1e-7 s (closed-form piecewise-linear law, no contact, the
/// fastest) to 3.5e-5 s (in contact every period; 2-core test machine under load, Release), taken as 2e-7 s: the
/// estimate is a lower bound, so only requests that cannot fit are refused.
inline constexpr double kTransientPeriodSeconds = 2e-7;

}  // namespace afmkit::cli
