#include "command.hpp"
#include "commands.hpp"

namespace afmkit::cli {

void register_spectroscopy(CLI::App& app) {
  CLI::App& spectroscopy = add_command_group(
      app, "spectroscopy", "Measured curves: preparation into a table law, force reconstruction (AM, FM), fits of laws (docs/spectroscopy.md)");
  register_spectroscopy_prepare(spectroscopy);
  register_spectroscopy_reconstruct(spectroscopy);
  register_spectroscopy_fit(spectroscopy);
}

}  // namespace afmkit::cli
