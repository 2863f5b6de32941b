// Hostile runs of the Python-backed commands from the command line (issue 24 §3): `afmkit study run` with study
// files whose [run] table or axes are wrong in kind or point where nothing can be written. Each must exit 2 with a
// message naming the study file and the field, print no Python traceback and leave nothing behind.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "../cli/cli_run.hpp"
#include "../cli/help_walk.hpp"

using afmkit_test::run_cli;
using afmkit_test::TempDir;

namespace {

const std::string kStudy =
    "computation = \"tapping.hb\"\noutputs = [\"free_amplitude\"]\n[parameters]\npoints = 50\n[axes]\n";

std::set<std::string> names(const TempDir& dir) {
  std::set<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(dir.path)) out.insert(e.path().filename().string());
  return out;
}

struct Case {
  const char* axes_and_run;  // appended to kStudy
  const char* message;       // must appear on standard error
};

}  // namespace

TEST(HostilePython, StudyFilesThatCannotRunAreRefusedBeforeAnythingIsWritten) {
  if (!afmkit_test::kHasPython)
    GTEST_SKIP() << "the study runner is the Python package, which this build (sanitizers) does not have";
  const Case cases[] = {
      {"quality_factor = [true, false]\n", "axes.quality_factor[0] = True: a boolean is not an axis value"},
      {"quality_factor = [50.0, [60.0, 70.0]]\n", "axes.quality_factor[1] is a nested list"},
      {"quality_factor = { start = 1, stop = 2, points = 1000000000000 }\n", "axes.quality_factor"},
      {"quality_factor = [50.0, 100.0]\n[run]\nstore = 5\n", "run.store = 5 is not allowed: must be a string"},
      {"quality_factor = [50.0, 100.0]\n[run]\nnetcdf = 7\n", "run.netcdf = 7 is not allowed"},
      {"quality_factor = [50.0, 100.0]\n[run]\nstore = \"plain/s.zarr\"\n", "store"},         // below a file
      {"quality_factor = [50.0, 100.0]\n[run]\nstore = \"plain\"\n", "exists and is not a folder"},
      {"quality_factor = [50.0, 100.0]\n[run]\nstore = \"s.zarr\"\nnetcdf = \"plain/r.nc\"\n", "netcdf"},
      {"quality_factor = [50.0, 100.0]\n[run]\nstore = \"s.zarr\"\nnetcdf = \".\"\n", "netcdf = '.': must name a file"},
      {"quality_factor = [50.0, 100.0]\n[run]\nstore = \"s.zarr\"\nscheduler = \"later\"\n", "scheduler = 'later'"},
  };
  for (const Case& c : cases) {
    TempDir dir;
    dir.write("study.toml", kStudy + c.axes_and_run);
    dir.write("plain", "a file, not a folder");
    const auto r = run_cli("study run study.toml --quiet", dir);
    EXPECT_EQ(r.status, 2) << c.axes_and_run << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.axes_and_run << r.err;
    EXPECT_NE(r.err.find("study.toml"), std::string::npos) << r.err;  // names the file
    EXPECT_EQ(r.err.find("Traceback"), std::string::npos) << r.err;
    EXPECT_EQ(names(dir), (std::set<std::string>{"plain", "study.toml"})) << c.axes_and_run;
  }
}

TEST(HostilePython, AStudyFileThatIsNotUtf8IsNamedWithItsLine) {
  if (!afmkit_test::kHasPython)
    GTEST_SKIP() << "the study runner is the Python package, which this build (sanitizers) does not have";
  TempDir dir;
  dir.write("latin1.toml", kStudy + "quality_factor = [50.0, 100.0]\n# r\xe9sum\xe9\n");
  const auto r = run_cli("study run latin1.toml", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("latin1.toml' is not UTF-8 text: byte 0xe9 at line 7"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("Traceback"), std::string::npos) << r.err;
}
