#include "command.hpp"
#include "commands.hpp"

namespace afmkit::cli {

void register_spectroscopy(CLI::App& app) {
  CLI::App& spectroscopy = add_command_group(
      app, "spectroscopy", "Measured force and AM-AFM curves: preparation, force reconstruction, fitting of laws");
  register_spectroscopy_fit(spectroscopy);
}

}  // namespace afmkit::cli
