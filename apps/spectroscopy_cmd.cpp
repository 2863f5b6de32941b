#include "command.hpp"
#include "commands.hpp"

namespace afmkit::cli {

void register_spectroscopy(CLI::App& app) {
  CLI::App& spectroscopy = add_command_group(
      app, "spectroscopy", "Measured force curves: preparation into a table law (docs/spectroscopy.md)");
  register_spectroscopy_prepare(spectroscopy);
}

}  // namespace afmkit::cli
