// afmkit tapping modes on the command line: far from the sample every mode oscillates as the linear closed form
// says (mode 1 at its resonance: A = ΓQ, phase π/2; mode 2 at its own with the asked free amplitude) and the tip is
// the sum of the modes; near it the second mode's phase moves, and every row's energy balance holds.
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_run.hpp"

namespace {

using afmkit_test::run_cli;
using afmkit_test::TempDir;

nlohmann::json modes_cli_document(const std::string& args) {
  TempDir dir;
  const auto r = run_cli("tapping modes " + args + " --json --output ''", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

double modes_cli_cell(const nlohmann::json& doc, std::size_t row, const std::string& column) {
  const auto& columns = doc["table"]["columns"];
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i]["name"] == column) {
      const auto& cell = doc["table"]["rows"][row][i];
      if (cell.is_boolean()) return cell.get<bool>() ? 1.0 : 0.0;
      return cell.is_null() ? std::nan("") : cell.get<double>();
    }
  ADD_FAILURE() << "no column " << column;
  return std::nan("");
}

TEST(TappingModesCli, FarFromTheSampleEveryModeIsItsFreeLinearResponse) {
  // normalised defaults: ω_1 = 1, Q = 100, Γ = 0.2 at ω = ω_1; Euler–Bernoulli mode 2: ω_2 = (λ_2/λ_1)², Q_2 = Qω_2
  const auto doc = modes_cli_document(
      "--separation-min 40 --separation-max 40 --points 1 --settle-periods 20 --lockin-periods 10 "
      "--second-free-amplitude 0.5");
  ASSERT_EQ(doc["table"]["rows"].size(), 1u);
  EXPECT_NEAR(modes_cli_cell(doc, 0, "amplitude_1"), 0.2 * 100.0, 1e-4 * 20.0);
  EXPECT_NEAR(modes_cli_cell(doc, 0, "phase_1"), std::numbers::pi / 2, 1e-5);
  EXPECT_NEAR(modes_cli_cell(doc, 0, "amplitude_2"), 0.5, 1e-3 * 0.5);
  EXPECT_NEAR(modes_cli_cell(doc, 0, "phase_2"), std::numbers::pi / 2, 1e-3);
  EXPECT_TRUE(std::isnan(modes_cli_cell(doc, 0, "amplitude_3")));
  // the tip at drive 1: mode 1 (−20i) plus mode 2 driven off resonance, Γ L_2(i)
  const double l1 = 1.8751040687119611, l2 = 4.6940911329741745;
  const double w2 = (l2 / l1) * (l2 / l1), q2 = 100.0 * w2;
  const std::complex<double> tip = std::complex<double>(0.0, -20.0) + 0.2 / std::complex<double>(w2 * w2 - 1.0, w2 / q2);
  EXPECT_NEAR(modes_cli_cell(doc, 0, "tip_amplitude_1"), std::abs(tip), 1e-4 * 20.0);
  EXPECT_EQ(modes_cli_cell(doc, 0, "tip_work_1"), 0.0);
  EXPECT_LT(modes_cli_cell(doc, 0, "energy_residual"), 1e-7 * std::abs(modes_cli_cell(doc, 0, "drive_work_1")));
  EXPECT_NEAR(doc["mode_frequencies"][1].get<double>() / doc["mode_frequencies"][0].get<double>(), w2, 1e-12 * w2);
}

TEST(TappingModesCli, InTappingTheSecondModePhaseMovesAndEveryModeBalancesItsEnergy) {
  const auto doc = modes_cli_document(
      "--quality-factor 20 --separation-min 3 --separation-max 30 --points 2 --settle-periods 40 "
      "--lockin-periods 10 --second-free-amplitude 0.5");
  ASSERT_EQ(doc["table"]["rows"].size(), 2u);
  EXPECT_NEAR(modes_cli_cell(doc, 0, "phase_2"), std::numbers::pi / 2, 1e-3);
  EXPECT_GT(modes_cli_cell(doc, 1, "impacts"), 0.0);
  EXPECT_GT(std::abs(modes_cli_cell(doc, 1, "phase_2") - std::numbers::pi / 2), 0.01);
  for (std::size_t row = 0; row < 2; ++row) {
    const double scale = std::abs(modes_cli_cell(doc, row, "drive_work_1"));
    EXPECT_LT(modes_cli_cell(doc, row, "energy_residual"), 1e-6 * scale) << row;
  }
  EXPECT_LT(modes_cli_cell(doc, 1, "tip_work_1") + modes_cli_cell(doc, 1, "tip_work_2"), 0.0);  // the sample takes
}

TEST(TappingModesCli, ThePeriodicOrbitIsWhereALongTransientSettles) {
  // one drive (commensurate): Newton's orbit after a short settling against 300 periods of settling at Q = 20
  // (free amplitude ΓQ = 4; transients decay by exp(−π·300/20) ≈ 3e-21)
  const std::string common = "--quality-factor 20 --separation-min 3 --separation-max 3 --points 1 --lockin-periods 4";
  const auto orbit = modes_cli_document(common + " --settle-periods 20 --periodic");
  const auto settled = modes_cli_document(common + " --settle-periods 300");
  ASSERT_EQ(modes_cli_cell(orbit, 0, "periodic"), 1.0);
  EXPECT_EQ(modes_cli_cell(settled, 0, "periodic"), 0.0);
  EXPECT_GT(modes_cli_cell(orbit, 0, "impacts"), 0.0);
  for (const char* column : {"amplitude_1", "phase_1", "amplitude_2", "tip_amplitude_1"})
    EXPECT_NEAR(modes_cli_cell(orbit, 0, column), modes_cli_cell(settled, 0, column),
                1e-6 * std::max(1.0, std::abs(modes_cli_cell(settled, 0, column))))
        << column;
}

}  // namespace
