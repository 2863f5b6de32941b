#pragma once
// A test fixture that runs the built `afmkit` program (AFMKIT_CLI) in a fresh folder per test, capturing its
// status, standard output and standard error; the test is skipped when the program has not been built.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace afmkit_test {

struct CliResult {
  int status;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class ControlCliFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    namespace fs = std::filesystem;
    if (!fs::exists(AFMKIT_CLI)) GTEST_SKIP() << "afmkit CLI not built: " << AFMKIT_CLI;
    dir_ = fs::temp_directory_path() / ("afmkit_control_cli_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir_.empty()) std::filesystem::remove_all(dir_, ec);
  }
  /// `afmkit <args>` run in the test's folder.
  CliResult run(const std::string& args) const {
    const std::string cmd = "cd '" + dir_.string() + "' && '" + std::string(AFMKIT_CLI) + "' " + args +
                            " > stdout.txt 2> stderr.txt";
    const int raw = std::system(cmd.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(dir_ / "stdout.txt"), slurp(dir_ / "stderr.txt")};
  }
  /// Files written in the folder other than the captured streams.
  int files() const {
    int n = 0;
    for (auto& e : std::filesystem::recursive_directory_iterator(dir_))
      if (e.is_regular_file() && e.path().filename() != "stdout.txt" && e.path().filename() != "stderr.txt") ++n;
    return n;
  }
  std::filesystem::path dir_;
};

}  // namespace afmkit_test
