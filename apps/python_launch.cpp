// Handing a command over to the Python package afmkit (python_launch.hpp).
#include "python_launch.hpp"

#include <dlfcn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <vector>

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

/// The folder holding the package afmkit when this code runs inside its compiled module (Python: the commands of
/// afmkit._afmkit): the module file's folder's parent; empty otherwise.
fs::path loaded_package_dir() {
  Dl_info info{};
  if (::dladdr(reinterpret_cast<void*>(&loaded_package_dir), &info) == 0 || info.dli_fname == nullptr) return {};
  std::error_code ec;
  const fs::path so = fs::canonical(info.dli_fname, ec);
  return ec ? fs::path() : so.parent_path().parent_path();
}

/// The folder holding the Python package `afmkit` with its subpackage `module` (or module file `module`.py): build/python next to build/bin in
/// a build tree, or <prefix>/AFMKIT_PYTHON_INSTALL_DIR next to <prefix>/bin when installed.
std::string python_package_dir(const std::string& module, bool file = false) {
  std::error_code ec;
  std::vector<fs::path> dirs;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path prefix = exe.parent_path().parent_path();
    dirs = {prefix / "python", prefix / AFMKIT_PYTHON_INSTALL_DIR};
  }
  if (file) dirs.push_back(loaded_package_dir());  // inside Python, the interpreter is /proc/self/exe
  for (const fs::path& dir : dirs)
    if (!dir.empty() &&
        (fs::exists(dir / "afmkit" / (module + ".py"), ec) ||
         (!file && fs::exists(dir / "afmkit" / module / "__main__.py", ec))))
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

bool python_module_found(const std::string& module) { return !python_package_dir(module, true).empty(); }

int run_python_function(const std::string& module, const std::string& function, const std::vector<std::string>& args) {
  const std::string dir = python_package_dir(module, true);
  if (dir.empty())
    throw InputError(fmt::format("the Python module afmkit.{} was not found next to this program (build it: it is part "
                                 "of the default build when pybind11-dev is installed, docs/python.md)",
                                 module));
  const char* old = std::getenv("PYTHONPATH");
  const std::string path = old && *old ? dir + ":" + old : dir;
  std::vector<std::string> all = {
      AFMKIT_PYTHON, "-c",
      fmt::format("import sys; from afmkit.{} import {} as f; sys.exit(f(sys.argv[1:]))", module, function)};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) throw InputError(fmt::format("cannot start the Python interpreter {}: {}", AFMKIT_PYTHON, std::strerror(errno)));
  if (pid == 0) {
    ::setenv("PYTHONPATH", path.c_str(), 1);
    ::execv(argv[0], argv.data());
    std::fprintf(stderr, "cannot start the Python interpreter %s: %s\n", AFMKIT_PYTHON, std::strerror(errno));
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw InputError(fmt::format("waiting for the Python interpreter: {}", std::strerror(errno)));
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

}  // namespace afmkit::cli
