#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace afmkit::cli {

// Placeholder registration: the subcommand is added when its domain lands.
void register_control_analysis(CLI::App& /*control*/) {}

}  // namespace afmkit::cli
