// Units in summaries (issue 24 §2, docs/units.md#summaries): every length, time, force, energy and frequency a
// summary prints is written with the SI prefix of its magnitude in physical units, and a number of a normalised
// model (the tapping model's L, the control commands' Omega and T) says that it is normalised — the tapping and
// control summaries printed fixed "nm" (0.0123 nm) or bare "Omega" / "T" numbers. Checked against the sidecar's
// full-precision values (their declared units), not against the printed text.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"

using afmkit_test::run_cli;
using afmkit_test::slurp;
using afmkit_test::TempDir;

namespace {

/// Every "<label> <mantissa> <prefix>m" in `text`, as metres, with its mantissa.
struct Printed {
  double metres, mantissa;
};
std::vector<Printed> lengths_after(const std::string& text, const std::string& label) {
  static const std::map<std::string, double> prefix = {{"f", 1e-15}, {"p", 1e-12}, {"n", 1e-9},
                                                       {"\xC2\xB5", 1e-6}, {"m", 1e-3}, {"", 1.0}};
  const std::regex re(label + R"( (-?[0-9.]+(?:e[-+][0-9]+)?) (f|p|n|\xC2\xB5|m|)m\b)");
  std::vector<Printed> out;
  for (std::sregex_iterator it(text.begin(), text.end(), re), end; it != end; ++it) {
    const double m = std::stod((*it)[1]);
    out.push_back({m * prefix.at((*it)[2]), m});
  }
  return out;
}

}  // namespace

TEST(SummaryUnits, TappingOrbitPrintsLengthsByMagnitudeInPhysicalUnits) {
  TempDir dir;
  // a 0.35 nm separation: the old summary printed "separation 0.35 nm" and offsets of 0.0xyz nm
  const auto r = run_cli("tapping orbit --units physical --separation 0.35 --output o.csv", dir);
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;
  const auto results = nlohmann::json::parse(slurp(dir.path / "o.csv.json")).at("results");
  ASSERT_EQ(results.at("units").at("length"), "nm");
  const auto separation = lengths_after(r.out, "separation");
  ASSERT_EQ(separation.size(), 1u) << r.out;
  EXPECT_NEAR(separation[0].metres, 0.35e-9, 1e-18);
  EXPECT_EQ(r.out.find("separation 350 pm"), 0u) << r.out;
  const auto offsets = lengths_after(r.out, "offset");
  std::vector<double> expected;  // HB solutions first, then the orbits, as printed
  for (const auto& h : results.at("harmonic_balance")) expected.push_back(h.at("offset").get<double>() * 1e-9);
  for (const auto& o : results.at("orbits")) expected.push_back(o.at("offset").get<double>() * 1e-9);
  ASSERT_EQ(offsets.size(), expected.size()) << r.out;
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    EXPECT_NEAR(offsets[i].metres, expected[i], 1e-5 * std::abs(expected[i]) + 1e-24) << r.out;
    if (expected[i] != 0.0) {  // the prefix puts the mantissa in [1, 1000)
      EXPECT_GE(std::abs(offsets[i].mantissa), 1.0) << r.out;
      EXPECT_LT(std::abs(offsets[i].mantissa), 1000.0) << r.out;
    }
  }
}

TEST(SummaryUnits, NormalisedNumbersSayTheyAreNormalised) {
  TempDir dir;
  const auto orbit = run_cli("tapping orbit --output ''", dir);
  ASSERT_EQ(orbit.status, 0) << orbit.err;
  EXPECT_EQ(orbit.out.find("separation 10 (normalised, units of L):"), 0u) << orbit.out;
  EXPECT_NE(orbit.out.find("amplitude 10.2"), std::string::npos) << orbit.out;
  EXPECT_EQ(orbit.out.find(" L,"), std::string::npos) << orbit.out;  // no bare "L" unit
  const auto hb = run_cli("tapping hb --output ''", dir);
  EXPECT_NE(hb.out.find("at separation 10 (normalised, units of L)"), std::string::npos) << hb.out;
  // control: a delay in units of T, with its value in seconds (Omega = 314.159 rad/s: T = 20 ms)
  const auto margin = run_cli("control margin --harmonics 3 --rotation-frequency 314.159265 --output m.csv", dir);
  ASSERT_EQ(margin.status, 0) << margin.err;
  const auto res = nlohmann::json::parse(slurp(dir.path / "m.csv.json")).at("results");
  const std::regex re(R"(tau_c = ([0-9.]+) \(normalised, units of T; ([0-9.]+) ms\))");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(margin.out, m, re)) << margin.out;
  const double in_periods = res.at("critical_delay").get<double>();
  EXPECT_NEAR(std::stod(m[1]), in_periods, 1e-5 * in_periods);
  EXPECT_NEAR(std::stod(m[2]) * 1e-3, in_periods * 2.0 * std::numbers::pi / 314.159265, 1e-5 * in_periods * 0.02);
  const auto roots = run_cli("control roots --harmonics 3 --output ''", dir);
  EXPECT_NE(roots.out.find("(normalised, units of Omega; "), std::string::npos) << roots.out;
}

namespace {
/// The keys of `record` holding a number or a boolean (or arrays / objects of them) that `units` does not name.
std::vector<std::string> summary_units_missing(const nlohmann::json& record, const nlohmann::json& units) {
  std::vector<std::string> missing;
  for (const auto& [key, value] : record.items()) {
    const bool numeric = value.is_number() || value.is_boolean() || value.is_array() ||
                         (value.is_object() && !value.empty());
    if (numeric && !units.contains(key)) missing.push_back(key);
  }
  return missing;
}
}  // namespace

TEST(SummaryUnits, EveryNumberOfATappingOrbitRecordHasItsUnit) {
  // the orbit records (numbers, flags, nested seeds) and the HB solutions beside them: each key named in `units`
  TempDir dir;
  const auto r = run_cli("tapping orbit --units physical --separation 5 --output o.csv", dir);
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;
  const auto results = nlohmann::json::parse(slurp(dir.path / "o.csv.json")).at("results");
  ASSERT_FALSE(results.at("orbits").empty());
  for (const auto& o : results.at("orbits"))
    EXPECT_EQ(summary_units_missing(o, results.at("units").at("orbits")), std::vector<std::string>{}) << o.dump();
  for (const auto& h : results.at("harmonic_balance"))
    EXPECT_EQ(summary_units_missing(h, results.at("units").at("harmonic_balance")), std::vector<std::string>{})
        << h.dump();
}
