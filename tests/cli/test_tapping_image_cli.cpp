// afmkit tapping image from the command line: every image it writes is a GSF that Gwyddion renders
// (gwyddion-thumbnailer) and that reads back into afmkit as written, with its PNG preview beside it; the sidecar's
// results carry their units and agree with the per-line table; a flat sample images zero height at the set-point.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "../scan/gwyddion_client.hpp"
#include "afmkit/scan/gsf.hpp"
#include "cli_run.hpp"

using afmkit_test::run_cli;
using afmkit_test::TempDir;

namespace {

const std::string kTappingImageSmall = "tapping image --pixels 16 --lines 6 --map-points 60 --quiet ";

TEST(TappingImageCli, WritesEveryImageGwyddionRendersAndTheSidecarHasUnits) {
  TempDir dir;
  const auto r = run_cli(kTappingImageSmall + "--sample steps --steps-height 1e-9 --json", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto printed = nlohmann::json::parse(r.out);
  std::ifstream in(dir.file("out/tapping_image/lines.csv.json"));
  const auto meta = nlohmann::json::parse(in);
  EXPECT_EQ(meta["results"]["units"]["trace_height_rms_error"], "m");
  EXPECT_EQ(meta["results"]["units"]["max_peak_force"], "N");
  EXPECT_EQ(meta["parameter_units"]["scan_size"], "m");
  EXPECT_EQ(meta["columns"][0]["name"], "line");
  const double fractions = printed["fraction_free"].get<double>() + printed["fraction_attractive"].get<double>() +
                           printed["fraction_repulsive"].get<double>();
  EXPECT_NEAR(fractions, 1.0, 1e-12);
  // the table: one row per line and direction
  std::ifstream csv(dir.file("out/tapping_image/lines.csv"));
  std::string line;
  int rows = -1;
  while (std::getline(csv, line))
    if (!line.empty() && line[0] != '#') ++rows;
  EXPECT_EQ(rows, 12);

  const std::string thumbnailer = gwyddion_client::find_thumbnailer();
  ASSERT_FALSE(thumbnailer.empty()) << gwyddion_client::missing_thumbnailer_message;
  int images = 0;
  for (const std::string channel : {"height", "error", "phase", "power", "peak_force", "regime"})
    for (const std::string direction : {"_trace", "_retrace"}) {
      const std::string stem = dir.file("out/tapping_image/image_" + channel + direction);
      ASSERT_TRUE(std::filesystem::exists(stem + ".gsf")) << stem;
      ASSERT_TRUE(std::filesystem::exists(stem + ".png")) << stem;
      const auto t = gwyddion_client::render(thumbnailer, stem + ".gsf", dir.file("gwy_" + channel + direction));
      EXPECT_EQ(t.exit_status, 0) << stem << ": " << t.error_output;
      EXPECT_TRUE(t.png_written) << stem;
      const afmkit::scan::GsfField f = afmkit::scan::read_gsf(stem + ".gsf");
      EXPECT_EQ(f.map.x_resolution(), 16);
      EXPECT_EQ(f.map.y_resolution(), 6);
      ++images;
    }
  EXPECT_EQ(images, 12);
  EXPECT_TRUE(std::filesystem::exists(dir.file("out/tapping_image/image_truth.gsf")));
  // the truth as written is the steps sample: terraces 250 nm wide (the default steps_width), 1 nm apart, over the
  // 1 µm scan centred on x = 0: floor(x / 250 nm) from -2 to 1, four terraces spanning 3 nm
  const afmkit::scan::GsfField truth = afmkit::scan::read_gsf(dir.file("out/tapping_image/image_truth.gsf"));
  double lo = 1, hi = -1;
  for (double v : truth.map.data()) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  EXPECT_NEAR(hi - lo, 3e-9, 1e-15);
}

TEST(TappingImageCli, AFlatSampleImagesZeroHeightAtTheSetPoint) {
  TempDir dir;
  const auto r = run_cli(kTappingImageSmall + "--sample flat --output '' --image-output '' --json", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto printed = nlohmann::json::parse(r.out);
  EXPECT_LT(printed["trace_height_rms_error"].get<double>(), 1e-15);
  EXPECT_LT(printed["max_amplitude_error"].get<double>(), 1e-15);
  EXPECT_EQ(printed["regime_switches_per_line"].get<double>(), 0.0);
  EXPECT_EQ(dir.count_files(), 0u);
}

TEST(TappingImageCli, TheSetPointSweepsScansInParallelAreEachTheScanAlone) {
  // the sweep's set-points are scanned in parallel (OpenMP), each with its own engine: the one at the main scan's
  // set-point gives the main scan's results bit for bit, whichever thread ran it and beside whichever others
  TempDir dir;
  const auto r = run_cli(kTappingImageSmall + "--sample steps --steps-height 1e-9 --setpoint 0.8 "
                         "--setpoint-sweep 0.7,0.8,0.75,0.8 --output '' --image-output '' --json", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto printed = nlohmann::json::parse(r.out);
  const auto& sweep = printed["setpoint_sweep"];
  ASSERT_EQ(sweep.size(), 4u);
  for (std::size_t k : {std::size_t{1}, std::size_t{3}}) {
    EXPECT_EQ(sweep[k]["setpoint"].get<double>(), 0.8);
    EXPECT_EQ(sweep[k]["trace_height_rms_error"].get<double>(), printed["trace_height_rms_error"].get<double>());
    EXPECT_EQ(sweep[k]["max_peak_force"].get<double>(), printed["max_peak_force"].get<double>());
    EXPECT_EQ(sweep[k]["engaged_separation"].get<double>(), printed["engaged_separation"].get<double>());
  }
  EXPECT_EQ(sweep[0]["setpoint"].get<double>(), 0.7);  // in the list's order
  EXPECT_EQ(sweep[2]["setpoint"].get<double>(), 0.75);
  EXPECT_NE(sweep[0]["engaged_separation"].get<double>(), sweep[2]["engaged_separation"].get<double>());
}

}  // namespace
