// Force laws on the command line: one registry for every command, the same key meaning the same in each.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"

using afmkit_test::run_cli;
using afmkit_test::TempDir;

namespace {
nlohmann::json first_orbit(const std::string& args) {
  TempDir dir;
  const auto r = run_cli(args + " --json", dir);
  EXPECT_EQ(r.status, 0) << args << "\n" << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j.at("orbits").empty());
  return j.at("orbits").at(0);
}
}  // namespace

TEST(ForceLawCli, OneModulusMeansNoHysteresisInTappingAsInImpact) {
  // departure_modulus follows effective_modulus in every command: a single modulus dissipates nothing in contact
  const auto same = first_orbit("tapping orbit --units physical --law dmt --effective-modulus 50");
  EXPECT_LT(std::abs(same.at("contact_dissipation").get<double>()), 1e-8 * same.at("drive_work").get<double>());
  const auto softer = first_orbit("tapping orbit --units physical --law dmt --effective-modulus 50 --departure-modulus 30");
  EXPECT_GT(softer.at("contact_dissipation").get<double>(), 1e-3 * softer.at("drive_work").get<double>());
  TempDir dir;
  const auto impact = run_cli("impact --law dmt --effective-modulus 50 --mass1 1e-11 --mass2 1 --velocity 1e6 --json", dir);
  ASSERT_EQ(impact.status, 0) << impact.err;
  EXPECT_NEAR(nlohmann::json::parse(impact.out).at("restitution").get<double>(), 1.0, 1e-8);
}

TEST(ForceLawCli, EveryBuiltInLawRunsInImpactAndTappingOrbit) {
  for (const char* law : {"hertz", "dmt", "jkr", "lennard_jones", "kelvin_voigt"}) {
    SCOPED_TRACE(law);
    TempDir dir;
    const auto r = run_cli(std::string("impact --law ") + law + " --mass1 1e-11 --mass2 1 --velocity 1e6 --gap 2 --json", dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("law").get<std::string>(), law);
    const auto orbit = first_orbit(std::string("tapping orbit --units physical --free-amplitude 10 --separation 8 --law ") + law);
    EXPECT_LT(orbit.at("min_gap").get<double>(), 0.2);
  }
}

TEST(ForceLawCli, MeasuredForceCurveFromAFile) {
  const std::string file = std::string(AFMKIT_SOURCE_DIR) + "/examples/force_curves/dmt_adhesion.csv";
  const auto orbit = first_orbit("tapping orbit --units physical --free-amplitude 10 --separation 8 --law table "
                                 "--force-curve '" + file + "'");
  EXPECT_GT(orbit.at("contact_dissipation").get<double>(), 0.0);
  TempDir dir;
  const auto r = run_cli("impact --law table --force-curve '" + file + "' --mass1 1e-11 --mass2 1 --velocity 3e6 --gap 2 --json", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(nlohmann::json::parse(r.out).at("restitution").get<double>(), 1.0);
}
