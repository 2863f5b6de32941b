#pragma once
// Numerical parameters shared by `afmkit tapping orbit` and `afmkit tapping sweep` (integrator, shooting,
// transients). Owned by the tapping-simulation helper.
#include "afmkit/io/params.hpp"
#include "afmkit/tapping/transient.hpp"

namespace afmkit::cli {

void add_tapping_sim_params(io::ParamSet& p);
tapping::ShootingOptions shooting_options_from(const io::ParamSet& p);
tapping::TransientOptions transient_options_from(const io::ParamSet& p);

}  // namespace afmkit::cli
