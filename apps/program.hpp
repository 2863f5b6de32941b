#pragma once
// The `afmkit` program: a CLI11 app that also lists every leaf command registered under it (command.hpp:
// CommandSpec), so that other front ends (the Python module) run the same commands with the same parameters.
#include <vector>

#include <CLI/CLI.hpp>

#include "command.hpp"

namespace afmkit::cli {

class Program : public CLI::App {
 public:
  Program();
  std::vector<CommandSpec> commands;  ///< filled by add_command, in registration order
};

/// Registers every command of the program (commands.hpp) under `app`.
void register_all(CLI::App& app);

}  // namespace afmkit::cli
