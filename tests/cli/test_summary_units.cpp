// Units in summaries (issue 24 §2, docs/units.md#summaries): every length, time, force, energy and frequency a
// summary prints is written with the SI prefix of its magnitude in physical units, and a number of a normalised
// model (the tapping model's L, the control commands' Omega and T) says that it is normalised — the tapping and
// control summaries printed fixed "nm" (0.0123 nm) or bare "Omega" / "T" numbers. Checked against the sidecar's
// full-precision values (their declared units), not against the printed text.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"
#include "help_walk.hpp"

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

// Units at one edge (issue 26 §1): every number, flag and array of numbers a command writes in its results has its
// unit in the results' `units` (a unit string covers what is below it; an object of units is followed key by key,
// into every record of a list). The tapping hb, sweep, fm, modes, demo and spectroscopy prepare results were written
// value by value beside a hand-written units object: demo named only "length", tapping modes had no unit for
// `modes` and `drives`, spectroscopy prepare only units by dimension (its curves, snap_in, pull_off had none).
namespace {
void collect_unitless_results(const nlohmann::json& value, const nlohmann::json* units, const std::string& path,
                              std::vector<std::string>& out) {
  if (units != nullptr && units->is_string()) return;
  if (value.is_number() || value.is_boolean()) {
    out.push_back(path);
  } else if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i)
      collect_unitless_results(value[i], units, path + "/" + std::to_string(i), out);
  } else if (value.is_object()) {
    // a record may carry its own units (control: settings, tau0)
    const nlohmann::json* own = value.contains("units") && value.at("units").is_object() ? &value.at("units") : nullptr;
    for (const auto& [key, v] : value.items()) {
      if (key == "units" && (path.empty() || own != nullptr)) continue;
      const nlohmann::json* u = units != nullptr && units->is_object() && units->contains(key) ? &units->at(key)
                                : own != nullptr && own->contains(key)                        ? &own->at(key)
                                                                                              : nullptr;
      collect_unitless_results(v, u, path + "/" + key, out);
    }
  }
}
/// The results paths of `sidecar` (a command's JSON sidecar) holding a number without a unit.
std::vector<std::string> unitless_results(const std::filesystem::path& sidecar) {
  const auto results = nlohmann::json::parse(slurp(sidecar)).at("results");
  std::vector<std::string> out;
  if (!results.contains("units")) return {"(no units)"};
  collect_unitless_results(results, &results.at("units"), "", out);
  return out;
}
}  // namespace

TEST(SummaryUnits, EveryResultOfTappingHbSweepFmModesAndDemoHasItsUnit) {
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"tapping hb --units physical --points 400 --output r.csv", "r.csv.json"},
      {"tapping hb --law attractive --approach-adhesion 1 --departure-adhesion 2 --separation 6 --points 400 "
       "--output r.csv",
       "r.csv.json"},
      // jumps, folds and grazing present (their records checked), then a mode without them (their units listed)
      {"tapping sweep --units physical --law attractive --adhesion-approach 40 --adhesion-departure 80 "
       "--separation-min 12 --separation-max 26 --points 30 --mode both --quiet --output r.csv",
       "r.csv.json"},
      {"tapping sweep --points 10 --directions approach --hb-beside off --quiet --output r.csv", "r.csv.json"},
      {"tapping sweep --parameter drive_frequency --parameter-min 0.98 --parameter-max 1.04 --points 12 --mode both "
       "--law attractive --approach-adhesion 1 --departure-adhesion 2 --separation 14 --quiet --output r.csv",
       "r.csv.json"},
      {"tapping fm --units physical --quiet --output r.csv", "r.csv.json"},
      {"tapping modes --units physical --modes 3 --points 2 --settle-periods 20 --lockin-periods 5 --quiet --output r.csv",
       "r.csv.json"},
      {"demo --units physical --points 20 --output-dir d", "d/demo_hb.csv.json"},
      {"demo --points 20 --output-dir d", "d/demo_sweep.csv.json"}};
  std::size_t run = 0;  // under the sanitizers every other run (cli_run.hpp)
  for (const auto& [args, sidecar] : runs) {
    if (afmkit_test::left_out_under_sanitizers(run++, 2)) continue;
    TempDir dir;
    const auto r = run_cli(args, dir);
    ASSERT_EQ(r.status, 0) << args << "\n" << r.err;
    EXPECT_EQ(unitless_results(dir.path / sidecar), std::vector<std::string>{}) << args;
  }
}

TEST(SummaryUnits, EveryResultOfTheControlCommandsHasItsUnit) {
  // on main the flags (complete, box_is_proven, stable_at_reference, diverged, converged, ...) and the chart's counts
  // had no unit, the
  // margin map no units at all; the settings and tau0 records carry their own
  std::size_t run = 0;  // under the sanitizers every other run (cli_run.hpp)
  for (const char* args :
       {"control roots --harmonics 3 --output r.csv", "control roots --controller infinite --output r.csv",
        "control margin --harmonics 3 --output r.csv", "control margin --controller single --output r.csv",
        "control margin --compare --harmonics 3 --output r.csv",
        "control chart --harmonics 3 --x-points 8 --y-points 8 --delays 0.1,0.2 --output r.csv",
        "control chart --harmonics 3 --quantity margin --x-points 6 --y-points 6 --output r.csv",
        "control simulate --harmonics 3 --signal 0.2,1.2,0.5,-0.8,-0.4 --signal-sample-rate 250 "
        "--rotation-frequency-hz 50 --periods 10 --output r.csv",
        "control tune --harmonics 3 --coarse-points 4 --max-evaluations 6 --gain-points 2 --delay-points 2 "
        "--output r.csv",
        "control tf --harmonics 3 --points 20 --output r.csv",
        "control tf --controller single --rotation-frequency 50 --points 20 --output r.csv"}) {
    if (afmkit_test::left_out_under_sanitizers(run++, 2)) continue;
    TempDir dir;
    const auto r = run_cli(args, dir);
    ASSERT_EQ(r.status, 0) << args << "\n" << r.err;
    EXPECT_EQ(unitless_results(dir.path / "r.csv.json"), std::vector<std::string>{}) << args;
  }
}

TEST(SummaryUnits, EveryResultOfControlExportHasItsUnit) {
  // on main damped_pairs, undamped_pairs and real_modes had no unit (the results are printed with --json)
  TempDir dir;
  const auto r = run_cli("control export --harmonics 3 --rotation-frequency 314.159265 --sample-rate 10000 "
                         "--test-vectors 4 --json --output f.h",
                         dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto results = nlohmann::json::parse(r.out);
  std::vector<std::string> unitless;
  collect_unitless_results(results, &results.at("units"), "", unitless);
  EXPECT_EQ(unitless, std::vector<std::string>{}) << r.out;
}

TEST(SummaryUnits, EveryResultOfSpectroscopyPrepareHasItsUnit) {
  const std::string file =
      std::string(AFMKIT_SOURCE_DIR) + "/../shared/data/force-curves/jpk_spot3-0192.jpk-force";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "no measured curve at " << file;
  TempDir dir;
  // a DMT fit: the contact record holds its fit
  const auto r = run_cli("spectroscopy prepare '" + file + "' --contact-method dmt --tip-radius 20 --output p.csv", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(unitless_results(dir.path / "p.csv.json"), std::vector<std::string>{});
  const auto results = nlohmann::json::parse(slurp(dir.path / "p.csv.json")).at("results");
  ASSERT_TRUE(results.at("curves").at(0).at("contact").contains("fit"));
  EXPECT_EQ(results.at("units").at("curves").at("contact").at("fit").at("contact_point"), "nm");
}

TEST(SummaryUnits, TheSweepArclengthIsALengthInTheSeparationsUnit) {
  // the continuation's arclength is the length of the branch in (x(0), ẋ(0)/ω, l): a length, in the unit of the
  // separation (nm or L), that grows along the branch at least by the change of l between two points
  std::size_t run = 0;  // under the sanitizers every other run (cli_run.hpp)
  for (const char* units : {"physical", "normalised"}) {
    if (afmkit_test::left_out_under_sanitizers(run++, 2)) continue;
    TempDir dir;
    const std::string args = std::string("tapping sweep --units ") + units +
                             " --separation-min 12 --separation-max 26 --mode continuation --quiet --output s.csv";
    const auto r = run_cli(args, dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto sidecar = nlohmann::json::parse(slurp(dir.path / "s.csv.json"));
    std::map<std::string, std::string> unit;
    std::vector<std::string> names;
    for (const auto& c : sidecar.at("columns")) {
      unit[c.at("name")] = c.at("unit");
      names.push_back(c.at("name"));
    }
    EXPECT_EQ(unit.at("arclength"), unit.at("separation")) << units;
    EXPECT_EQ(unit.at("separation"), std::string(units) == "physical" ? "nm" : "L");
    const auto column = [&](const std::string& name) {
      return static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
    };
    std::istringstream csv(slurp(dir.path / "s.csv"));
    std::string line;
    std::getline(csv, line);  // the header
    std::vector<std::pair<double, double>> points;  // (separation, arclength)
    while (std::getline(csv, line)) {
      std::vector<std::string> cells;
      std::stringstream cellstream(line);
      for (std::string cell; std::getline(cellstream, cell, ',');) cells.push_back(cell);
      if (cells.at(column("direction")) != "continuation") continue;
      points.emplace_back(std::stod(cells.at(column("separation"))), std::stod(cells.at(column("arclength"))));
    }
    ASSERT_GT(points.size(), 10u) << units;
    for (std::size_t i = 1; i < points.size(); ++i)
      EXPECT_GE(points[i].second - points[i - 1].second,
                std::abs(points[i].first - points[i - 1].first) * (1.0 - 1e-9))
          << units << " point " << i;
  }
}

TEST(SummaryUnits, TheSweepHelpGivesTheArclengthStepAsALengthOfTheSeparation) {
  // --help said "scaled arclength" for max_arclength_step: the step is of the arclength, a length in the unit of the
  // separation (the test above), and --help says so with the separation's unit
  std::map<std::string, std::string> description;
  for (const auto& o : afmkit_test::options_of("tapping sweep")) description[o.name] = o.description;
  const auto unit_of = [&](const std::string& name) {
    const std::string& d = description.at(name);
    const std::size_t at = d.find("[unit: ");
    return at == std::string::npos ? std::string() : d.substr(at + 7, d.find(';', at) - at - 7);
  };
  const std::string& step = description.at("max-arclength-step");
  EXPECT_EQ(step.find("scaled"), std::string::npos) << step;
  EXPECT_NE(step.find("arclength, a length in the separation's unit"), std::string::npos) << step;
  EXPECT_FALSE(unit_of("max-arclength-step").empty()) << step;
  EXPECT_EQ(unit_of("max-arclength-step"), unit_of("separation-min"));
}

TEST(SummaryUnits, EveryResultOfSpectroscopyFitHasItsUnit) {
  // on main the estimates' units were listed beside `estimates` (units.hamaker: one string for value, errors and the
  // `identifiable` flag, under no key of the results) and noise_estimated's flags had none: AM with and without a
  // phase column, FM (a curve far from the surface: distance_offset not identifiable, its flag false)
  TempDir dir;
  std::ofstream(dir.path / "am.csv") << "distance (nm), amplitude (nm), phase (deg)\n40, 10, 90.1\n38, 10, 90.3\n"
                                        "36, 10, 89.9\n34, 10, 90.2\n";
  std::ofstream(dir.path / "am_np.csv") << "distance (nm), amplitude (nm)\n40, 10\n38, 9.9\n36, 9.7\n34, 9.5\n"
                                           "32, 9.2\n";
  std::ofstream(dir.path / "fm.csv") << "distance (nm), frequency shift (Hz)\n10.0, 0.5846\n9.9177, 0.7734\n"
                                        "9.8354, 0.8\n9.7531, 0.83\n9.6708, 0.86\n";
  std::size_t run = 0;  // under the sanitizers every other run (cli_run.hpp)
  for (const char* args :
       {"spectroscopy fit am.csv --spring-constant 40 --resonance-frequency 300 --quality-factor 100 "
        "--free-amplitude 10 --parameters phase_offset --output r.csv",
        "spectroscopy fit am_np.csv --spring-constant 40 --resonance-frequency 300 --quality-factor 100 "
        "--free-amplitude 10 --parameters distance_offset --output r.csv",
        "spectroscopy fit fm.csv --spring-constant 40 --resonance-frequency 300 --quality-factor 400 --amplitude 5 "
        "--parameters distance_offset,frequency_shift_offset --output r.csv"}) {
    if (afmkit_test::left_out_under_sanitizers(run++, 2)) continue;
    const auto r = run_cli(args, dir);
    ASSERT_EQ(r.status, 0) << args << "\n" << r.err;
    EXPECT_EQ(unitless_results(dir.path / "r.csv.json"), std::vector<std::string>{}) << args;
    const auto results = nlohmann::json::parse(slurp(dir.path / "r.csv.json")).at("results");
    ASSERT_FALSE(results.at("estimates").empty()) << args;
    for (const auto& [name, estimate] : results.at("estimates").items()) {
      const auto& unit = results.at("units").at("estimates").at(name);
      EXPECT_EQ(unit.at("identifiable"), "boolean (0/1)") << name;
      EXPECT_EQ(unit.at("value"), unit.at("standard_error")) << name;
      EXPECT_EQ(unit.at("value"), name == "distance_offset" ? "nm" : name == "phase_offset" ? "deg"
                                  : name == "hamaker"        ? "J"
                                                             : "Hz")
          << name;
    }
  }
}

TEST(SummaryUnits, EveryResultOfImpactAndSpectroscopyReconstructHasItsUnit) {
  // impact: on main its units were by dimension (time, gap, energy, ...), naming no key of the results; each result
  // (the bodies' after-impact records, the contact flag) has its own now. reconstruct was already complete: kept so
  // while its results are built on UnitTagged (FM here; the AM round trip takes seconds)
  const std::string configs = std::string(AFMKIT_SOURCE_DIR) + "/examples/configs/";
  std::size_t run = 0;  // under the sanitizers every other run (cli_run.hpp)
  for (const std::string& args :
       {std::string("impact --output r.csv --points 20"),
        std::string("impact --law dmt --hamaker 1e-19 --mass1 1e-11 --mass2 1 --velocity 1e6 --gap 2 --points 20 "
                    "--output r.csv"),
        "spectroscopy reconstruct --input '" + configs + "fm_curve_dmt.csv' --method sader_jarvis --tail zero "
        "--spring-constant 40 --resonance-frequency 300 --amplitude 2 --law-output '' --output r.csv"}) {
    if (afmkit_test::left_out_under_sanitizers(run++, 2)) continue;
    TempDir dir;
    const auto r = run_cli(args, dir);
    ASSERT_EQ(r.status, 0) << args << "\n" << r.err;
    EXPECT_EQ(unitless_results(dir.path / "r.csv.json"), std::vector<std::string>{}) << args;
  }
  // the linear law without adhesion writes restitution_impulsive_limit; the units name it (dimensionless) also when
  // a law does not
  TempDir dir;
  ASSERT_EQ(run_cli("impact --points 20 --output r.csv", dir).status, 0);
  const auto results = nlohmann::json::parse(slurp(dir.path / "r.csv.json")).at("results");
  ASSERT_TRUE(results.contains("restitution_impulsive_limit"));
  EXPECT_EQ(results.at("units").at("restitution_impulsive_limit"), "dimensionless");
  EXPECT_EQ(results.at("units").at("body1_after").at("velocity"), "nm/s");
}

TEST(SummaryUnits, EveryResultOfScanHasItsUnit) {
  // on main the flags (saturates_with_control, saturates_without_control, scan_area_gain_is_lower_bound; recorded:
  // uses_index_pulse) had no unit; the error budget's units, inside the record, are under units.error_budget now
  const std::string recorded = std::string(AFMKIT_SOURCE_DIR) + "/examples/recorded/spiral.csv";
  std::size_t run = 0;  // under the sanitizers every other run (cli_run.hpp)
  for (const std::string& args :
       {std::string("scan --sample-rate 20000 --radial-speed 1e-3 --image-resolution 128 --sample-resolution 512 "
                    "--image-output '' --output r.csv"),
        std::string("scan --sample-rate 20000 --radial-speed 1e-3 --image-resolution 128 --sample-resolution 512 "
                    "--control off --image-output '' --output r.csv"),
        "scan --recorded '" + recorded + "' --image-resolution 64 --image-output '' --output r.csv"}) {
    if (afmkit_test::left_out_under_sanitizers(run++, 2)) continue;
    TempDir dir;
    const auto r = run_cli(args, dir);
    ASSERT_EQ(r.status, 0) << args << "\n" << r.err;
    EXPECT_EQ(unitless_results(dir.path / "r.csv.json"), std::vector<std::string>{}) << args;
  }
}

TEST(SummaryUnits, EveryResultOfTappingImageHasItsUnit) {
  // on main the branches at the set-point had no unit for their `branch` (an index of the orbit map's branches); the
  // results are built on UnitTagged now, and the lists' units are there also when a list is empty (no sweep)
  std::size_t run = 0;  // under the sanitizers every other run (cli_run.hpp)
  for (const char* args : {"tapping image --pixels 8 --lines 4 --map-points 60 --setpoint-sweep 0.7,0.9 --quiet "
                           "--image-output '' --output r.csv",
                           "tapping image --pixels 8 --lines 4 --map-points 60 --quiet --image-output '' "
                           "--output r.csv"}) {
    if (afmkit_test::left_out_under_sanitizers(run++, 2)) continue;
    TempDir dir;
    const auto r = run_cli(args, dir);
    ASSERT_EQ(r.status, 0) << args << "\n" << r.err;
    EXPECT_EQ(unitless_results(dir.path / "r.csv.json"), std::vector<std::string>{}) << args;
    const auto results = nlohmann::json::parse(slurp(dir.path / "r.csv.json")).at("results");
    ASSERT_FALSE(results.at("branches_at_setpoint").empty()) << args;
    EXPECT_EQ(results.at("units").at("branches_at_setpoint").at("branch"), "count");
    EXPECT_EQ(results.at("units").at("setpoint_sweep").at("engaged_separation"), "m");
  }
}
