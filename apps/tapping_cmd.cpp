#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace afmkit::cli {

void register_tapping(CLI::App& app) {
  auto* tapping = app.add_subcommand("tapping", "Tapping-mode AFM: periodic orbits, harmonic balance, separation sweeps");
  tapping->require_subcommand(1);
  register_tapping_orbit(*tapping);
  register_tapping_hb(*tapping);
  register_tapping_sweep(*tapping);
}

}  // namespace afmkit::cli
