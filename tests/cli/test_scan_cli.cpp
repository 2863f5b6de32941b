// afmkit scan from the command line: the files it writes are what it says (sidecar columns and results), Gwyddion
// opens every GSF it writes (gwyddion-thumbnailer renders it) and parses its GXYZF point cloud, the GSF images read
// back into afmkit exactly, the controller buys scan area, a recorded spiral runs through the same filter, and bad
// input writes nothing.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "../scan/gwyddion_client.hpp"
#include "afmkit/scan/gsf.hpp"
#include "afmkit/scan/gxyzf.hpp"
#include "afmkit/scan/png16.hpp"
#include "afmkit/scan/virtual_scan.hpp"
#include "cli_run.hpp"

using afmkit_test::run_cli;
using afmkit_test::TempDir;

namespace {

// A small scan: 50 Hz, 400 samples per turn, 200 turns to 4 mm, 128² images.
const std::string kSmall =
    "scan --sample-rate 20000 --radial-speed 1e-3 --image-resolution 128 --sample-resolution 512 ";

nlohmann::json sidecar(const TempDir& dir, const std::string& csv) {
  std::ifstream in(dir.file(csv + ".json"));
  return nlohmann::json::parse(in);
}

TEST(ScanCli, WritesImagesGwyddionOpensAndTheControllerBuysArea) {
  TempDir dir;
  const auto r = run_cli(kSmall + "--points-output out/points.gxyzf --points-every 7 --series-output out/series.csv "
                                  "--series-every 50 --json",
                         dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto printed = nlohmann::json::parse(r.out);
  const auto meta = sidecar(dir, "out/scan/turns.csv");
  auto without_output = printed;
  without_output.erase("output");  // the printed document also says where the table went
  EXPECT_EQ(meta["results"], without_output);
  EXPECT_FALSE(printed["saturates_with_control"].get<bool>());
  EXPECT_TRUE(printed["saturates_without_control"].get<bool>());
  EXPECT_TRUE(printed["scan_area_gain_is_lower_bound"].get<bool>());
  EXPECT_GT(printed["scan_area_gain"].get<double>(), 2.5);
  EXPECT_LT(printed["loop_spectral_abscissa"].get<double>(), 0.0);
  EXPECT_EQ(meta["results"]["units"]["max_radius_without_control"], "m");
  EXPECT_EQ(meta["parameter_units"]["radial_speed"], "m/s");
  EXPECT_EQ(meta["parameter_units"]["tilt_angle"], "deg");
  EXPECT_EQ(meta["columns"][2]["name"], "deflection_first_harmonic");
  EXPECT_EQ(sidecar(dir, "out/series.csv")["columns"].size(), 10u);
  // the inverse reconstruction (the default) against the lagged one beside it (docs/scan.md#reconstruction)
  EXPECT_EQ(printed["reconstruction"], "inverse");
  EXPECT_LT(printed["error_budget"]["reconstruction"].get<double>(), 1e-6 * printed["sample_rms_height"].get<double>());
  EXPECT_DOUBLE_EQ(printed["error_budget"]["imaging_relative"].get<double>(),
                   printed["error_budget"]["imaging"].get<double>() / printed["sample_rms_height"].get<double>());
  EXPECT_GT(printed["lagged_rms_error"].get<double>(), 3 * printed["inverse_rms_error"].get<double>());  // 15 vs 3.5 nm
  EXPECT_EQ(printed["units"]["error_budget"]["noise_gain"], "dimensionless");  // a record's units under `units`

  const std::string thumbnailer = gwyddion_client::find_thumbnailer();
  ASSERT_FALSE(thumbnailer.empty()) << gwyddion_client::missing_thumbnailer_message;
  int gsf_files = 0;
  for (const std::string name : {"deflection", "topography", "topography_lagged", "truth"})
    for (const std::string suffix : {"", "_mask"}) {
      const std::string path = dir.file("out/scan/scan_" + name + suffix + ".gsf");
      ASSERT_TRUE(std::filesystem::exists(path)) << path;
      const auto t = gwyddion_client::render(thumbnailer, path, dir.file("gwy_" + name + suffix));
      EXPECT_EQ(t.exit_status, 0) << path << ": " << t.error_output;
      EXPECT_TRUE(t.png_written) << path;
      ++gsf_files;
      ASSERT_TRUE(std::filesystem::exists(dir.file("out/scan/scan_" + name + ".png")));
    }
  EXPECT_EQ(gsf_files, 8);
  // the point cloud: Gwyddion's loader accepts it (it has no image to preview), and afmkit reads it back
  const auto cloud = gwyddion_client::render(thumbnailer, dir.file("out/points.gxyzf"), dir.file("gwy_points"));
  EXPECT_TRUE(cloud.no_previewable_data()) << cloud.error_output;
  const afmkit::scan::XyzField points = afmkit::scan::read_gxyzf(dir.file("out/points.gxyzf"));
  EXPECT_EQ(points.size(), printed["point_cloud_points"].get<std::size_t>());
  EXPECT_EQ(points.channels().size(), 2u);
  {  // its topography channel is the chosen reconstruction (inverse): sample 350 m is point 50 m and series row 7 m
    std::ifstream series(dir.file("out/series.csv"));
    std::string line;
    std::getline(series, line);  // header
    long row = 0, compared = 0;
    while (std::getline(series, line)) {
      if (row % 7 == 0 && static_cast<std::size_t>(row / 7 * 50) < points.size()) {
        const double inverse = std::stod(line.substr(line.rfind(',') + 1));  // topography_inverse, the last column
        EXPECT_NEAR(points.channels()[1].values[static_cast<std::size_t>(row / 7 * 50)], inverse,
                    1e-9 * std::abs(inverse) + 1e-18) << "series row " << row;
        ++compared;
      }
      ++row;
    }
    EXPECT_GT(compared, 100);
  }

  // the GSF image reads back as written: metres, the scanned square, the mask
  const auto image = afmkit::scan::read_gsf_with_mask(dir.file("out/scan/scan_topography.gsf"),
                                                      dir.file("out/scan/scan_topography_mask.gsf"));
  EXPECT_EQ(image.map.z_unit(), "m");
  EXPECT_EQ(image.map.x_resolution(), 128);
  EXPECT_DOUBLE_EQ(image.map.x_size(), 8e-3);
  EXPECT_DOUBLE_EQ(image.map.x_offset(), -4e-3);
  EXPECT_EQ(static_cast<long>(image.map.valid_count()), printed["valid_pixels"].get<long>());
}

TEST(ScanCli, WithoutControlTheDetectorSaturatesAndTheImageHasHoles) {
  TempDir dir;
  const auto on = run_cli(kSmall + "--output \"\" --image-output \"\" --json", dir);
  const auto off = run_cli(kSmall + "--control off --output \"\" --image-output \"\" --json", dir);
  ASSERT_EQ(on.status, 0) << on.err;
  ASSERT_EQ(off.status, 0) << off.err;
  const auto a = nlohmann::json::parse(on.out), b = nlohmann::json::parse(off.out);
  EXPECT_TRUE(b["saturates_with_control"].get<bool>());
  EXPECT_NEAR(b["max_radius_with_control"].get<double>(), a["max_radius_without_control"].get<double>(), 1e-12);
  EXPECT_GT(b["saturated_fraction"].get<double>(), 0.1);
  EXPECT_LT(b["valid_pixels"].get<long>(), a["valid_pixels"].get<long>());
  EXPECT_TRUE(b["scan_area_gain"].is_null());  // no comparison run when the controller is off
  EXPECT_EQ(dir.count_files(), 0u);
}

// A detector saturated on every sample leaves no image: not a silent success but "no answer" (exit 1, status and
// note in the results, docs/commands.md#exit-status); a partly saturated scan stays ok (the test above).
TEST(ScanCli, ADetectorSaturatedEverywhereIsNoAnswer) {
  TempDir dir;
  const auto r = run_cli(kSmall + "--detector-noise 1e-3 --output \"\" --image-output \"\" --json", dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("no answer: status no_image: 0 valid pixel(s)"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["status"], "no_image");
  EXPECT_EQ(j["valid_pixels"].get<long>(), 0);
  EXPECT_TRUE(j["topography_rms_error"].is_null());
  EXPECT_GT(j["saturated_fraction"].get<double>(), 0.99);
}

TEST(ScanCli, RecordedSpiralRunsThroughTheFilter) {
  TempDir dir;
  const std::string source = std::string(AFMKIT_SOURCE_DIR) + "/examples/recorded/";
  for (const std::string file : {"spiral.csv", "spiral_index.csv"}) {
    const auto r = run_cli("scan --recorded '" + source + file + "' --image-resolution 64 --image-output out/" + file +
                               " --output out/" + file + "_turns.csv --json",
                           dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto results = nlohmann::json::parse(r.out);
    EXPECT_NEAR(results["spindle_frequency"].get<double>(), 50.0, 1e-6);
    EXPECT_NEAR(results["sample_rate"].get<double>(), 2000.0, 1e-6);
    EXPECT_GT(results["valid_pixels"].get<long>(), 2000);
    // late turns: the tilt-free first harmonic is a small fraction of the recorded one
    std::ifstream table(dir.file("out/" + file + "_turns.csv"));
    std::string line, last;
    while (std::getline(table, line)) last = line;
    double turn, radius, free, recorded;
    ASSERT_EQ(std::sscanf(last.c_str(), "%lf,%lf,%lf,%lf", &turn, &radius, &free, &recorded), 4) << last;
    EXPECT_LT(free, 0.05 * recorded) << file;
    EXPECT_TRUE(std::filesystem::exists(dir.file("out/" + file + "_tilt_free.gsf")));
  }
}

TEST(ScanCli, BadInputWritesNothing) {
  TempDir dir;
  dir.write("bad.gsf", "Gwyddion Simple Field 1.0\nXRes = 4\n");
  for (const std::string args :
       {"scan --tilt-angle 95", "scan --radial-speed 0.1", "scan --sample file --sample-file bad.gsf",
        "scan --recorded missing.csv", "scan --recorded missing.csv --bandwidth 10"}) {
    const auto r = run_cli(args + " --output out/t.csv --image-output out/img --series-output out/s.csv", dir);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("out"))) << args;
  }
}

TEST(ScanCli, ABadSampleFileIsReportedBeforeTheImagerIsBuilt) {
  // the file is read and checked first: the whole refused run takes well under the time of building the imager of
  // its 1536² image alone (sorting 2.4·10⁶ pixel centres, timed here in the same test)
  TempDir dir;
  dir.write("ragged.txt", "1 2 3\n4 5\n");
  afmkit::scan::InstrumentSpec s;
  s.spiral.sample_rate = 300e3;
  s.spiral.radial_speed = 150e-6;
  const auto start = std::chrono::steady_clock::now();
  {
    const afmkit::scan::SpiralImager imager = afmkit::scan::scan_imager(s, afmkit::scan::image_grid(s, 1536));
    EXPECT_EQ(imager.samples(), 0);
  }
  const double imager_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto run_start = std::chrono::steady_clock::now();
  const auto r = run_cli("scan --sample file --sample-file ragged.txt --sample-size 1e-2 --image-resolution 1536 "
                         "--output out/t.csv --image-output out/img", dir);
  const double run_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count();
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("ragged rows"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("out")));
  EXPECT_LT(run_seconds, 0.5 * imager_seconds) << "imager " << imager_seconds << " s";
}

}  // namespace

namespace {

// The sample from a file: a GSF (metres, its own size), an ASCII matrix and a 16-bit PNG (size and height scale
// given): a constant height h comes back in the ground-truth image as h + the tilt plane (no tilt here: h).
TEST(ScanCli, SampleFromGsfAsciiOrPng) {
  TempDir dir;
  const long n = 64;
  const afmkit::scan::Grid g{n, n, 2e-3, 2e-3, 5.0, 7.0};  // offsets are ignored: the map is centred on the axis
  afmkit::scan::write_gsf(dir.file("sample.gsf"), afmkit::scan::HeightMap(g, std::vector<double>(n * n, 3e-8)));
  std::string ascii;
  for (long j = 0; j < n; ++j) {
    for (long i = 0; i < n; ++i) ascii += i ? " 30" : "30";
    ascii += "\n";
  }
  dir.write("sample.txt", ascii);
  afmkit::scan::Grey16 grey{n, n, std::vector<std::uint16_t>(n * n, 65535)};
  {
    std::ofstream png(dir.file("sample.png"), std::ios::binary);
    png << afmkit::scan::format_png16(grey);
  }
  const std::string common = " --tilt-angle 0 --end-radius 0.9e-3 --sample-rate 20000 --image-resolution 32 "
                             "--output \"\" --json --image-output out/";
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"gsf", "scan --sample file --sample-file sample.gsf"},
      {"txt", "scan --sample file --sample-file sample.txt --sample-size 2e-3 --sample-z-scale 1e-9"},
      {"png", "scan --sample file --sample-file sample.png --sample-size 2e-3 --sample-z-scale 3e-8"}};
  for (const auto& [name, args] : runs) {
    const auto r = run_cli(args + common + name, dir);
    ASSERT_EQ(r.status, 0) << args << "\n" << r.err;
    const auto truth = afmkit::scan::read_gsf_with_mask(dir.file("out/" + name + "_truth.gsf"),
                                                        dir.file("out/" + name + "_truth_mask.gsf"));
    ASSERT_GT(truth.map.valid_count(), 100u) << name;
    for (double z : truth.map.data())
      if (std::isfinite(z)) {
        ASSERT_NEAR(z, 3e-8, 1e-7 * 3e-8) << name;  // float32 (2^-24 relative) in the files
      }
  }
}

}  // namespace
