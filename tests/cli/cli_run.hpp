#pragma once
// Runs the built `afmkit` program (path AFMKIT_CLI from CMake) in a fresh temporary folder.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace afmkit_test {

/// The sanitizer build (CMake defines AFMKIT_TEST_SANITIZED there; a process runs ~10x slower): a test that runs
/// many processes takes a deterministic sample of its cases there and runs them all in Release
/// (docs/development.md).
#ifdef AFMKIT_TEST_SANITIZED
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

/// Under the sanitizers, whether case `index` of a list is left out of the sample that keeps one case in `every`
/// (indices 0, every, 2·every, …); never in Release.
inline bool left_out_under_sanitizers(std::size_t index, std::size_t every) {
  return kSanitized && index % every != 0;
}

struct RunResult {
  int status;
  std::string out;
  std::string err;
};

/// A fresh empty folder per test (removed at destruction).
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    path = std::filesystem::temp_directory_path() /
           ("afmkit_cli_" + std::to_string(::getpid()) + "_" + std::to_string(counter()++));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  static int& counter() {
    static int c = 0;
    return c;
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(path / name) << text; }
  std::size_t count_files() const {
    std::size_t n = 0;
    for (auto& e : std::filesystem::recursive_directory_iterator(path))
      if (e.is_regular_file()) ++n;
    return n;
  }
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Run `afmkit <args>` with the working directory `dir`.
inline RunResult run_cli(const std::string& args, const TempDir& dir) {
  const std::string out = dir.file(".stdout"), err = dir.file(".stderr");
  const std::string cmd = "cd '" + dir.path.string() + "' && '" + std::string(AFMKIT_CLI) + "' " + args + " >'" + out +
                          "' 2>'" + err + "'";
  const int raw = std::system(cmd.c_str());
  RunResult r{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

/// Run a bash command line in `dir`, in which the word `afmkit` runs the built program (a shell function), so that
/// command lines copied from the documentation run as written (environment prefixes, quoting, $'…').
inline RunResult run_shell(const std::string& line, const TempDir& dir) {
  const std::string script = dir.file(".command.sh"), out = dir.file(".stdout"), err = dir.file(".stderr");
  std::ofstream(script) << "afmkit() { '" << AFMKIT_CLI << "' \"$@\"; }\n" << line << "\n";
  const std::string cmd =
      "cd '" + dir.path.string() + "' && bash '" + script + "' >'" + out + "' 2>'" + err + "' </dev/null";
  const int raw = std::system(cmd.c_str());
  RunResult r{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
  for (const auto& f : {script, out, err}) std::filesystem::remove(f);
  return r;
}

/// The text of a file of the source tree (AFMKIT_SOURCE_DIR from CMake), e.g. "docs/bad-input.md".
inline std::string source_file(const std::string& relative) {
  return slurp(std::filesystem::path(AFMKIT_SOURCE_DIR) / relative);
}

}  // namespace afmkit_test
