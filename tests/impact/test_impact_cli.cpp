// End-to-end check of `afmkit impact` (apps/impact_cmd.cpp) through the built binary AFMKIT_CLI. Skipped when
// the afmkit_cli target has not been built in this build tree (the lead's tests/cli cover the CLI in general).
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

namespace {

struct CliRun {
  int status;
  std::string out;
};

CliRun run(const std::string& args) {
  const std::string cmd = std::string(AFMKIT_CLI) + " impact " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return {-1, ""};
  std::string out;
  char buffer[4096];
  while (std::size_t n = fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int raw = pclose(pipe);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, out};
}

bool have_cli() { return std::filesystem::exists(AFMKIT_CLI); }

}  // namespace

TEST(ImpactCli, JsonRestitutionAndEnergies) {
  if (!have_cli()) GTEST_SKIP() << "afmkit_cli not built";
  const CliRun r = run("--mass1 2 --mass2 3 --velocity 1.5 --approach-stiffness 4 --departure-stiffness 1 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["outcome"], "separated");
  EXPECT_EQ(j["method"], "closed_form");
  EXPECT_NEAR(j["restitution"].get<double>(), 0.5, 1e-14);  // √(K_b/K_a)
  const double mu = 2.0 * 3.0 / 5.0, loss = (1 - 0.25) * mu / 2 * 1.5 * 1.5;  // eq. (3)
  EXPECT_NEAR(j["kinetic_energy_loss"].get<double>(), loss, 1e-13);
  EXPECT_NEAR(j["energy_loss_area"].get<double>(), loss, 1e-13);
}

TEST(ImpactCli, RestitutionOptionSetsDepartureStiffness) {
  if (!have_cli()) GTEST_SKIP() << "afmkit_cli not built";
  const CliRun r = run("--restitution 0.3 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["restitution"].get<double>(), 0.3, 1e-14);
}

TEST(ImpactCli, OutputWritesHistoryAndSidecar) {
  if (!have_cli()) GTEST_SKIP() << "afmkit_cli not built";
  const auto dir = std::filesystem::temp_directory_path() / "afmkit_impact_cli_test";
  std::filesystem::remove_all(dir);
  const std::string csv = (dir / "dmt.csv").string();
  const CliRun r = run("--law dmt --mass1 3e-10 --mass2 1e-11 --velocity 3e6 --gap 2 --departure-modulus 0.8 "
                    "--departure-hamaker 1e-19 --points 50 --output " + csv);
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("t,gap,gap_rate,force", 0), 0u) << header;
  int rows = 0;
  for (std::string line; std::getline(in, line);) ++rows;
  EXPECT_GE(rows, 50);
  std::ifstream side(csv + ".json");
  const auto j = nlohmann::json::parse(side);
  const auto& res = j["results"];
  EXPECT_EQ(res["outcome"], "separated");
  EXPECT_EQ(res["method"], "integrator");
  EXPECT_NEAR(res["kinetic_energy_loss"].get<double>(), res["energy_loss_area"].get<double>(),
              1e-8 * res["kinetic_energy_before"].get<double>());
  std::filesystem::remove_all(dir);
}

TEST(ImpactCli, BadInputExitsWithStatus2NamingTheParameter) {
  if (!have_cli()) GTEST_SKIP() << "afmkit_cli not built";
  CliRun r = run("--mass1 -1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("mass1"), std::string::npos) << r.out;
  r = run("--v1 0 --v2 1");  // separating
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("relative_velocity"), std::string::npos) << r.out;
  r = run("--law dmt --approach-stiffness 3");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("approach_stiffness"), std::string::npos) << r.out;
  r = run("--law linear --mass2 nan");
  EXPECT_EQ(r.status, 2);
}
