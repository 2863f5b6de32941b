// Every parameter is declared once (issue 26, "typed requests declared once"): over every command of the program
// (command_specs(), the registry the command line and the Python module share), a key is declared at one place —
// one line of a shared declaration function (add_tapping_model_params, add_output_params, …) or of a library
// struct's describe() (afmkit/core/describe.hpp, through apps/described_params.hpp) — so that its default, range,
// unit and help cannot drift apart between commands. io::ParamSet records where each key is declared
// (Description::declared_at: the declaring call's file and line).
//
// The rule, precisely: a key declared at two or more places (over all commands, or twice within one command) fails,
// unless it is listed below as a name that several commands use for genuinely different parameters (another
// quantity, unit or meaning: each entry says which), or as a known duplicate still to be merged (each entry: the
// places, and why it is not merged yet). Both lists only shrink: an entry whose key is no longer declared at two
// places fails too, so that it is removed.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <vector>

#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "afmkit/core/units.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/table.hpp"
#include "cli_run.hpp"
#include "command.hpp"
#include "described_params.hpp"
#include "unit_tagged.hpp"

namespace {

// key -> place ("file:line", shortened to the repository) -> the commands declaring it there.
using DeclaredOnceSites = std::map<std::string, std::map<std::string, std::set<std::string>>>;

// "/…/<checkout>/apps/x.cpp:12" or "../apps/x.cpp:12" (ccache's base_dir) -> "apps/x.cpp:12": from the first
// top-level folder of the repository in the path.
std::string declared_once_short(const std::string& place) {
  std::size_t from = std::string::npos;
  for (const char* root : {"/apps/", "/include/", "/src/", "/python/", "/tests/"})
    if (const auto at = place.find(root); at != std::string::npos && (from == std::string::npos || at < from))
      from = at;
  return from == std::string::npos ? place : place.substr(from + 1);
}

DeclaredOnceSites declared_once_sites(const std::vector<afmkit::cli::CommandSpec>& specs) {
  DeclaredOnceSites sites;
  for (const auto& spec : specs) {
    afmkit::io::ParamSet p;
    spec.declare(p);
    for (const auto& d : p.describe())
      for (const std::string& place : d.declared_at) sites[d.key][declared_once_short(place)].insert(spec.path);
  }
  return sites;
}

std::string declared_once_places(const std::map<std::string, std::set<std::string>>& places) {
  std::string out;
  for (const auto& [place, commands] : places) {
    out += "\n    " + place + " (";
    bool first = true;
    for (const auto& c : commands) out += (first ? "" : ", ") + c, first = false;
    out += ")";
  }
  return out;
}

// A listed key: at how many places it is declared, and why. A listed key declared at another number of places fails
// (a new declaration of a listed key reuses one of its declarations, or the list is updated with the reason).
struct DeclaredOnceListed {
  std::size_t places;
  const char* why;
};
using DeclaredOnceList = std::map<std::string, DeclaredOnceListed>;

// Names several commands use for different parameters (key -> places, what differs).
const DeclaredOnceList kDeclaredOnceDifferentParameters = {
    {"absolute_tolerance", {2, "impact: of the impact integrator on the scaled state (dimensionless); tapping: of the "
                           "adaptive DOP853 integrator on the model state (L)"}},
    {"relative_tolerance", {2, "impact: the impact integrator's, in (0, 1e-2]; tapping: the adaptive DOP853's, "
                               "in (0, 1)"}},
    {"allow_energy_gain", {2, "the law's flag (accept a law that creates energy) vs spectroscopy prepare's (accept a "
                          "prepared table whose retract force exceeds the approach force)"}},
    {"delay", {2, "control: measurement delay in units of T; scan: actuator delay in seconds"}},
    {"sample_rate", {2, "control export: the filter's sample rate on the target; scan: the simulated detector's, "
                        "in Hz"}},
    {"file", {2, "spectroscopy fit: the measured curve CSV; study run: the study's TOML file"}},
    {"format", {2, "control export: the output format; spectroscopy prepare: the input file's format"}},
    {"input", {2, "spectroscopy prepare: an instrument file; spectroscopy reconstruct: a prepared curve CSV"}},
    {"output", {2, "a table's CSV (add_output_params) vs control export's C header"}},
    {"output_dir", {2, "demo: folder of its two tables; report: folder of the HTML report"}},
    {"plot", {2, "PNG of different figures: spectroscopy fit (data vs fit), prepare (raw and prepared curves)"}},
    {"max_evaluations", {2, "control tune: Nelder-Mead budget; spectroscopy fit: forward-model evaluations of LM"}},
    {"method", {3, "impact: solver; control simulate: time stepping; spectroscopy reconstruct: inversion formula"}},
    {"store", {2, "study run: the study's Zarr store (resumed); tapping grid: the grid's Zarr store (replaced)"}},
    {"image_output", {2, "scan: the prefix of the rotational scan's images; tapping image: the prefix of the raster "
                         "images (trace, retrace, truth), other files"}},
    {"points", {4, "the separations of tapping sweep, grid, fm, modes and demo (one declaration: "
                   "add_separation_points_param); impact: time-history samples; tapping hb: q samples of the curve; "
                   "control tf: frequencies of the grid"}},
    {"gain", {2, "the bank's gain K in two unit systems: control: in units of Omega (the rotation units of every "
                 "control rate; gain_rad_per_s its SI form), default = plant_rate; scan: in rad/s like the scan's "
                 "bandwidth, default (0) = bandwidth"}},
};

// The same parameter declared at several places, not merged yet (key -> the places and why). To merge one, declare
// it in one function the commands share (per-command defaults by set_default() or an argument) and remove it here.
const DeclaredOnceList kDeclaredOnceNotYetMerged = {};

/// The violations of the rule above in `sites` (one message each; empty: every key is declared once).
std::vector<std::string> declared_once_violations(const DeclaredOnceSites& sites, const DeclaredOnceList& different,
                                                  const DeclaredOnceList& not_yet_merged) {
  std::vector<std::string> out;
  for (const auto& [key, places] : sites) {
    if (places.size() < 2) continue;
    const DeclaredOnceListed* listed = nullptr;
    if (const auto d = different.find(key); d != different.end()) listed = &d->second;
    if (const auto m = not_yet_merged.find(key); m != not_yet_merged.end()) listed = &m->second;
    if (listed == nullptr) {
      out.push_back("key '" + key + "' is declared at " + std::to_string(places.size()) +
                    " places (declare it once, in a function or describe() the commands share):" +
                    declared_once_places(places));
    } else if (listed->places != places.size()) {
      out.push_back("key '" + key + "' is declared at " + std::to_string(places.size()) + " places, listed with " +
                    std::to_string(listed->places) + " (" + listed->why +
                    "): reuse one of its declarations, or update the list" + declared_once_places(places));
    }
  }
  for (const auto* list : {&different, &not_yet_merged})
    for (const auto& [key, listed] : *list) {
      const auto it = sites.find(key);
      if (it == sites.end() || it->second.size() < 2)
        out.push_back("key '" + key + "' is listed as declared at several places but is declared at " +
                      std::to_string(it == sites.end() ? 0 : it->second.size()) + ": remove it from the list");
    }
  return out;
}

TEST(DeclaredOnce, EveryKeyOfEveryCommandIsDeclaredAtOnePlace) {
  const auto specs = afmkit::cli::command_specs();
  ASSERT_GT(specs.size(), 15u);
  const DeclaredOnceSites sites = declared_once_sites(specs);
  ASSERT_GT(sites.size(), 100u);
  for (const std::string& v :
       declared_once_violations(sites, kDeclaredOnceDifferentParameters, kDeclaredOnceNotYetMerged))
    ADD_FAILURE() << v;
}

TEST(DeclaredOnce, TheLibraryStructsDeclareTheirKeysInTheirHeaders) {
  // the converted option structs: their keys come from describe() in the library's headers, for every command
  const DeclaredOnceSites sites = declared_once_sites(afmkit::cli::command_specs());
  for (const auto& [key, header] : std::map<std::string, std::string>{
           {"integrator", "include/afmkit/tapping/simulation.hpp"},
           {"time_budget", "include/afmkit/tapping/shooting.hpp"},
           {"shooting_tolerance", "include/afmkit/tapping/shooting.hpp"},  // spectroscopy fit's too
           {"max_transient_periods", "include/afmkit/tapping/transient.hpp"},
           {"huber", "include/afmkit/spectroscopy/fit.hpp"}}) {
    ASSERT_TRUE(sites.count(key)) << key;
    for (const auto& [place, commands] : sites.at(key))
      EXPECT_TRUE(place.substr(0, place.find(':')).ends_with(header)) << key << " declared at " << place;
  }
}

TEST(DeclaredOnce, AKeyDeclaredAtTwoPlacesIsFound) {
  // two commands declaring the same key each on its own line: the rule names both places; one shared declaration
  // function: no violation
  const auto shared = [](afmkit::io::ParamSet& p) { p.real("declared_once_q", 1.0, "shared").unit("dimensionless"); };
  const std::vector<afmkit::cli::CommandSpec> twice = {
      {"one", "", [](afmkit::io::ParamSet& p) { p.real("declared_once_q", 1.0, "here").unit("dimensionless"); }, {}},
      {"two", "", [](afmkit::io::ParamSet& p) { p.real("declared_once_q", 2.0, "there").unit("dimensionless"); }, {}}};
  const auto found = declared_once_violations(declared_once_sites(twice), {}, {});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NE(found[0].find("'declared_once_q' is declared at 2 places"), std::string::npos) << found[0];
  EXPECT_NE(found[0].find("test_declared_once.cpp"), std::string::npos) << found[0];
  const std::vector<afmkit::cli::CommandSpec> once = {{"one", "", shared, {}}, {"two", "", shared, {}}};
  EXPECT_TRUE(declared_once_violations(declared_once_sites(once), {}, {}).empty());
  // declared twice within one command (a second declaration replacing the first) counts too
  const std::vector<afmkit::cli::CommandSpec> replaced = {{"one", "", [](afmkit::io::ParamSet& p) {
                                                             p.real("declared_once_q", 1.0, "a").unit("dimensionless");
                                                             p.real("declared_once_q", 2.0, "b").unit("dimensionless");
                                                           }, {}}};
  EXPECT_EQ(declared_once_violations(declared_once_sites(replaced), {}, {}).size(), 1u);
  // a listed key that is no longer declared twice is reported, so the lists only shrink
  EXPECT_EQ(declared_once_violations(declared_once_sites(once), {{"declared_once_q", {2, "stale"}}}, {}).size(), 1u);
  // a listed key declared at one more place than listed is reported
  EXPECT_TRUE(declared_once_violations(declared_once_sites(twice), {{"declared_once_q", {2, "two"}}}, {}).empty());
  EXPECT_EQ(declared_once_violations(declared_once_sites(twice), {{"declared_once_q", {3, "three"}}}, {}).size(), 1u);
}


// Units at one edge (afmkit/core/units.hpp): a user's number is converted once on its way in (real_si, from the
// unit its parameter declares) and once on its way out (the Unit of a column or a results entry, which also names
// the unit). A conversion done twice or missed changes these values by a factor of 1e9 (or k, 2π f0).
TEST(UnitsAtOneEdge, AParameterIsReadInItsDeclaredUnitAsSi) {
  afmkit::io::ParamSet p;
  p.real("units_edge_gap", 1.0, "a gap").unit("nm");
  p.real("units_edge_f0", 300.0, "a frequency").unit("kHz");
  p.real("units_edge_k", 40.0, "a stiffness").unit("N/m");
  p.real("units_edge_q", 2.0, "a ratio").unit("units of Omega");
  EXPECT_EQ(afmkit::cli::real_si(p, "units_edge_gap"), 1e-9);   // 1 nm = 1e-9 m, not 1 m and not 1e-18 m
  EXPECT_EQ(afmkit::cli::real_si(p, "units_edge_f0"), 300e3);    // 300 kHz = 3e5 Hz
  EXPECT_EQ(afmkit::cli::real_si(p, "units_edge_k"), 40.0);      // N/m is SI
  p.set_from_string("units_edge_gap", "2.5");
  EXPECT_EQ(afmkit::cli::real_si(p, "units_edge_gap"), 2.5 * 1e-9);
  EXPECT_THROW(afmkit::cli::real_si(p, "units_edge_q"), std::logic_error);  // no SI form: a programming error
}

TEST(UnitsAtOneEdge, AColumnConvertsItsValueIntoTheUnitItNames) {
  struct UnitsEdgeRow {
    double gap;      // m (SI)
    double model_v;  // model units L/t
  };
  const afmkit::units::Unit length{"nm", 3.0}, time{"s", 0.5};
  const afmkit::io::TableOf<UnitsEdgeRow> table{
      {"gap", afmkit::units::from_si("nm"), "a gap", &UnitsEdgeRow::gap},
      {"velocity", length.per(time), "a velocity", &UnitsEdgeRow::model_v}};
  const auto columns = table.columns();
  EXPECT_EQ(columns[0].unit, "nm");
  EXPECT_EQ(columns[1].unit, "nm/s");
  const UnitsEdgeRow row{2e-9, 1.0};
  EXPECT_DOUBLE_EQ(std::get<double>(table.entries()[0].value(row)), 2.0);
  EXPECT_DOUBLE_EQ(std::get<double>(table.entries()[1].value(row)), 6.0);  // 1 L/t * 3 nm/L / (0.5 s/t)
  // a results entry: the value and its unit declared together
  afmkit::cli::UnitTagged tagged;
  tagged.add("gap", 2e-9, afmkit::units::from_si("nm")).add("count", 3, "count").add("name", "x");
  EXPECT_DOUBLE_EQ(tagged.values()["gap"].get<double>(), 2.0);
  EXPECT_EQ(tagged.units(), (nlohmann::json{{"gap", "nm"}, {"count", "count"}}));
  EXPECT_DOUBLE_EQ(afmkit::units::degrees_from_radians()(std::acos(-1.0)), 180.0);
}

TEST(UnitsAtOneEdge, ARowRecordHoldsTheValuesOfItsDeclarationsAndASummaryMovesValuesAndUnitsOut) {
  // rows of an array are built without units (UnitTagged::values_only: the array's units are given once); the same
  // declarations give the same values; a record moved into a document keeps its values and units
  const afmkit::units::Unit nm = afmkit::units::from_si("nm");
  const auto record = [&](afmkit::cli::UnitTagged j) { return j.add("gap", 2e-9, nm).add("count", 3, "count"); };
  afmkit::cli::UnitTagged full = record(afmkit::cli::UnitTagged());
  const nlohmann::json row = record(afmkit::cli::UnitTagged(afmkit::cli::UnitTagged::values_only)).values();
  EXPECT_EQ(row, (nlohmann::json{{"gap", 2.0}, {"count", 3}}));
  EXPECT_EQ(row, full.values());
  EXPECT_TRUE(record(afmkit::cli::UnitTagged(afmkit::cli::UnitTagged::values_only)).units().empty());
  afmkit::cli::UnitTagged document;
  document.add("rows", nlohmann::json::array({row})).unit("rows", full.units()).add("nested", std::move(full));
  const nlohmann::json summary = std::move(document).summary();
  EXPECT_EQ(summary["nested"], row);
  EXPECT_EQ(summary["units"]["rows"], (nlohmann::json{{"gap", "nm"}, {"count", "count"}}));
  EXPECT_EQ(summary["units"]["nested"], summary["units"]["rows"]);
}

TEST(UnitsAtOneEdge, TappingOrbitInPhysicalUnitsIsTheNormalisedOrbitScaledOnce) {
  // the same model (law attractive) run in physical units (k = 2 N/m, f0 = 1 kHz, A_free = 10 nm, Q = 50,
  // ω/ω_n = 1) and in its normalised form (ω_n = 1, Γ = A_free |1 - r^2 + i r/Q| = A_free/Q, stiffnesses and
  // adhesions divided by k): lengths equal (L = nm), forces and energies k times, velocities 2π f0 times. A scale
  // applied twice or not at all (or to the wrong quantity) breaks one of these.
  const double k = 2.0, f0_hz = 1e3, a_free = 10.0, q = 50.0, ks_a = 8.0, ks_b = 6.0, f_a = 0.2, f_b = 0.4;
  const std::string common = " --law attractive --quality-factor 50 --separation 9 --json --output orbit.csv";
  afmkit_test::TempDir dir;
  const auto phys = afmkit_test::run_cli(
      "tapping orbit --units physical --spring-constant 2 --resonance-frequency 1 --free-amplitude 10 "
      "--sample-stiffness-approach 8 --sample-stiffness-departure 6 --adhesion-approach 0.2 --adhesion-departure 0.4" +
          common, dir);
  ASSERT_EQ(phys.status, 0) << phys.err;
  const auto norm = afmkit_test::run_cli(
      "tapping orbit --drive-amplitude " + std::to_string(a_free / q) + " --approach-stiffness " +
          std::to_string(ks_a / k) + " --departure-stiffness " + std::to_string(ks_b / k) + " --approach-adhesion " +
          std::to_string(f_a / k) + " --departure-adhesion " + std::to_string(f_b / k) + common, dir);
  ASSERT_EQ(norm.status, 0) << norm.err;
  const auto pj = nlohmann::json::parse(phys.out), nj = nlohmann::json::parse(norm.out);
  ASSERT_FALSE(pj["orbits"].empty());
  ASSERT_EQ(pj["orbits"].size(), nj["orbits"].size());
  const auto& po = pj["orbits"][0];
  const auto& no = nj["orbits"][0];
  const double omega = 2.0 * std::acos(-1.0) * f0_hz;
  const auto near = [](double a, double b) { return std::abs(a - b) <= 1e-5 * std::max(std::abs(b), 1e-3); };
  EXPECT_TRUE(near(po["amplitude"].get<double>(), no["amplitude"].get<double>())) << po["amplitude"];
  EXPECT_TRUE(near(po["peak_force"].get<double>(), k * no["peak_force"].get<double>())) << po["peak_force"];
  EXPECT_TRUE(near(po["drive_work"].get<double>(), k * no["drive_work"].get<double>())) << po["drive_work"];
  EXPECT_TRUE(near(po["contact_dissipation"].get<double>(), k * no["contact_dissipation"].get<double>()))
      << po["contact_dissipation"];
  EXPECT_TRUE(near(po["initial_velocity"].get<double>(), omega * no["initial_velocity"].get<double>()))
      << po["initial_velocity"];
  EXPECT_TRUE(near(pj["free_amplitude"].get<double>(), a_free)) << pj["free_amplitude"];
  EXPECT_EQ(pj["units"]["orbits"]["peak_force"], "nN");
  EXPECT_EQ(pj["units"]["orbits"]["initial_velocity"], "nm/s");
  EXPECT_EQ(nj["units"]["orbits"]["initial_velocity"], "L/t");
}

}  // namespace
