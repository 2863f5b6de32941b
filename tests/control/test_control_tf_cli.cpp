// `afmkit control tf` end to end (skipped when the CLI has not been built): output format, sidecar content,
// exit status 2 with the parameter named for bad input. Values are checked against independent formulas.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdlib>
#include <unistd.h>
#include <sys/wait.h>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "test_helpers.hpp"

namespace {
namespace fs = std::filesystem;

struct CliRun {
  int status;
  std::string err;
};

CliRun run(const std::string& args, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  const std::string cmd = std::string(AFMKIT_CLI) + " control tf " + args + " > " + (dir / "stdout.txt").string() +
                          " 2> " + err.string();
  const int raw = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, ss.str()};
}

class ControlTfCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(AFMKIT_CLI)) GTEST_SKIP() << "afmkit CLI not built: " << AFMKIT_CLI;
    dir_ = fs::temp_directory_path() / ("afmkit_control_tf_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};
}  // namespace

TEST_F(ControlTfCli, SingleOscillatorCsvMatchesEq10) {
  const fs::path out = dir_ / "tf.csv";
  const CliRun r = run("--controller single --a 0.5 --b 0.2 --gain 3 --points 7 --frequency-min 0.1 --frequency-max 3 "
                    "--output " + out.string(), dir_);
  ASSERT_EQ(r.status, 0) << r.err;
  std::string header;
  const auto rows = afmkit::control::testing::read_tf_csv(out, &header);
  EXPECT_EQ(header, "frequency,magnitude,phase,real,imag");
  for (const auto& row : rows) {
    const double f = row.frequency;
    // eq. (10) with Ω = 1 (units of Ω): C(iω) = K (a iω − b)/(1 − ω²)
    const std::complex<double> expected = 3.0 * std::complex<double>(-0.2, 0.5 * f) / (1.0 - f * f);
    EXPECT_NEAR(row.real, expected.real(), 1e-12 * std::abs(expected));
    EXPECT_NEAR(row.imag, expected.imag(), 1e-12 * std::abs(expected));
    EXPECT_NEAR(row.magnitude, std::abs(expected), 1e-12 * std::abs(expected));
  }
  EXPECT_EQ(rows.size(), 7u);
  std::ifstream side(out.string() + ".json");
  const auto j = nlohmann::json::parse(side);
  EXPECT_EQ(j["command"], "control tf");
  // eq. (13): b < γΩ/K = 20/3
  EXPECT_NEAR(j["results"]["tau0"]["eq13_b_limit"].get<double>(), 20.0 / 3.0, 1e-12);
  EXPECT_TRUE(j["results"]["tau0"]["eq13_stable"].get<bool>());
}

TEST_F(ControlTfCli, JsonSummaryHasCriticalBetaAndRejection) {
  const CliRun r = run("--harmonics 1 --json --output ''", dir_);
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream in(dir_ / "stdout.txt");
  const auto j = nlohmann::json::parse(in);
  EXPECT_NEAR(j["tau0"]["beta_critical_over_omega"].get<double>(), -1.0 / 3.0, 1e-12);  // N = 1: ν² = Ω²/3
  EXPECT_EQ(j["at_harmonics"][0]["sensitivity_magnitude"].get<double>(), 0.0);
}

TEST_F(ControlTfCli, BadInputExitsWithStatus2NamingTheParameter) {
  for (const auto& [args, name] : std::vector<std::pair<std::string, std::string>>{
           {"--harmonics 0", "harmonics"},
           {"--rotation-frequency 0", "rotation_frequency"},
           {"--alpha nan", "alpha"},
           {"--delay -0.5", "delay"},
           {"--frequency-min 0 --log-spacing true", "frequency_min"},
           {"--rejected 1,7 --harmonics 5", "rejected"}}) {
    const CliRun r = run(args + " --output " + (dir_ / "x.csv").string(), dir_);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_NE(r.err.find(name), std::string::npos) << args << ": " << r.err;
  }
}
