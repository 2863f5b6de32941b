// Honest answers on the command line (issue 24 §2): an internal failure is never reported as the user's error, an
// empty or degenerate answer is never a silent success, and the recorded parameters are the ones the run used.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../cli/cli_run.hpp"
#include "afmkit/impact/force_law.hpp"

using afmkit_test::run_cli;
using afmkit_test::slurp;
using afmkit_test::TempDir;

namespace {

// A SiN-like measured curve where the tip sticks: DMT approach (E* = 2 GPa, R = 10 nm, A_H = 1e-19 J,
// a0 = 0.165 nm: pull-off ≈ 6 nN) and a retract branch with an extra neck adhesion of 5 nN — both far above the
// drive force k·A0/Q = 1.1841 N/m · 20 nm / 139.13 ≈ 0.17 nN of the cantilever below.
constexpr double kA0 = 0.165;  // nm: the contact gap of the curve (its lowest approach force)
double dmt_nN(double d_nm) {
  const double ah = 1e-19, r = 10e-9, a0 = kA0 * 1e-9, e = 2e9, d = d_nm * 1e-9;
  const double f = d >= a0 ? -ah * r / (6 * d * d) : -ah * r / (6 * a0 * a0) + 4.0 / 3.0 * e * std::sqrt(r) * std::pow(a0 - d, 1.5);
  return f * 1e9;
}
void write_sticky_curve(const TempDir& dir, const std::string& name) {
  std::ostringstream s;
  s << "# SiN-like curve: DMT approach, retract with an extra 5 nN neck adhesion\n"
    << "distance (nm),approach (nN),retract (nN)\n";
  for (int i = 0; i < 321; ++i) {
    const double d = -2.0 + 32.0 * i / 320.0;
    const double neck = 5.0 * std::exp(-std::max(d - kA0, 0.0) / 0.5);
    s << fmt::format("{:.6f},{:.9g},{:.9g}\n", d, dmt_nN(d), dmt_nN(d) - neck);
  }
  dir.write(name, s.str());
}
const std::string kSticky =
    "--units physical --law table --force-curve F.csv --spring-constant 1.1841 --resonance-frequency 23.251 "
    "--quality-factor 139.13 --free-amplitude 20";

/// The CSV `path` as rows of cells (header first).
std::vector<std::vector<std::string>> read_csv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}
std::size_t column(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return i;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

/// An exit that is not the user's fault: never 2, never "invalid parameter" / "input error".
void expect_not_blamed_on_input(const afmkit_test::RunResult& r, const std::string& what) {
  EXPECT_NE(r.status, 2) << what << "\n" << r.err;
  EXPECT_EQ(r.err.find("invalid parameter"), std::string::npos) << what << "\n" << r.err;
  EXPECT_EQ(r.err.find("input error"), std::string::npos) << what << "\n" << r.err;
  EXPECT_EQ(r.err.find("= nan"), std::string::npos) << what << "\n" << r.err;
}

}  // namespace

// ------------------------------------------------------------------ 1. internal failures are not input errors
TEST(HonestyInternalFailure, OrbitOnAStickyMeasuredLawIsNeverReportedAsABadSeparation) {
  TempDir dir;
  write_sticky_curve(dir, "F.csv");
  const auto r = run_cli("tapping orbit " + kSticky + " --separation 5 --output o.csv", dir);
  expect_not_blamed_on_input(r, "tapping orbit");
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;
  if (r.status == 1) {  // either no answer (status in the written results) or a numerical failure naming the step
    EXPECT_TRUE(r.err.find("no answer") != std::string::npos || r.err.find("numerical failure") != std::string::npos)
        << r.err;
  }
}

TEST(HonestyInternalFailure, EveryTappingCommandOnTheStickyLawBlamesNoInput) {
  TempDir dir;
  write_sticky_curve(dir, "F.csv");
  for (const std::string& cmd :
       {std::string("tapping hb --separation 20 --points 200"),
        std::string("tapping sweep --separation-min 0 --separation-max 24 --points 9 --quiet --mode instrument"),
        std::string("tapping sweep --separation-min 3 --separation-max 24 --quiet --mode continuation")}) {
    const auto r = run_cli(cmd + " " + kSticky + " --output out.csv", dir);
    expect_not_blamed_on_input(r, cmd);
  }
  // tapping fm: the loops set the drive, so the sticky model without its free amplitude
  const std::string fm_model = kSticky.substr(0, kSticky.find(" --free-amplitude"));
  const auto r = run_cli("tapping fm --amplitude 20 --separation-min 0 --separation-max 24 --points 9 --quiet " +
                             fm_model + " --output out.csv",
                         dir);
  expect_not_blamed_on_input(r, "tapping fm");
}

// ------------------------------------------------------------------ 2. no silent empty answers
TEST(HonestyStatus, HbSaysWhatItFoundInSummarySidecarAndExitStatus) {
  TempDir dir;
  write_sticky_curve(dir, "F.csv");
  const auto r = run_cli("tapping hb " + kSticky + " --separation 20 --points 200 --output hb.csv", dir);
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;
  const auto results = nlohmann::json::parse(slurp(dir.path / "hb.csv.json")).at("results");
  const auto rows = read_csv(dir.file("hb.csv"));
  const std::string status = results.at("status");
  if (rows.size() <= 1) {  // header only: no curve is no answer
    EXPECT_EQ(status, results.at("solutions_at_separation").empty() ? "no_solution" : "empty_curve");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("no answer: status " + status), std::string::npos) << r.err;
    EXPECT_FALSE(results.at("note").get<std::string>().empty());
  } else {
    EXPECT_EQ(status, "ok");
    EXPECT_EQ(r.status, 0) << r.err;
  }
}

TEST(HonestyStatus, AnEmptyHbCurveIsNoAnswer) {
  // an adhesion far above the drive (F_a = 5, F_b = 8 against Γ = 0.2, normalised): no harmonic-balance solution
  // with contact anywhere in q ∈ [-5, 0.9] (and q < 1 excludes the free branch), so the curve is empty
  TempDir dir;
  const std::string args = "tapping hb --law attractive --approach-adhesion 5 --departure-adhesion 8 --q-min -5 "
                           "--q-max 0.9 --points 50";
  const auto r = run_cli(args + " --output hb.csv", dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("no answer: status "), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("fold(s)"), std::string::npos) << r.out;  // the summary and the files are still written
  EXPECT_EQ(read_csv(dir.file("hb.csv")).size(), 1u);             // header only
  const auto results = nlohmann::json::parse(slurp(dir.path / "hb.csv.json")).at("results");
  // empty curve; whether a solution exists at the separation decides between the two statuses
  EXPECT_EQ(results.at("status"), results.at("solutions_at_separation").empty() ? "no_solution" : "empty_curve");
  EXPECT_EQ(results.at("rows"), 0);
  EXPECT_FALSE(results.at("note").get<std::string>().empty());
  // --json: the same status in the printed document, still exit 1
  const auto j = run_cli(args + " --output '' --json", dir);
  EXPECT_EQ(j.status, 1);
  EXPECT_EQ(nlohmann::json::parse(j.out).at("status"), results.at("status"));
  // a curve with rows is an answer
  const auto ok = run_cli("tapping hb --points 50 --output '' --json", dir);
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_EQ(nlohmann::json::parse(ok.out).at("status"), "ok");
}

TEST(HonestyStatus, SweepMarksRowsOfATrappedTipAndCountsThem) {
  TempDir dir;
  write_sticky_curve(dir, "F.csv");
  const auto r = run_cli("tapping sweep " + kSticky +
                             " --separation-min 0 --separation-max 24 --points 9 --mode instrument --quiet "
                             "--output s.csv",
                         dir);
  expect_not_blamed_on_input(r, "tapping sweep");
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;
  const auto rows = read_csv(dir.file("s.csv"));
  ASSERT_GT(rows.size(), 1u);
  const auto& h = rows[0];
  const std::size_t amp = column(h, "amplitude"), offset = column(h, "offset"), gap = column(h, "min_gap"),
                    trapped = column(h, "trapped");
  long n_trapped = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double a = std::stod(rows[i][amp]), g = std::stod(rows[i][gap]);
    const bool t = rows[i][trapped] == "1";
    n_trapped += t ? 1 : 0;
    // independent of the flag's definition: a trapped tip's highest gap (min gap + peak-to-peak motion, at most
    // 4 B for a near-harmonic motion) stays below the curve's contact gap; a tapping tip leaves it
    if (t) {
      EXPECT_LT(g + 4.0 * a, kA0 + 1e-6) << "row " << i;
    }
    // a motion below a picometre at an amplitude-20-nm drive is the tip stuck to the sample: it must be marked
    if (a < 1e-3 && g < kA0) {
      EXPECT_TRUE(t) << "row " << i << ": amplitude " << a << " nm, offset " << rows[i][offset];
    }
  }
  const auto results = nlohmann::json::parse(slurp(dir.path / "s.csv.json")).at("results");
  EXPECT_EQ(results.at("trapped_rows").get<long>(), n_trapped);
  EXPECT_GT(n_trapped, 0) << "the adhesion (several nN) traps the tip once it touches: 0.17 nN of drive cannot pull off";
  const bool all = n_trapped == static_cast<long>(rows.size() - 1);
  EXPECT_EQ(results.at("status"), all ? "tip_trapped" : "ok");
  EXPECT_EQ(r.status, all ? 1 : 0) << r.err;
  EXPECT_NE(r.out.find("trapped"), std::string::npos) << r.out;  // the summary says so
}

TEST(HonestyStatus, OrbitStatusMatchesItsOrbits) {
  TempDir dir;
  write_sticky_curve(dir, "F.csv");
  const auto r = run_cli("tapping orbit " + kSticky + " --separation 0 --output o.csv", dir);
  expect_not_blamed_on_input(r, "tapping orbit");
  const auto results = nlohmann::json::parse(slurp(dir.path / "o.csv.json")).at("results");
  const auto& orbits = results.at("orbits");
  bool tapping = false;
  for (const auto& o : orbits) tapping = tapping || !o.at("trapped").get<bool>();
  const std::string status = results.at("status");
  EXPECT_EQ(status, orbits.empty() ? "no_orbit" : tapping ? "ok" : "tip_trapped");
  EXPECT_EQ(r.status, status == "ok" ? 0 : 1) << r.err;
  if (status != "ok") {
    EXPECT_NE(r.err.find("no answer: status " + status), std::string::npos) << r.err;
  }
}

// `tapping grid`'s Zarr store said nothing of trapped tips or missing orbits, which the CSV outputs of `orbit` and
// `sweep` report (issue 24): it now holds count(amplitude | trapped) per separation, the counts of separations
// without a tapping orbit, a status and a note, and exits 1 when no separation has one.
TEST(HonestyStatus, GridStoreCountsTrappedSeparationsAsTheOrbitCommandJudgesThem) {
  TempDir dir;
  write_sticky_curve(dir, "F.csv");
  const auto g = run_cli("tapping grid " + kSticky + " --separation-min -0.5 --separation-max 0 --points 2 "
                         "--store g.zarr --quiet", dir);
  expect_not_blamed_on_input(g, "tapping grid");
  const auto attrs = nlohmann::json::parse(slurp(dir.path / "g.zarr" / ".zattrs"));
  auto read_f8 = [&](const std::string& name) {  // an uncompressed chunk of 2 little-endian doubles
    const std::string raw = slurp(dir.path / "g.zarr" / name / "0");
    std::vector<double> v(raw.size() / sizeof(double));
    std::memcpy(v.data(), raw.data(), v.size() * sizeof(double));
    return v;
  };
  const std::vector<double> trapped = read_f8("count_amplitude_trapped"), all = read_f8("count_amplitude");
  ASSERT_EQ(trapped.size(), 2u);
  // independently: `tapping orbit` at each separation of the grid, its status and its orbits' trapped column
  long trapped_separations = 0, no_orbit_separations = 0;
  for (int i = 0; i < 2; ++i) {
    const std::string l = i == 0 ? "-0.5" : "0";
    const auto o = run_cli("tapping orbit " + kSticky + " --separation " + l + " --output o.csv", dir);
    const auto results = nlohmann::json::parse(slurp(dir.path / "o.csv.json")).at("results");
    long n_trapped = 0;
    for (const auto& orbit : results.at("orbits")) n_trapped += orbit.at("trapped").get<bool>() ? 1 : 0;
    EXPECT_EQ(all[i], static_cast<double>(results.at("orbits").size())) << "separation " << l;
    EXPECT_EQ(trapped[i], static_cast<double>(n_trapped)) << "separation " << l;
    trapped_separations += results.at("status") == "tip_trapped" ? 1 : 0;
    no_orbit_separations += results.at("status") == "no_orbit" ? 1 : 0;
  }
  EXPECT_GT(trapped_separations, 0) << "the tip sticks at and below contact";
  EXPECT_EQ(attrs.at("trapped_separations").get<long>(), trapped_separations);
  EXPECT_EQ(attrs.at("no_orbit_separations").get<long>(), no_orbit_separations);
  const bool none = trapped_separations + no_orbit_separations == 2;
  EXPECT_EQ(attrs.at("status"), !none ? "ok" : no_orbit_separations == 2 ? "no_orbit" : "tip_trapped");
  EXPECT_EQ(g.status, none ? 1 : 0) << g.err;
  EXPECT_NE(g.out.find("trapped"), std::string::npos) << g.out;  // the summary says so
}

// ------------------------------------------------------------------ 3. recorded parameters are those used
namespace {
/// The sidecar's parameters `keys` as a TOML file (numbers, strings, booleans, arrays), for a replay with --config.
/// (Only the keys of the law used: keys of other laws are recorded too but refused when given — a separate issue.)
std::string as_toml(const nlohmann::json& params, const std::vector<std::string>& keys) {
  std::string t;
  for (const auto& [k, v] : params.items()) {
    if (std::find(keys.begin(), keys.end(), k) == keys.end()) continue;
    if (v.is_string()) t += fmt::format("{} = {}\n", k, v.dump());
    else if (v.is_boolean()) t += fmt::format("{} = {}\n", k, v.get<bool>() ? "true" : "false");
    else if (v.is_number_integer()) t += fmt::format("{} = {}\n", k, v.get<long>());
    else if (v.is_number()) t += fmt::format("{} = {:.17g}\n", k, v.get<double>());
    else if (v.is_array()) {
      std::string items;
      for (const auto& x : v) items += fmt::format("{}{:.17g}", items.empty() ? "" : ", ", x.get<double>());
      t += fmt::format("{} = [{}]\n", k, items);
    }
  }
  return t;
}
}  // namespace

TEST(HonestyRecords, FollowedLawKeysRecordTheValueUsedInEveryLawCommand) {
  const std::vector<std::string> commands = {
      "impact --law dmt --mass1 1e-11 --mass2 1 --velocity 1e6 --gap 2",
      "tapping hb --units physical --law dmt --points 50",
      "tapping orbit --units physical --law dmt --free-amplitude 10 --separation 8",
      "tapping sweep --units physical --law dmt --free-amplitude 10 --separation-min 7 --separation-max 9 --points 3 "
      "--mode instrument --quiet",
      "tapping fm --units physical --law dmt --separation-min 7 --separation-max 9 --points 3 --quiet"};
  for (const std::string& cmd : commands) {
    SCOPED_TRACE(cmd);
    TempDir dir;
    const auto r = run_cli(cmd + " --hamaker 1e-19 --effective-modulus 3 --output run.csv", dir);
    ASSERT_EQ(r.status, 0) << r.err;
    auto params = nlohmann::json::parse(slurp(dir.path / "run.csv.json")).at("parameters");
    EXPECT_EQ(params.at("departure_hamaker").get<double>(), 1e-19);  // not the declared 6.4e-20
    EXPECT_EQ(params.at("departure_modulus").get<double>(), 3.0);
    EXPECT_FALSE(params.contains("restitution"));  // an alternative not given: not used, not recorded
    // independently: the DMT law from the recorded values is the law of the run (A_H while departing)
    const auto num = [&](const char* key) { return params.at(key).get<double>(); };
    const afmkit::impact::DmtLaw recorded(num("effective_modulus"), num("departure_modulus"), num("tip_radius"),
                                          num("hamaker"), num("departure_hamaker"), num("intermolecular_distance"));
    const afmkit::impact::DmtLaw used(3.0, 3.0, 10.0, 1e-19, 1e-19, 0.165);
    for (double d : {-0.5, 0.1, 0.3, 1.0, 4.0}) {
      EXPECT_EQ(recorded.approach(d), used.approach(d));
      EXPECT_EQ(recorded.departure(d), used.departure(d));
    }
    // a replay of the record runs (no "departure_hamaker must be >= hamaker") and records the same
    params.erase("output");
    dir.write("replay.toml", as_toml(params, {"law", "effective_modulus", "departure_modulus", "tip_radius", "hamaker",
                                              "departure_hamaker", "intermolecular_distance"}));
    const auto again = run_cli(cmd + " --config replay.toml --output again.csv", dir);
    ASSERT_EQ(again.status, 0) << again.err;
    auto params_again = nlohmann::json::parse(slurp(dir.path / "again.csv.json")).at("parameters");
    params_again.erase("output");
    EXPECT_EQ(params_again, params);
  }
}

TEST(HonestyRecords, ImpactRecordsVelocityOrV1V2AndRestitutionOnlyAsUsed) {
  TempDir dir;
  auto r = run_cli("impact --v1 1 --v2 -2 --output a.csv", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  auto p = nlohmann::json::parse(slurp(dir.path / "a.csv.json")).at("parameters");
  EXPECT_FALSE(p.contains("velocity"));
  EXPECT_EQ(p.at("v1").get<double>(), 1.0);
  EXPECT_EQ(p.at("v2").get<double>(), -2.0);
  r = run_cli("impact --restitution 0.5 --output b.csv", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  p = nlohmann::json::parse(slurp(dir.path / "b.csv.json")).at("parameters");
  EXPECT_EQ(p.at("restitution").get<double>(), 0.5);
  EXPECT_FALSE(p.contains("departure_stiffness"));  // K_b = e² K_a was used, not the declared 8 N/m
  EXPECT_FALSE(p.contains("v1"));
  EXPECT_EQ(p.at("velocity").get<double>(), 1.0);
  p.erase("output");
  dir.write("replay.toml", as_toml(p, {"law", "approach_stiffness", "restitution", "departure_stiffness", "velocity",
                                       "mass1", "mass2", "gap"}));
  r = run_cli("impact --config replay.toml --output c.csv", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(dir.path / "c.csv.json")).at("results").at("restitution"),
            nlohmann::json::parse(slurp(dir.path / "b.csv.json")).at("results").at("restitution"));
}

TEST(HonestyRecords, ComputedDefaultsAreRecordedAsComputed) {
  TempDir dir;
  // control roots: the automatic box edge and the proven half-height it searched
  auto r = run_cli("control roots --harmonics 3 --output r.csv", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  auto side = nlohmann::json::parse(slurp(dir.path / "r.csv.json"));
  EXPECT_EQ(side["parameters"]["min_real"], side["results"]["box"]["real_min"]);
  EXPECT_EQ(side["parameters"]["max_imag"], side["results"]["box"]["imag_max"]);
  // control gain / model_delay follow plant_rate / delay
  r = run_cli("control tf --controller smith --harmonics 3 --plant-rate 7 --points 20 --output t.csv", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  side = nlohmann::json::parse(slurp(dir.path / "t.csv.json"));
  EXPECT_EQ(side["parameters"]["gain"].get<double>(), 7.0);
  EXPECT_EQ(side["parameters"]["model_rate"].get<double>(), 7.0);
  // a bank without the Smith predictor: its keys did not apply and are not recorded
  r = run_cli("control tf --harmonics 3 --plant-rate 7 --points 20 --output t.csv", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  side = nlohmann::json::parse(slurp(dir.path / "t.csv.json"));
  EXPECT_FALSE(side["parameters"].contains("model_rate"));
  EXPECT_FALSE(side["parameters"].contains("a"));
  // control margin of a Smith predictor: the reference delay is the model delay
  r = run_cli("control margin --controller smith --harmonics 3 --model-delay 0.05 --output m.csv", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  side = nlohmann::json::parse(slurp(dir.path / "m.csv.json"));
  EXPECT_EQ(side["parameters"]["reference_delay"].get<double>(), 0.05);
}

TEST(HonestyRecords, RestitutionInPhysicalTappingUnitsIsUsedAndRecordedInsteadOfTheStiffness) {
  // was refused: "give either restitution or departure_stiffness, not both" although only restitution was given
  TempDir dir;
  const std::string base = "tapping orbit --units physical --law hysteresis --separation 18 --quality-factor 50";
  const auto r = run_cli(base + " --restitution 0.5 --output e.csv", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto side = nlohmann::json::parse(slurp(dir.path / "e.csv.json"));
  const auto& params = side.at("parameters");
  EXPECT_EQ(params.at("restitution").get<double>(), 0.5);
  EXPECT_FALSE(params.contains("sample_stiffness_departure"));  // the run used e² K_a, not the declared 320 N/m
  EXPECT_FALSE(params.contains("departure_stiffness"));
  // independently: K_b = e² K_a = 0.25 · 400 N/m given directly is the same orbit
  const auto k = run_cli(base + " --sample-stiffness-departure 100 --output k.csv", dir);
  ASSERT_EQ(k.status, 0) << k.err;
  const nlohmann::json a = side.at("results").at("orbits").at(0);
  const nlohmann::json b = nlohmann::json::parse(slurp(dir.path / "k.csv.json")).at("results").at("orbits").at(0);
  EXPECT_NEAR(a.at("amplitude").get<double>(), b.at("amplitude").get<double>(), 1e-9);
  EXPECT_NEAR(a.at("contact_dissipation").get<double>(), b.at("contact_dissipation").get<double>(),
              1e-9 * std::abs(b.at("drive_work").get<double>()));
}
