// afmkit — command-line front end. Exit status: 0 success, 2 bad input (parameter, file, config),
// 1 numerical failure (no convergence, budget exhausted), no answer (a status other than "ok" in the written
// results: docs/commands.md#exit-status) or any other error.
#include <cstdio>
#include <iostream>
#include <new>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "command.hpp"
#include "program.hpp"

int main(int argc, char** argv) {
  afmkit::cli::Program app;                    // every command (program.cpp)
  afmkit::io::remove_temporaries_on_signal();  // Ctrl-C or a kill leaves no half-written output behind
  // A word that names no command where one is expected (`afmkit frobnicate`, `afmkit tapping orbits`).
  const CLI::App* level = &app;
  for (int i = 1; i < argc && argv[i][0] != '-'; ++i) {
    const auto subcommands = level->get_subcommands([](const CLI::App*) { return true; });
    if (subcommands.empty()) break;
    const CLI::App* next = nullptr;
    std::string names;
    for (const CLI::App* sub : subcommands) {
      if (sub->get_name() == argv[i]) next = sub;
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!next) {
      fmt::print(stderr, "afmkit: unknown command '{}': must be one of {} (see afmkit --help)\n", argv[i], names);
      return 2;
    }
    level = next;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const afmkit::InvalidParameter& e) {
    fmt::print(stderr, "afmkit: invalid parameter: {}\n", e.what());
    return 2;
  } catch (const afmkit::InputError& e) {
    fmt::print(stderr, "afmkit: input error: {}\n", e.what());
    return 2;
  } catch (const afmkit::cli::NoAnswer& e) {  // outputs written, with the status in them (docs/commands.md)
    fmt::print(stderr, "afmkit: no answer: {}\n", e.what());
    return 1;
  } catch (const afmkit::NumericalFailure& e) {
    fmt::print(stderr, "afmkit: numerical failure: {}\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {  // last resort: commands check their sizes against memory before work
    fmt::print(stderr, "afmkit: out of memory: the request needs more memory than is available (reduce its sizes: "
                       "points, harmonics, periods, grid points)\n");
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "afmkit: error: {}\n", e.what());
    return 1;
  }
  // results printed to standard output must have arrived (a full disk, a closed pipe): otherwise exit 1
  std::cout.flush();
  if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout)) {
    fmt::print(stderr, "afmkit: error: cannot write the results to standard output\n");
    return 1;
  }
  return 0;
}
