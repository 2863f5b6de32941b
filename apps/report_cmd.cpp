// afmkit report: every figure of both papers and the figures beyond them, computed with afmkit, in one HTML page
// (out/report/index.html). The report is the Python package afmkit.report (python/afmkit/report/, Matplotlib): this
// command validates its parameters and hands over to the Python interpreter afmkit was built with.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/params.hpp"
#include "command.hpp"
#include "commands.hpp"

#ifndef AFMKIT_PYTHON
#define AFMKIT_PYTHON "/usr/bin/python3"
#endif
#ifndef AFMKIT_PYTHON_INSTALL_DIR
#define AFMKIT_PYTHON_INSTALL_DIR "lib/python3/dist-packages"
#endif

namespace afmkit::cli {

namespace {

namespace fs = std::filesystem;

/// The folder holding the Python package `afmkit`: build/python next to build/bin in a build tree, or
/// <prefix>/AFMKIT_PYTHON_INSTALL_DIR next to <prefix>/bin when installed.
std::string python_package_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path prefix = exe.parent_path().parent_path();
  for (const fs::path& dir : {prefix / "python", prefix / AFMKIT_PYTHON_INSTALL_DIR})
    if (fs::exists(dir / "afmkit" / "report" / "__main__.py", ec)) return dir.string();
  return {};
}

/// Refuses an output folder that cannot be created or written, before anything starts and without creating it
/// (the report creates it, and checks again).
void check_writable(const std::string& dir) {
  auto refuse = [&](const std::string& why) {
    throw InvalidParameter("output_dir",
                           fmt::format("output_dir '{}' cannot be written: {}: must be a writable folder", dir, why));
  };
  if (dir.empty()) refuse("empty");
  std::error_code ec;
  fs::path existing = dir;  // the folder itself, or the nearest ancestor that exists (where it would be created)
  while (!existing.empty() && !fs::exists(existing, ec)) existing = existing.parent_path();
  if (existing.empty()) existing = ".";
  if (!fs::is_directory(existing, ec)) refuse(fmt::format("'{}' is not a folder", existing.string()));
  if (::access(existing.c_str(), W_OK | X_OK) != 0) refuse(fmt::format("'{}': {}", existing.string(), std::strerror(errno)));
}

void run_report(const io::ParamSet& p, Captured*) {
  check_writable(p.text("output_dir"));
  const std::string dir = python_package_dir();
  if (dir.empty())
    throw InputError("the Python package afmkit was not found next to this program (build it: it is part of the "
                     "default build when pybind11-dev is installed, docs/python.md)");
  const char* old = std::getenv("PYTHONPATH");
  const std::string path = old && *old ? dir + ":" + old : dir;
  ::setenv("PYTHONPATH", path.c_str(), 1);
  std::vector<std::string> args = {AFMKIT_PYTHON, "-m", "afmkit.report", "--output-dir", p.text("output_dir"),
                                   "--jobs", std::to_string(p.integer("jobs")), "--figures", p.text("figures")};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  ::execv(argv[0], argv.data());
  throw InputError(fmt::format("cannot start the Python interpreter {}: {}", AFMKIT_PYTHON, std::strerror(errno)));
}

}  // namespace

void register_report(CLI::App& app) {
  add_command(
      app, "report",
      "every figure of both papers and beyond, computed with afmkit, in one HTML page (out/report/index.html) "
      "with captions and a table of key numbers; Python + Matplotlib, about 5 seconds on 2 cores",
      [](io::ParamSet& p) {
        p.group("Report")
            .file("output_dir", "out/report", "folder the report is written to (index.html and the figures' PNG "
                                              "files); index.html is replaced only when the report is complete")
            .integer("jobs", 2, "figures computed at the same time (processes)", 1, 64)
            .text("figures", "all",
                  "'all', or a comma-separated list of figure ids (seed000-fig3, seed003-fig2, beyond-tuning, …: "
                  "docs/report.md lists them); an unknown id is refused before anything is computed");
      },
      run_report);
}

}  // namespace afmkit::cli
