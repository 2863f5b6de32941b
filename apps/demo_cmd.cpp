#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace afmkit::cli {

// Placeholder registration: the subcommand is added when its domain lands.
void register_demo(CLI::App& /*app*/) {}

}  // namespace afmkit::cli
