#include "command.hpp"
#include "commands.hpp"

namespace afmkit::cli {

void register_spectroscopy(CLI::App& app) {
  CLI::App& spectroscopy = add_command_group(
      app, "spectroscopy", "Measured curves: preparation, force reconstruction (AM, FM) and fits");
  register_spectroscopy_reconstruct(spectroscopy);
}

}  // namespace afmkit::cli
