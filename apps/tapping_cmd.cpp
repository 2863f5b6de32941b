#include "command.hpp"
#include "commands.hpp"

namespace afmkit::cli {

void register_tapping(CLI::App& app) {
  CLI::App& tapping =
      add_command_group(app, "tapping", "Tapping-mode AFM: periodic orbits, harmonic balance, separation sweeps");
  register_tapping_orbit(tapping);
  register_tapping_hb(tapping);
  register_tapping_sweep(tapping);
  register_tapping_grid(tapping);
  register_tapping_fm(tapping);
  register_tapping_image(tapping);
  register_tapping_modes(tapping);
}

}  // namespace afmkit::cli
