#include "command.hpp"
#include "commands.hpp"

namespace afmkit::cli {

void register_spectroscopy(CLI::App& app) {
  CLI::App& spectroscopy = add_command_group(
      app, "spectroscopy", "Measured force and AM-AFM curves: preparation into a table law, force reconstruction, fitting of laws (docs/spectroscopy.md)");
  register_spectroscopy_prepare(spectroscopy);
  register_spectroscopy_fit(spectroscopy);
}

}  // namespace afmkit::cli
