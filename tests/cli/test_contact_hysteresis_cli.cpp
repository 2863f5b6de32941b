// --hysteresis on the command line (docs/force-laws.md#hysteresis): a table law is contact-aware by default, so a
// tip that never touches dissipates nothing through it; --hysteresis velocity restores the seed's rule.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../tapping_sim/contact_curve.hpp"
#include "cli_run.hpp"

using afmkit_test::run_cli;
using afmkit_test::TempDir;

namespace {
/// The neck curve of contact_curve.hpp as a force-curve file.
void write_neck_curve(const TempDir& dir, const std::string& name) {
  const auto c = afmkit_test::neck_curve();
  std::ostringstream s;
  s << "# DMT approach; retract with a 3 nN neck breaking at +14 nm\ndistance (nm),approach (nN),retract (nN)\n";
  for (std::size_t i = 0; i < c.approach_gap.size(); ++i)
    s << fmt::format("{:.17g},{:.17g},{:.17g}\n", c.approach_gap[i], c.approach_force[i], c.retract_force[i]);
  dir.write(name, s.str());
}
const std::string kSoft =
    "--units physical --law table --force-curve F.csv --spring-constant 1.1841 --resonance-frequency 23.251 "
    "--quality-factor 139.13 --free-amplitude 20 --separation 25 --json";
}  // namespace

TEST(ContactHysteresisCli, ATipThatNeverTouchesDissipatesNothingUnlessVelocitySwitchingIsAsked) {
  TempDir dir;
  write_neck_curve(dir, "F.csv");
  const auto aware = run_cli("tapping orbit " + kSoft, dir);
  const auto seed = run_cli("tapping orbit " + kSoft + " --hysteresis velocity", dir);
  ASSERT_EQ(aware.status, 0) << aware.err;
  ASSERT_EQ(seed.status, 0) << seed.err;
  const auto a = nlohmann::json::parse(aware.out).at("orbits").at(0);
  const auto s = nlohmann::json::parse(seed.out).at("orbits").at(0);
  EXPECT_LE(std::abs(a.at("contact_dissipation").get<double>()), 1e-9 * a.at("drive_work").get<double>());
  EXPECT_GT(s.at("contact_dissipation").get<double>(), 0.02 * s.at("drive_work").get<double>());
  EXPECT_GT(a.at("amplitude").get<double>(), 19.9);   // A/A0 ≈ 1: the conservative law's orbit
  EXPECT_LT(s.at("amplitude").get<double>(), 19.4);  // A/A0 ≈ 0.94 with the seed's rule
}

TEST(ContactHysteresisCli, ImpactStoppedAboveTheContactGapIsElastic) {
  TempDir dir;
  write_neck_curve(dir, "F.csv");
  const std::string args = "impact --law table --force-curve F.csv --mass1 1 --mass2 1 --velocity 4.9 --gap 20 "
                           "--force2 1 --json";
  const auto aware = run_cli(args, dir);
  const auto seed = run_cli(args + " --hysteresis velocity", dir);
  ASSERT_EQ(aware.status, 0) << aware.err;
  ASSERT_EQ(seed.status, 0) << seed.err;
  EXPECT_NEAR(nlohmann::json::parse(aware.out).at("restitution").get<double>(), 1.0, 1e-8);
  EXPECT_LT(nlohmann::json::parse(seed.out).at("restitution").get<double>(), 0.99);
}

TEST(ContactHysteresisCli, ContactHysteresisIsRefusedForTheSeedsLaws) {
  TempDir dir;
  const auto r = run_cli("impact --law dmt --hysteresis contact", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("hysteresis = contact applies only to law = table"), std::string::npos) << r.err;
  const auto ok = run_cli("impact --law dmt --hysteresis velocity --json", dir);
  EXPECT_EQ(ok.status, 0) << ok.err;
}

TEST(ContactHysteresisCli, HarmonicBalanceHonoursTheMemoryOfContact) {
  // x = B + A cos θ that does not reach the contact gap is free: the conservative law's describing functions
  TempDir dir;
  write_neck_curve(dir, "F.csv");
  const std::string args = "tapping hb --units physical --law table --force-curve F.csv --spring-constant 1.1841 "
                           "--resonance-frequency 23.251 --quality-factor 139.13 --free-amplitude 20 "
                           "--separation 25 --points 200 --output hb.csv";
  auto amplitude = [&](const std::string& extra) {
    const auto r = run_cli(args + extra, dir);
    EXPECT_EQ(r.status, 0) << r.err;
    std::ifstream in(dir.path / "hb.csv.json");
    const auto j = nlohmann::json::parse(in).at("results").at("solutions_at_separation");
    EXPECT_EQ(j.size(), 1u);
    return j.at(0).at("amplitude").get<double>();
  };
  EXPECT_GT(amplitude(""), 19.99);                        // A/A0 ≈ 1 (shooting: 0.99997)
  EXPECT_LT(amplitude(" --hysteresis velocity"), 19.4);  // the neck dissipates at every cycle
}

TEST(ContactHysteresisCli, FmOrbitThatNeverTouchesDissipatesNothingThroughTheLaw) {
  // tapping fm carries the memory of contact like shooting: at a 3 nm turning point (contact gap 0.165 nm) the
  // neck's retract branch is never used, so the tip–sample dissipation is rounding; the seed's rule dissipates
  TempDir dir;
  write_neck_curve(dir, "F.csv");
  const std::string args = "tapping fm --units physical --law table --force-curve F.csv --spring-constant 40 "
                           "--resonance-frequency 300 --quality-factor 400 --amplitude 5 --separations 8";
  auto dissipation = [&](const std::string& extra, const std::string& out) {
    const auto r = run_cli(args + extra + " --output " + out, dir);
    EXPECT_EQ(r.status, 0) << r.err;
    std::ifstream in(dir.file(out));
    std::string header, row;
    std::getline(in, header);
    std::getline(in, row);
    std::stringstream h(header), v(row);
    std::string name, value;
    while (std::getline(h, name, ',') && std::getline(v, value, ','))
      if (name == "dissipation") return std::stod(value);  // J per cycle
    ADD_FAILURE() << "no dissipation column in " << header;
    return 0.0;
  };
  const double aware = dissipation("", "aware.csv"), seed = dissipation(" --hysteresis velocity", "seed.csv");
  EXPECT_GT(seed, 1e-19);  // ≈ 2.8 aJ per cycle with velocity-sign switching
  EXPECT_LE(std::abs(aware), 1e-9 * seed);
}
