#include "command.hpp"
#include "commands.hpp"

namespace afmkit::cli {

void register_control(CLI::App& app) {
  CLI::App& control = add_command_group(
      app, "control",
      "First-harmonic rejection under unknown delay: transfer functions, spectra, margins, charts, simulation");
  register_control_tf(control);
  register_control_analysis(control);
  register_control_simulate(control);
  register_control_export(control);
}

}  // namespace afmkit::cli
