// afmkit — command-line front end. Exit status: 0 success, 2 bad input (parameter, file, config),
// 1 numerical failure (no convergence, budget exhausted) or any other error.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/version.hpp"
#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"afmkit: dynamics and control of atomic force microscopes (tapping-mode impact dynamics, "
               "first-harmonic rejection for rotational scanning)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(afmkit::version));
  afmkit::cli::register_demo(app);
  afmkit::cli::register_impact(app);
  afmkit::cli::register_tapping(app);
  afmkit::cli::register_control(app);
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
  } catch (const afmkit::NumericalFailure& e) {
    fmt::print(stderr, "afmkit: numerical failure: {}\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "afmkit: error: {}\n", e.what());
    return 1;
  }
  return 0;
}
