// Handing a command over to the Python package afmkit (python_launch.hpp).
#include "python_launch.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

#ifndef AFMKIT_PYTHON
#define AFMKIT_PYTHON "/usr/bin/python3"
#endif
#ifndef AFMKIT_PYTHON_INSTALL_DIR
#define AFMKIT_PYTHON_INSTALL_DIR "lib/python3/dist-packages"
#endif

namespace afmkit::cli {

namespace {

namespace fs = std::filesystem;

/// The folder holding the Python package `afmkit` with its subpackage `module`: build/python next to build/bin in
/// a build tree, or <prefix>/AFMKIT_PYTHON_INSTALL_DIR next to <prefix>/bin when installed.
std::string python_package_dir(const std::string& module) {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path prefix = exe.parent_path().parent_path();
  for (const fs::path& dir : {prefix / "python", prefix / AFMKIT_PYTHON_INSTALL_DIR})
    if (fs::exists(dir / "afmkit" / module / "__main__.py", ec) || fs::exists(dir / "afmkit" / (module + ".py"), ec))
      return dir.string();
  return {};
}

}  // namespace

void exec_python_module(const std::string& module, const std::vector<std::string>& args) {
  const std::string dir = python_package_dir(module);
  if (dir.empty())
    throw InputError("the Python package afmkit was not found next to this program (build it: it is part of the "
                     "default build when pybind11-dev is installed, docs/python.md)");
  const char* old = std::getenv("PYTHONPATH");
  const std::string path = old && *old ? dir + ":" + old : dir;
  ::setenv("PYTHONPATH", path.c_str(), 1);
  std::vector<std::string> all = {AFMKIT_PYTHON, "-m", "afmkit." + module};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  ::execv(argv[0], argv.data());
  throw InputError(fmt::format("cannot start the Python interpreter {}: {}", AFMKIT_PYTHON, std::strerror(errno)));
}

}  // namespace afmkit::cli
