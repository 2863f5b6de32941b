// `tapping sweep --directions approach|both` and `--hb-beside on|off|auto`: the approach-only sweep is the approach
// part of the full one, line for line; without HB beside the points the hb_* columns are nan and every other cell
// is the same; auto puts HB beside the points of a piecewise-linear law (closed form) and not beside those of DMT,
// saying so in the results.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"

using namespace afmkit_test;

namespace {

std::vector<std::string> sweepopt_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::vector<std::string> sweepopt_cells(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) out.push_back(cell);
  return out;
}

std::size_t sweepopt_column(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return i;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

const std::string kSweepoptArgs = "tapping sweep --points 12 --separation-min 8 --separation-max 14 --quiet";

}  // namespace

TEST(SweepOptions, ApproachOnlyIsTheApproachOfTheFullSweep) {
  TempDir dir;
  const auto both = run_cli(kSweepoptArgs + " --output both.csv", dir);
  const auto approach = run_cli(kSweepoptArgs + " --directions approach --output approach.csv", dir);
  ASSERT_EQ(both.status, 0) << both.err;
  ASSERT_EQ(approach.status, 0) << approach.err;
  const auto full = sweepopt_lines(slurp(dir.path / "both.csv"));
  const auto half = sweepopt_lines(slurp(dir.path / "approach.csv"));
  ASSERT_EQ(full.size(), 1u + 2u * 12u);
  ASSERT_EQ(half.size(), 1u + 12u);
  for (std::size_t k = 0; k < half.size(); ++k) EXPECT_EQ(half[k], full[k]) << "line " << k;
  const std::size_t direction = sweepopt_column(sweepopt_cells(half[0]), "direction");
  for (std::size_t k = 1; k < half.size(); ++k) EXPECT_EQ(sweepopt_cells(half[k])[direction], "approach");
  const auto results = nlohmann::json::parse(slurp(dir.path / "approach.csv.json"))["results"];
  EXPECT_EQ(results["directions"], "approach");
  EXPECT_TRUE(results["retract_jumps"].empty());
  EXPECT_EQ(results["units"]["directions"], "label");
  EXPECT_NE(approach.out.find("no retract pass"), std::string::npos) << approach.out;
  // at the defaults nothing new is recorded (the records of a run as before)
  const auto defaults = nlohmann::json::parse(slurp(dir.path / "both.csv.json"));
  EXPECT_FALSE(defaults["results"].contains("directions"));
  EXPECT_FALSE(defaults["results"].contains("harmonic_balance"));
  EXPECT_FALSE(defaults["parameters"].contains("directions"));
  EXPECT_FALSE(defaults["parameters"].contains("hb_beside"));
}

TEST(SweepOptions, HbBesideOffLeavesTheOtherCellsAlone) {
  TempDir dir;
  const auto on = run_cli(kSweepoptArgs + " --output on.csv", dir);
  const auto off = run_cli(kSweepoptArgs + " --hb-beside off --output off.csv", dir);
  ASSERT_EQ(on.status, 0) << on.err;
  ASSERT_EQ(off.status, 0) << off.err;
  const auto with = sweepopt_lines(slurp(dir.path / "on.csv"));
  const auto without = sweepopt_lines(slurp(dir.path / "off.csv"));
  ASSERT_EQ(with.size(), without.size());
  const auto header = sweepopt_cells(with[0]);
  std::size_t finite_hb = 0;
  for (std::size_t k = 1; k < with.size(); ++k) {
    const auto a = sweepopt_cells(with[k]), b = sweepopt_cells(without[k]);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t c = 0; c < a.size(); ++c) {
      if (header[c].rfind("hb_", 0) == 0) {
        EXPECT_EQ(b[c], header[c] == "hb_solutions" ? "0" : "nan") << header[c];
        if (header[c] == "hb_amplitude" && a[c] != "nan") ++finite_hb;
      } else {
        EXPECT_EQ(a[c], b[c]) << header[c] << " at line " << k;
      }
    }
  }
  EXPECT_GT(finite_hb, 0u) << "the piecewise-linear default law has HB beside its points (auto)";
  const auto results = nlohmann::json::parse(slurp(dir.path / "off.csv.json"))["results"];
  EXPECT_NE(results["harmonic_balance"].get<std::string>().find("hb_beside = off"), std::string::npos);
}

TEST(SweepOptions, AutoLeavesHbOutForALawWithoutClosedForm) {
  TempDir dir;
  const std::string dmt =
      "tapping sweep --units physical --law dmt --points 4 --separation-min 6 --separation-max 9 --quiet "
      "--directions approach";
  const auto automatic = run_cli(dmt + " --output auto.csv", dir);
  const auto on = run_cli(dmt + " --hb-beside on --output on.csv", dir);
  ASSERT_EQ(automatic.status, 0) << automatic.err;
  ASSERT_EQ(on.status, 0) << on.err;
  const auto a = sweepopt_lines(slurp(dir.path / "auto.csv")), b = sweepopt_lines(slurp(dir.path / "on.csv"));
  const std::size_t hb = sweepopt_column(sweepopt_cells(a[0]), "hb_solutions");
  std::size_t with_solutions = 0;
  for (std::size_t k = 1; k < a.size(); ++k) {
    EXPECT_EQ(sweepopt_cells(a[k])[hb], "0");
    if (sweepopt_cells(b[k])[hb] != "0") ++with_solutions;
  }
  EXPECT_GT(with_solutions, 0u);
  const auto results = nlohmann::json::parse(slurp(dir.path / "auto.csv.json"))["results"];
  EXPECT_NE(results["harmonic_balance"].get<std::string>().find("law = dmt"), std::string::npos);
}
