#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace afmkit::cli {

void register_control(CLI::App& app) {
  auto* control = app.add_subcommand(
      "control", "First-harmonic rejection under unknown delay: transfer functions, spectra, margins, charts, simulation");
  control->require_subcommand(1);
  register_control_tf(*control);
  register_control_analysis(*control);
  register_control_simulate(*control);
}

}  // namespace afmkit::cli
