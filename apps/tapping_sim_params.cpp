#include "tapping_sim_params.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "described_params.hpp"
#include "work_budget.hpp"

namespace afmkit::cli {

void add_tapping_sim_params(io::ParamSet& p) {
  p.group("Numerics");
  declare_fields(p, tapping::ShootingOptions{});  // integrator, tolerances, Newton, time budget
  declare_fields(p, tapping::TransientOptions{});
}

tapping::ShootingOptions shooting_options_from(const io::ParamSet& p) {
  tapping::ShootingOptions o;
  read_fields(p, o);
  return o;
}

tapping::TransientOptions transient_options_from(const io::ParamSet& p) {
  tapping::TransientOptions o;
  read_fields(p, o);
  return o;
}

double require_transient_work(const io::ParamSet& p, const tapping::TransientOptions& transient, double transients,
                              const std::string& what) {
  const double quality = p.real("quality_factor");
  const double periods = static_cast<double>(transient.max_periods);
  return require_work_with("max_transient_periods", periods,
                           transients * kTransientPeriodSeconds * std::min(1.0, quality / periods), [&] {
                             return fmt::format("{} of min(max_transient_periods, quality_factor) drive periods, "
                                                "quality_factor = {}, at least {:.2g} s per period",
                                                what, quality, kTransientPeriodSeconds);
                           });
}

}  // namespace afmkit::cli
