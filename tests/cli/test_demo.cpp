// The Quick-start demo prints and records the harmonic-balance folds of its model: they must equal those of
// `tapping hb` on the same model (the demo once printed folds read from freed memory), and its sweep must show
// the retract jump beyond the fold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"

using afmkit_test::run_cli;
using afmkit_test::slurp;
using afmkit_test::TempDir;

TEST(Demo, PrintedFoldsEqualThoseOfTappingHbOnTheSameModel) {
  TempDir dir;
  const auto demo = run_cli("demo --points 21 --output-dir res", dir);
  ASSERT_EQ(demo.status, 0) << demo.err;
  const auto sidecar = nlohmann::json::parse(slurp(dir.path / "res/demo_hb.csv.json"));

  // `tapping hb` on the demo's model: every demo parameter that `tapping hb` also has with another default, set
  // through a TOML file.
  const auto defaults = run_cli("tapping hb --law attractive --output probe.csv", dir);  // the demo's law: its keys recorded
  ASSERT_EQ(defaults.status, 0) << defaults.err;
  const auto hb_keys = nlohmann::json::parse(slurp(dir.path / "probe.csv.json"))["parameters"];
  std::string toml;
  for (const auto& [key, value] : sidecar["parameters"].items())
    if (hb_keys.contains(key) && (hb_keys[key] != value || key == "law") && key != "points" && key != "output") toml += key + " = " + value.dump() + "\n";
  dir.write("demo_model.toml", toml);
  const auto hb = run_cli("tapping hb --config demo_model.toml --output hb.csv", dir);
  ASSERT_EQ(hb.status, 0) << hb.err;
  const auto folds = nlohmann::json::parse(slurp(dir.path / "hb.csv.json"))["results"]["folds"];

  // Printed lines (4 decimals) and recorded values (full precision) against `tapping hb`.
  const std::regex printed(R"(harmonic balance fold \(jump point\) at separation (-?[0-9.]+))");
  std::vector<double> shown;
  for (std::sregex_iterator it(demo.out.begin(), demo.out.end(), printed), end; it != end; ++it)
    shown.push_back(std::stod((*it)[1]));
  const auto& recorded = sidecar["results"]["hb_folds"];
  ASSERT_GE(folds.size(), 1u);
  ASSERT_EQ(shown.size(), folds.size()) << demo.out;
  ASSERT_EQ(recorded.size(), folds.size());
  for (std::size_t i = 0; i < folds.size(); ++i) {
    const double l = folds[i]["separation"].get<double>();
    EXPECT_NEAR(shown[i], l, 5.1e-5);
    EXPECT_EQ(recorded[i]["separation"].get<double>(), l);
    EXPECT_EQ(recorded[i]["amplitude"].get<double>(), folds[i]["amplitude"].get<double>());
  }

  // Each fold is an extremum of l(q) on the demo's own sampled curve (demo_hb.csv): no sample of its branch
  // near q* goes beyond it, and the nearest samples come close to it.
  std::ifstream csv(dir.path / "res/demo_hb.csv");
  std::string line;
  std::getline(csv, line);
  ASSERT_EQ(line, "q,separation,amplitude,offset,phase,branch");
  struct Sample {
    double q, l;
    std::string branch;
  };
  std::vector<Sample> curve;
  while (std::getline(csv, line)) {
    std::istringstream row(line);
    std::string q, l, b, skip;
    std::getline(row, q, ',');
    std::getline(row, l, ',');
    for (int i = 0; i < 3; ++i) std::getline(row, skip, ',');
    std::getline(row, b, ',');
    curve.push_back({std::stod(q), std::stod(l), b});
  }
  for (const auto& fold : folds) {
    const double q = fold["q"].get<double>(), l = fold["separation"].get<double>();
    const double sign = fold["kind"] == "maximum" ? 1.0 : -1.0;
    double closest = 1e300;
    int near = 0;
    for (const Sample& s : curve)
      if (s.branch == fold["branch"] && std::abs(s.q - q) < 0.02) {
        ++near;
        EXPECT_LE(sign * (s.l - l), 1e-12) << "sample beyond the fold at q = " << s.q;
        closest = std::min(closest, std::abs(s.l - l));
      }
    EXPECT_GE(near, 3);
    EXPECT_LT(closest, 1e-3 * std::max(1.0, std::abs(l)));
  }
}

// `demo --units physical` runs the same dimensionless case (lengths scaled by s = A_free / A_free,normalised):
// the folds and jumps the demo exists to show are kept, at s times the normalised separations, whatever spring
// constant and free amplitude are given.
TEST(Demo, PhysicalUnitsKeepTheFoldAtTheScaledSeparation) {
  TempDir dir;
  const auto normalised = run_cli("demo --points 21 --output-dir n", dir);
  ASSERT_EQ(normalised.status, 0) << normalised.err;
  const auto physical = run_cli("demo --points 21 --units physical --spring-constant 3 --free-amplitude 35 "
                                "--output-dir p",
                                dir);
  ASSERT_EQ(physical.status, 0) << physical.err;
  const auto n = nlohmann::json::parse(slurp(dir.path / "n/demo_hb.csv.json"))["results"];
  const auto p = nlohmann::json::parse(slurp(dir.path / "p/demo_hb.csv.json"))["results"];
  EXPECT_NEAR(p["free_amplitude"].get<double>(), 35.0, 1e-9);
  const double s = 35.0 / n["free_amplitude"].get<double>();
  ASSERT_GE(n["hb_folds"].size(), 1u);
  ASSERT_EQ(p["hb_folds"].size(), n["hb_folds"].size());
  for (std::size_t i = 0; i < n["hb_folds"].size(); ++i)
    EXPECT_NEAR(p["hb_folds"][i]["separation"].get<double>(), s * n["hb_folds"][i]["separation"].get<double>(),
                1e-7 * s);
  ASSERT_FALSE(n["sweep_jumps"]["retract"].empty());
  ASSERT_EQ(p["sweep_jumps"]["retract"].size(), n["sweep_jumps"]["retract"].size());
  EXPECT_NEAR(p["sweep_jumps"]["retract"][0].get<double>(), s * n["sweep_jumps"]["retract"][0].get<double>(), 1e-7 * s);
  EXPECT_EQ(p["units"]["length"], "nm");
  EXPECT_EQ(n["units"]["length"], "L");
}
