// Hostile limits (issue 24 §3), at the command line: energy-creating force curves that only the whole-domain check
// sees, heights that overflow, a recorded spiral with a radius outlier in its last turn, images and sample maps
// beyond the memory limit, requests beyond the work limit, and the one spelling of undefined values in tables.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "../cli/cli_run.hpp"

using afmkit_test::run_cli;
using afmkit_test::run_shell;
using afmkit_test::slurp;
using afmkit_test::TempDir;

namespace {
/// A three-column force curve: the approach H_a = −d on [−3, 1] nm and the given retract forces at the same gaps.
std::string curve_text(const std::string& retract) {
  const double gaps[] = {-3, -2, -1, 0, 1};
  std::string text = "distance (nm), approach (nN), retract (nN)\n";
  std::size_t start = 0;
  for (double d : gaps) {
    const std::size_t end = retract.find(' ', start);
    text += std::to_string(d) + ", " + std::to_string(-d) + ", " + retract.substr(start, end - start) + "\n";
    start = end == std::string::npos ? end : end + 1;
  }
  return text;
}

/// The number after `key` in `text` (NaN if absent).
double number_after(const std::string& text, const std::string& key) {
  const auto at = text.find(key);
  return at == std::string::npos ? NAN : std::stod(text.substr(at + key.size()));
}
}  // namespace

TEST(HostileLimits, ForceCurvesThatCreateEnergyOnlyOffTheKnotsAreRefused) {
  TempDir dir;
  // between the knots (the retract's interpolant rises above the approach line between −2 and −1 nm)
  dir.write("between.csv", curve_text("2.0 1.99 0.99 -0.5 -1.5"));
  const auto r = run_cli("impact --law table --force-curve between.csv --gap 2 --velocity 32 --output o.csv", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("the curve would create energy"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("o.csv")));
  // a retract stiffer at the deepest point continues below the tables with the approach's slope (table_law.hpp):
  // accepted, and a deep impact (far below the measured −3 nm) still dissipates
  dir.write("below.csv", curve_text("2.5 1.2 0.4 -0.1 -1.2"));
  const auto g = run_cli("impact --law table --force-curve below.csv --gap 2 --velocity 32 --output \"\" --json", dir);
  ASSERT_EQ(g.status, 0) << g.err;
  EXPECT_LE(number_after(g.out, "\"restitution\": "), 1.0) << g.out;
  EXPECT_LT(number_after(g.out, "\"minimum_gap\": "), -3.9) << g.out;  // deeper than where the old lines crossed
  // an accepted curve dissipates: e <= 1 in the same impact
  dir.write("good.csv", curve_text("2.5 1.5 0.5 -0.5 -1.5"));
  const auto ok = run_cli("impact --law table --force-curve good.csv --gap 2 --velocity 32 --output \"\" --json", dir);
  ASSERT_EQ(ok.status, 0) << ok.err;
  EXPECT_LE(number_after(ok.out, "\"restitution\": "), 1.0) << ok.out;
}

TEST(HostileLimits, HeightsThatOverflowAreRefused) {
  TempDir dir;
  dir.write("huge.txt", "1e308 0 0 0\n0 0 0 0\n0 0 0 0\n0 0 0 1e307\n");
  auto r = run_cli("scan --sample file --sample-file huge.txt --sample-size 1e-2 --output t.csv --image-output \"\"",
                   dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("sample_z_scale = 1 m is out of range for huge.txt: its value 1e+308 at row 1, column 1"),
            std::string::npos)
      << r.err;
  dir.write("small.txt", "1 2 3 4\n1 2 3 4\n1 2 3 4\n1 2 3 4\n");
  r = run_cli("scan --sample file --sample-file small.txt --sample-size 1e-2 --sample-z-scale 1e307 --output t.csv "
              "--image-output \"\"",
              dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("sample_z_scale must be <= 0.25 m for this file"), std::string::npos) << r.err;
  r = run_cli("scan --grating-height 1e300 --output t.csv --image-output \"\"", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("grating_height"), std::string::npos) << r.err;
  EXPECT_EQ(dir.count_files(), 2u);  // only the two inputs: nothing written
}

TEST(HostileLimits, ARadiusOutlierInTheLastPartialTurnIsRefused) {
  TempDir dir;
  // 50 Hz spindle sampled at 1 kHz (20 samples a turn), 3.5 turns from 1 mm outwards at 1 µm a turn; one radius of
  // 1 m in the last, partial, turn
  std::string csv = "time,radius,angle,deflection\n";
  const int n = 70;
  for (int k = 0; k < n; ++k) {
    const double t = k * 1e-3, angle = 2.0 * M_PI * 50.0 * t;
    const double radius = k == n - 3 ? 1.0 : 1e-3 + 1e-6 * angle / (2.0 * M_PI);
    csv += std::to_string(t) + "," + std::to_string(radius) + "," + std::to_string(angle) + ",0\n";
  }
  dir.write("outlier.csv", csv);
  const auto r = run_cli("scan --recorded outlier.csv --harmonics 2 --image-resolution 64 --image-output img --output t.csv",
                         dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("the recorded spiral advances up to 0.99"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("t = 0.06 s"), std::string::npos) << r.err;
  EXPECT_EQ(dir.count_files(), 1u);
}

TEST(HostileLimits, ImagesAndSampleMapsAreCheckedBeforeTheyAreAllocated) {
  TempDir dir;
  auto r = run_shell("AFMKIT_MEMORY_LIMIT=64M afmkit scan --sample-resolution 64 --image-resolution 16384 --output t.csv",
                     dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("image_resolution = 16384 needs about"), std::string::npos) << r.err;
  // the largest value named fits: 32 MiB usable, less the 64² sample at 24 bytes a pixel, at 80 bytes a pixel
  // (two reconstructions of the topography, docs/development.md#memory-and-sizes)
  const double largest = number_after(r.err, "must be <= ");
  EXPECT_NEAR(largest, std::floor(std::sqrt((32.0 * 1048576 - 64.0 * 64 * 24) / 80.0)), 1.0) << r.err;
  r = run_shell("AFMKIT_MEMORY_LIMIT=64M afmkit scan --sample-resolution 16384 --output t.csv", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("sample_resolution = 16384 needs about"), std::string::npos) << r.err;
  // a 1 MiB GSF against a 4 MiB limit: the file's map needs about 6 MiB
  {
    std::string header = "Gwyddion Simple Field 1.0\nXRes = 512\nYRes = 512\nXReal = 0.01\nYReal = 0.01\nZUnits = m\n";
    header += std::string(4 - header.size() % 4, '\0');
    std::ofstream(dir.file("big.gsf"), std::ios::binary) << header << std::string(512 * 512 * 4, '\0');
  }
  r = run_shell("AFMKIT_MEMORY_LIMIT=4M afmkit scan --sample file --sample-file big.gsf --output t.csv", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("sample_file = big.gsf (1 MiB) needs about"), std::string::npos) << r.err;
  r = run_shell("AFMKIT_MEMORY_LIMIT=64M afmkit scan --recorded none.csv --image-resolution 16384 --output t.csv", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("image_resolution = 16384 needs about"), std::string::npos) << r.err;
  EXPECT_EQ(dir.count_files(), 1u);  // big.gsf only
}

TEST(HostileLimits, RequestsBeyondTheWorkLimitAreRefusedAtOnce) {
  TempDir dir;
  struct Case {
    const char* line;
    const char* message;
  };
  const Case cases[] = {
      {"afmkit control tf --points 1e7 --harmonics 1e5 --output t.csv", "points = 10000000 would take about"},
      {"afmkit control tune --harmonics 1000 --coarse-points 10000 --output t.csv",
       "coarse_points = 10000 would take about"},
      {"AFMKIT_WORK_LIMIT=10 afmkit tapping orbit --max-transient-periods 1e8 --quality-factor 1e9 --output t.csv",
       "max_transient_periods = 100000000 would take about"},
      {"AFMKIT_WORK_LIMIT=soon afmkit control tf --output t.csv", "AFMKIT_WORK_LIMIT = 'soon' is out of range"},
  };
  for (const Case& c : cases) {
    const auto start = std::chrono::steady_clock::now();
    const auto r = run_shell(c.line, dir);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.status, 2) << c.line << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.line << "\n" << r.err;
    EXPECT_LT(seconds, 10.0) << c.line;
    EXPECT_EQ(dir.count_files(), 0u) << c.line;
  }
  // the largest value named fits the limit: control tf with it is accepted by the same model
  const auto r = run_shell("afmkit control tf --points 1e7 --harmonics 1e5 --output t.csv", dir);
  const double largest = number_after(r.err, "must be <= ");
  ASSERT_GT(largest, 0.0) << r.err;
  EXPECT_LT(largest, 1e7);
}
