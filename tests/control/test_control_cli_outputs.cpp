// `afmkit control …` outputs end to end (skipped when the CLI has not been built): every table command writes no
// file with --output "" and prints its table with --json; every column and parameter carries a unit; results do not
// depend on the rotation frequency once stated in units of Ω and T; several chart delays in one run equal single
// runs; `control simulate` reports harmonics above N, checked against an independent DFT of its own time series and
// against the closed-loop response S(ikΩ) f_k of the frequency domain.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <unistd.h>
#include <sys/wait.h>
#include <vector>

#include <nlohmann/json.hpp>

#include "control_cli_fixture.hpp"

#include "afmkit/control/loop.hpp"
#include "afmkit/control/settings.hpp"

namespace {
namespace fs = std::filesystem;
using afmkit_test::CliResult;
using afmkit_test::slurp;
using nlohmann::json;



// A CSV with a header: column name -> values (numbers; text cells as NaN).
std::map<std::string, std::vector<double>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::stringstream h(line); std::getline(h, cell, ',');) names.push_back(cell);
  std::map<std::string, std::vector<double>> t;
  while (std::getline(in, line)) {
    std::stringstream r(line);
    for (const auto& n : names) {
      std::getline(r, cell, ',');
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      t[n].push_back(end == cell.c_str() ? NAN : v);
    }
  }
  return t;
}

class ControlCliOutputs : public afmkit_test::ControlCliFixture {
 protected:
  json run_json(const std::string& args) const {
    const CliResult r = run(args);
    EXPECT_EQ(r.status, 0) << args << "\n" << r.err;
    return r.status == 0 ? json::parse(r.out) : json();
  }
};

// Small runs of every control command that computes a table.
const std::vector<std::string> kCommands = {
    "control tf --points 5",
    "control roots --harmonics 3",
    "control margin --harmonics 3",
    "control margin --harmonics 3 --compare",
    "control chart --harmonics 3 --x-points 3 --y-points 3 --progress false --boundaries-output ''",
    "control chart --harmonics 3 --x-points 3 --y-points 3 --progress false --quantity margin",
    "control tune --harmonics 3 --coarse-points 2 --max-evaluations 2 --delay-points 1 --gain-points 1 --progress false",
    "control simulate --harmonics 3 --periods 3 --steps-per-period 100"};

// No "nan" strings anywhere: NaN is null in JSON (docs/conventions.md).
void expect_no_nan_text(const json& j, const std::string& where) {
  if (j.is_string()) {
    EXPECT_NE(j.get<std::string>(), "nan") << where;
  } else if (j.is_structured()) {
    for (const auto& item : j) expect_no_nan_text(item, where);
  }
}

void expect_described_columns(const json& columns, const std::string& where) {
  ASSERT_TRUE(columns.is_array()) << where;
  ASSERT_FALSE(columns.empty()) << where;
  for (const auto& c : columns) {
    EXPECT_FALSE(c["name"].get<std::string>().empty()) << where;
    EXPECT_FALSE(c["unit"].get<std::string>().empty()) << where << " " << c["name"];
    EXPECT_NE(c["unit"].get<std::string>(), "?") << where << " " << c["name"];
    EXPECT_FALSE(c["description"].get<std::string>().empty()) << where << " " << c["name"];
  }
}

}  // namespace

TEST_F(ControlCliOutputs, WithoutAFileJsonPrintsTheTableAndNothingIsWritten) {
  for (const std::string& command : kCommands) {
    const json j = run_json(command + " --output '' --json");
    EXPECT_EQ(files(), 0) << command;
    ASSERT_TRUE(j.contains("table")) << command;
    expect_described_columns(j["table"]["columns"], command);
    const std::size_t width = j["table"]["columns"].size();
    ASSERT_FALSE(j["table"]["rows"].empty()) << command;
    for (const auto& row : j["table"]["rows"]) EXPECT_EQ(row.size(), width) << command;
    expect_no_nan_text(j, command);
    EXPECT_TRUE(j.contains("settings") && j.contains("settings_si")) << command;
  }
}

TEST_F(ControlCliOutputs, WithoutAFileTheSummaryIsPrintedAndNothingIsWritten) {
  for (const std::string& command : kCommands) {
    const CliResult r = run(command + " --output ''");
    EXPECT_EQ(r.status, 0) << command << "\n" << r.err;
    EXPECT_FALSE(r.out.empty()) << command;
    EXPECT_EQ(files(), 0) << command;
  }
}

TEST_F(ControlCliOutputs, SidecarsGiveTheUnitOfEveryColumnAndParameterAndTheSettingsInBothUnits) {
  for (const std::string& command : kCommands) {
    const CliResult r = run(command + " --output t.csv");
    ASSERT_EQ(r.status, 0) << command << "\n" << r.err;
    const json side = json::parse(slurp(dir_ / "t.csv.json"));
    expect_described_columns(side["columns"], command);
    for (const auto& [key, value] : side["parameters"].items())
      if (value.is_number() || value.is_array()) {
        EXPECT_TRUE(side["parameter_units"].contains(key)) << command << ": " << key << " has no unit";
      }
    const json& user = side["results"]["settings"];
    const json& si = side["results"]["settings_si"];
    EXPECT_EQ(user["units"]["delay"], "T") << command;
    EXPECT_EQ(si["units"]["delay"], "s") << command;
    EXPECT_NEAR(user["delay"].get<double>() * si["period"].get<double>(), si["delay"].get<double>(), 1e-15) << command;
    EXPECT_NEAR(user["plant_rate"].get<double>() * si["rotation_frequency"].get<double>(), si["plant_rate"].get<double>(),
                1e-12)
        << command;
    expect_no_nan_text(side, command);
    fs::remove(dir_ / "t.csv");
    fs::remove(dir_ / "t.csv.json");
    fs::remove_all(dir_ / "out");
  }
}

// Stated in units of Ω and T, the loop is the same at any rotation frequency: every number is independent of it.
TEST_F(ControlCliOutputs, ResultsInUnitsOfOmegaAndTDoNotDependOnTheRotationFrequency) {
  const std::string fast = " --rotation-frequency 314.159265 --output '' --json";
  const json m1 = run_json("control margin --harmonics 4 --output '' --json"), m2 = run_json("control margin --harmonics 4" + fast);
  EXPECT_NEAR(m1["critical_delay"].get<double>(), m2["critical_delay"].get<double>(), 1e-9);
  EXPECT_NEAR(m1["crossing_frequency"].get<double>(), m2["crossing_frequency"].get<double>(), 1e-9);
  EXPECT_NE(m2["loop"].get<std::string>().find("tau=0.1 T"), std::string::npos) << m2["loop"];

  for (const char* system : {"controller", "plant", "loop"}) {
    const std::string tf = std::string("control tf --points 6 --frequency-min 0.3 --frequency-max 4 --system ") + system;
    const json a = run_json(tf + " --output '' --json"), b = run_json(tf + fast);
    ASSERT_EQ(a["table"]["rows"].size(), b["table"]["rows"].size());
    for (std::size_t i = 0; i < a["table"]["rows"].size(); ++i)
      for (std::size_t c = 0; c < 5; ++c) {
        const double x = a["table"]["rows"][i][c].get<double>(), y = b["table"]["rows"][i][c].get<double>();
        EXPECT_NEAR(x, y, 1e-9 * (1.0 + std::abs(x))) << system << " row " << i << " column " << c;
      }
  }

  const std::string sim = "control simulate --harmonics 3 --periods 20 --steps-per-period 200 --plant first_order";
  const json s1 = run_json(sim + " --output '' --json"), s2 = run_json(sim + fast);
  EXPECT_NEAR(s1["growth_rate"].get<double>(), s2["growth_rate"].get<double>(), 1e-6);
  EXPECT_NEAR(s1["step"].get<double>(), 1.0 / 200, 1e-15);  // h = T/M in units of T
  EXPECT_NEAR(std::abs(s1["control_first_harmonic"]["abs"].get<double>() - s2["control_first_harmonic"]["abs"].get<double>()),
              0.0, 1e-6);
}

// tf of the single oscillator in units of Ω at Ω = 50 rad/s: C/Ω = K(a i x − b)/(1 − x²), x = ω/Ω (eq. 10).
TEST_F(ControlCliOutputs, ControllerResponseIsInUnitsOfOmega) {
  const json j = run_json("control tf --controller single --a 0.5 --b 0.2 --gain 3 --rotation-frequency 50 --points 4 "
                          "--frequency-min 0.2 --frequency-max 3 --output '' --json");
  EXPECT_EQ(j["table"]["columns"][1]["unit"], "Omega");
  for (const auto& row : j["table"]["rows"]) {
    const double x = row[0].get<double>();
    const std::complex<double> expected = 3.0 * std::complex<double>(-0.2, 0.5 * x) / (1.0 - x * x);
    EXPECT_NEAR(row[3].get<double>(), expected.real(), 1e-12 * std::abs(expected));
    EXPECT_NEAR(row[4].get<double>(), expected.imag(), 1e-12 * std::abs(expected));
  }
}

TEST_F(ControlCliOutputs, ChartWithSeveralDelaysEqualsOneRunPerDelay) {
  const std::string chart = "control chart --harmonics 3 --x-points 4 --y-points 3 --x-min 0.02 --x-max 0.5 --y-min -0.3 "
                            "--y-max 0.2 --progress false --threads 1";
  const std::vector<double> delays = {0.05, 0.2};
  CliResult r = run(chart + " --delays 0.05,0.2 --output all.csv --boundaries-output all_b.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto all = read_csv(dir_ / "all.csv"), all_b = read_csv(dir_ / "all_b.csv");
  const json side = json::parse(slurp(dir_ / "all.csv.json"));
  ASSERT_EQ(side["results"]["charts"].size(), delays.size());
  EXPECT_EQ(side["parameters"]["delays"], json(delays));
  std::size_t row = 0, brow = 0;
  for (std::size_t d = 0; d < delays.size(); ++d) {
    EXPECT_EQ(side["results"]["charts"][d]["delay"].get<double>(), delays[d]);
    r = run(chart + " --delay " + std::to_string(delays[d]) + " --output one.csv --boundaries-output one_b.csv");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto one = read_csv(dir_ / "one.csv"), one_b = read_csv(dir_ / "one_b.csv");
    const json one_side = json::parse(slurp(dir_ / "one.csv.json"));
    EXPECT_EQ(side["results"]["charts"][d]["regions"], one_side["results"]["charts"][0]["regions"]) << delays[d];
    for (std::size_t i = 0; i < one.at("x").size(); ++i, ++row) {
      for (const char* c : {"x", "y", "spectral_abscissa", "unstable_roots", "region", "delay"})
        EXPECT_DOUBLE_EQ(all.at(c).at(row), one.at(c).at(i)) << c << " at delay " << delays[d] << " row " << i;
      EXPECT_EQ(all.at("delay").at(row), delays[d]);
    }
    ASSERT_FALSE(one_b.at("x").empty());
    for (std::size_t i = 0; i < one_b.at("x").size(); ++i, ++brow)
      for (const char* c : {"curve", "frequency", "x", "y", "delay"})
        EXPECT_DOUBLE_EQ(all_b.at(c).at(brow), one_b.at(c).at(i)) << c << " at delay " << delays[d];
  }
  EXPECT_EQ(row, all.at("x").size());
  EXPECT_EQ(brow, all_b.at("x").size());
  // the margin map does not depend on the delay: several delays are refused, naming the parameter
  r = run(chart + " --quantity margin --delays 0.05,0.2 --output m.csv");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("delays"), std::string::npos) << r.err;
  r = run(chart + " --delays 0.1,nan --output m.csv");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("delays"), std::string::npos) << r.err;
}

// N = 3 bank, static plant, f = sin(Ωt) + 0.5 sin(5Ωt + 0.3): harmonic 5 lies above N. The report lists it (up to
// max_order), its value equals a DFT of the simulated y over the last period (computed here from the CSV), and
// (converged) the frequency-domain closed loop: y_5 = S(5iΩ) f_5 with f_5 = −i F e^{iφ}.
TEST_F(ControlCliOutputs, SimulateReportsHarmonicsAboveTheBank) {
  const int periods = 60, steps = 400;
  const CliResult r = run("control simulate --harmonics 3 --disturbance-offset 0 --disturbance-amplitudes 1,0,0,0,0.5 "
                          "--disturbance-phases 0,0,0,0,0.3 --periods " + std::to_string(periods) +
                          " --steps-per-period " + std::to_string(steps) +
                          " --record-every 1 --max-order 8 --method ab3 --output sim.csv --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json rep = json::parse(r.out);
  EXPECT_EQ(rep["bank_max_order"].get<int>(), 3);
  const auto t = read_csv(dir_ / "sim.csv");
  const auto& y = t.at("y");
  ASSERT_EQ(y.size(), static_cast<std::size_t>(periods * steps));
  EXPECT_NEAR(t.at("t").at(y.size() - steps), periods - 1.0, 1e-9);  // t in units of T
  std::map<int, std::complex<double>> reported;
  for (const auto& h : rep["harmonics"])
    reported[h["order"].get<int>()] = {h["value"]["re"].get<double>(), h["value"]["im"].get<double>()};
  for (int k = 2; k <= 8; ++k) ASSERT_TRUE(reported.count(k)) << "harmonic " << k << " not reported";
  EXPECT_FALSE(reported.count(9));
  // independent DFT of the last period: c_k = (2/M) Σ y_n e^{−2πikn/M}
  for (int k = 2; k <= 8; ++k) {
    std::complex<double> c = 0.0;
    for (int n = 0; n < steps; ++n)
      c += y[y.size() - steps + n] * std::exp(std::complex<double>(0.0, -2.0 * std::numbers::pi * k * n / steps));
    c *= 2.0 / steps;
    EXPECT_NEAR(std::abs(reported[k] - c), 0.0, 1e-9) << "harmonic " << k;
  }
  // frequency domain: y_5 = S(5iΩ) f_5 (Ω = 1; S of the same loop, loop.hpp)
  afmkit::control::ControlSettings s;
  s.harmonics = 3;
  const afmkit::control::LoopSpec loop = afmkit::control::loop_from(s);
  const std::complex<double> f5 = std::complex<double>(0.0, -0.5) * std::exp(std::complex<double>(0.0, 0.3));
  const std::complex<double> expected = afmkit::control::disturbance_response(loop, {0.0, 5.0}) * f5;
  EXPECT_GT(std::abs(expected - f5), 1e-2);  // harmonic 5 is distorted: the controller does not model it
  EXPECT_NEAR(std::abs(reported[5] - expected), 0.0, 1e-4 * std::abs(f5))
      << "simulated " << reported[5] << ", frequency domain " << expected;
  EXPECT_NEAR(rep["max_harmonic_error_above_bank"].get<double>(), std::abs(reported[5] - f5), 1e-6);
}

TEST_F(ControlCliOutputs, SimulateMaxOrderBeyondNyquistIsRefusedNamingIt) {
  const CliResult r = run("control simulate --harmonics 3 --steps-per-period 100 --max-order 50 --output s.csv");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("max_order = 50 is out of range: must be an integer in [1, 49]"), std::string::npos) << r.err;
  EXPECT_EQ(files(), 0);
}
