#include "program.hpp"

#include <string>

#include "afmkit/core/version.hpp"
#include "commands.hpp"

namespace afmkit::cli {

Program::Program()
    : CLI::App("afmkit: dynamics and control of atomic force microscopes (tapping-mode impact dynamics, "
               "first-harmonic rejection for rotational scanning)",
               "afmkit") {
  require_subcommand(1);
  set_version_flag("--version", std::string(afmkit::version));
  register_all(*this);
}

void register_all(CLI::App& app) {
  register_report(app);
  register_demo(app);
  register_impact(app);
  register_tapping(app);
  register_control(app);
  register_scan(app);
  register_study(app);
  register_spectroscopy(app);
}

std::vector<CommandSpec> command_specs() { return Program().commands; }

}  // namespace afmkit::cli
