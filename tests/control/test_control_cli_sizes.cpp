// `afmkit control …` at large N and with out-of-range sizes (issue 6), end to end (skipped when the CLI has not
// been built): every command answers at N = 1000; sizes beyond the documented ranges (docs/commands.md) or beyond
// the available memory exit with status 2 naming the parameter before any work (no output file); the chart
// sidecar records the window that was computed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <unistd.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "control_cli_fixture.hpp"

#include "test_helpers.hpp"

namespace {
namespace fs = std::filesystem;
using afmkit_test::CliResult;
using afmkit_test::slurp;



class ControlCliSizes : public afmkit_test::ControlCliFixture {
 protected:
};

// ---- every command answers at N = 1000 (defect 1) ------------------------------------------------------------

TEST_F(ControlCliSizes, TfAtN1000MatchesStateSpaceAndN100000Answers) {
  const CliResult r = run("control tf --harmonics 1000 --points 5 --frequency-min 0.55 --frequency-max 2.55 "
                    "--log-spacing false --output tf.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  // independent: C(iω) = K c_1ᵀ (iωI − A)⁻¹ b with 2×2 blocks and Sherman–Morrison (seed-2 eqs. 37–39), α = 0.1,
  // β = −0.1, K = 20, Ω = 1: x-component of block k: (a_k s − kΩ b_k)/(s² + k²)
  const auto rows = afmkit::control::testing::read_tf_csv(dir_ / "tf.csv");
  for (const auto& row : rows) {
    const std::complex<double> s(0.0, row.frequency);
    std::complex<double> ce_y = 0.1 / s, c1_y = 0.0;
    for (int k = 1; k <= 1000; ++k) {
      const std::complex<double> y = (0.2 * s - 0.2) / (s * s + double(k) * k);
      (k == 1 ? c1_y : ce_y) += y;
    }
    const std::complex<double> expected = 20.0 * c1_y / (1.0 + ce_y);
    EXPECT_NEAR(row.real, expected.real(), 1e-9 * std::abs(expected)) << row.line;
    EXPECT_NEAR(row.imag, expected.imag(), 1e-9 * std::abs(expected)) << row.line;
  }
  EXPECT_EQ(rows.size(), 5u);
  // the documented maximum
  const CliResult big = run("control tf --harmonics 100000 --points 3 --output big.csv");
  EXPECT_EQ(big.status, 0) << big.err;
}

TEST_F(ControlCliSizes, RootsMarginChartTuneSimulateAnswerAtN1000) {
  CliResult r = run("control roots --harmonics 1000 --delay 0.1 --count 6 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["complete"].get<bool>());
  EXPECT_LT(j["spectral_abscissa"].get<double>(), 0.0);  // τ = 0.1T < τ_c ≈ 0.29T (docs/theory-control.md#delay-margin)

  // N = 1000 is the documented maximum of roots, margin, chart, tune and simulate (docs/commands.md)
  r = run("control margin --harmonics 1000 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  // N → ∞ value τ_c/T = 0.294 at (α, β) = (0.1, −0.1) (docs/theory-control.md#delay-margin); finite-N corrections are
  // O(1/N)
  EXPECT_NEAR(j["critical_delay"].get<double>(), 0.294, 0.005);

  r = run("control chart --harmonics 1000 --x-points 2 --y-points 2 --x-min 0.05 --x-max 0.15 --y-min -0.15 "
          "--y-max -0.05 --progress false --output chart.csv --boundaries-output b.csv");
  EXPECT_EQ(r.status, 0) << r.err;

  r = run("control tune --harmonics 1000 --coarse-points 2 --max-evaluations 2 --delay-points 1 --gain-points 1 "
          "--progress false --json");
  EXPECT_EQ(r.status, 0) << r.err;

  r = run("control simulate --harmonics 1000 --method zoh --periods 2 --steps-per-period 4000 --json");
  EXPECT_EQ(r.status, 0) << r.err;
}

// Out-of-range sizes (exit 2 before any work, the parameter named): rows of docs/bad-input.md, run by
// tests/cli/test_bad_input.cpp.

// ---- the chart sidecar records the computed window (defect 2) -------------------------------------------------

// The grid actually written: min/max of the first two CSV columns (x, y) and the row count.
struct GridExtent {
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  int rows = 0;
};
GridExtent grid_extent(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  GridExtent e;
  while (std::getline(in, line)) {
    double x, y;
    char c;
    std::stringstream ss(line);
    ss >> x >> c >> y;
    e.xmin = std::min(e.xmin, x);
    e.xmax = std::max(e.xmax, x);
    e.ymin = std::min(e.ymin, y);
    e.ymax = std::max(e.ymax, y);
    ++e.rows;
  }
  return e;
}
// The sidecar's window, in the parameters as run and in the results, is the grid written.
void expect_window(const nlohmann::json& sidecar, const GridExtent& e) {
  for (const auto* sec : {"parameters", "results"}) {
    const auto& w = std::string(sec) == "results" ? sidecar[sec]["window"] : sidecar[sec];
    EXPECT_DOUBLE_EQ(w["x_min"].get<double>(), e.xmin) << sec;
    EXPECT_DOUBLE_EQ(w["x_max"].get<double>(), e.xmax) << sec;
    EXPECT_DOUBLE_EQ(w["y_min"].get<double>(), e.ymin) << sec;
    EXPECT_DOUBLE_EQ(w["y_max"].get<double>(), e.ymax) << sec;
  }
}

TEST_F(ControlCliSizes, ChartSidecarRecordsTheComputedWindow) {
  // default window of the coupling family (docs: alpha in [-0.1, 1], beta in [-0.4, 1])
  const CliResult r = run("control chart --harmonics 3 --x-points 3 --y-points 3 --progress false --output c.csv "
                    "--boundaries-output b.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const GridExtent e = grid_extent(dir_ / "c.csv");
  EXPECT_EQ(e.rows, 9);
  EXPECT_DOUBLE_EQ(e.xmin, -0.1);
  EXPECT_DOUBLE_EQ(e.xmax, 1.0);
  EXPECT_DOUBLE_EQ(e.ymin, -0.4);
  EXPECT_DOUBLE_EQ(e.ymax, 1.0);
  const auto j = nlohmann::json::parse(slurp(dir_ / "c.csv.json"));
  expect_window(j, e);
  EXPECT_EQ(j["results"]["x_points"].get<int>(), 3);
  EXPECT_EQ(j["results"]["y_points"].get<int>(), 3);
}

TEST_F(ControlCliSizes, TuneSidecarRecordsTheComputedWindow) {
  // default window of the tuning search (coupling family): the coarse grid's corners are the window's
  const CliResult r = run("control tune --harmonics 3 --coarse-points 3 --max-evaluations 2 --delay-points 1 "
                          "--gain-points 1 --progress false --output t.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const GridExtent e = grid_extent(dir_ / "t.csv");
  EXPECT_EQ(e.rows, 9);
  const auto j = nlohmann::json::parse(slurp(dir_ / "t.csv.json"));
  expect_window(j, e);
}

}  // namespace
