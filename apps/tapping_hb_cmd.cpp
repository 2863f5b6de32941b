#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace afmkit::cli {

// Placeholder registration: the subcommand is added when its domain lands.
void register_tapping_hb(CLI::App& /*tapping*/) {}

}  // namespace afmkit::cli
