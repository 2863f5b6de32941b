// `tapping hb` streams its curve to the file: the peak memory of a run does not grow with the number of q samples
// (it held 96 bytes a sample before), so a memory limit that refused a request then lets it run now; rows held for
// printing (--json without a file) are still checked against the memory.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <string>
#include <vector>

#include "cli_run.hpp"

using namespace afmkit_test;

namespace {

struct HbStreamRun {
  int status = -1;
  long peak_rss_kib = 0;  // of the program itself (wait4)
};

// Runs the program directly (no shell, whose memory would count) in `dir` and measures its peak resident memory.
HbStreamRun hb_stream_run(const std::vector<std::string>& args, const TempDir& dir) {
  std::vector<char*> argv;
  std::string program = AFMKIT_CLI;
  argv.push_back(program.data());
  std::vector<std::string> copy = args;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.path.c_str()) != 0) ::_exit(127);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  HbStreamRun r;
  int raw = 0;
  rusage usage{};
  if (pid > 0 && ::wait4(pid, &raw, 0, &usage) == pid) {
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.peak_rss_kib = usage.ru_maxrss;
  }
  return r;
}

}  // namespace

TEST(HbStream, PeakMemoryDoesNotGrowWithThePoints) {
  TempDir dir;
  const HbStreamRun small = hb_stream_run({"tapping", "hb", "--points", "2000", "--output", "small.csv"}, dir);
  const HbStreamRun large = hb_stream_run({"tapping", "hb", "--points", "150000", "--output", "large.csv"}, dir);
  ASSERT_EQ(small.status, 0);
  ASSERT_EQ(large.status, 0);
  // the curve held in memory took 2 × 48 bytes per sample: 14 MiB more for the large run
  EXPECT_LT(large.peak_rss_kib - small.peak_rss_kib, 4 * 1024)
      << "peak memory " << small.peak_rss_kib << " KiB at 2000 points, " << large.peak_rss_kib << " KiB at 150000";
  // every sample written: 150000 Plus/Free rows (the default q range ends beyond grazing), then the Minus rows
  const std::string csv = slurp(dir.path / "large.csv");
  EXPECT_GE(std::count(csv.begin(), csv.end(), '\n'), 150001);  // the header and a row per sample at least
}

TEST(HbStream, AMemoryLimitNoLongerRefusesAStreamedCurve) {
  TempDir dir;
  // 150000 samples held would need 14.4 MB, more than half of 20 MB (the share a request may take)
  auto r = run_shell("AFMKIT_MEMORY_LIMIT=20M afmkit tapping hb --points 150000 --output hb.csv", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  // rows printed as JSON are held: still checked
  r = run_shell("AFMKIT_MEMORY_LIMIT=20M afmkit tapping hb --points 150000 --output '' --json", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("points = 150000 needs about"), std::string::npos) << r.err;
}
