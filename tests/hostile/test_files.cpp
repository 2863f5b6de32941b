// Hostile files from the command line: an output that is an input (through links too) is refused and the input
// kept; deep TOML is refused instead of crashing; a FIFO is refused instead of waited on; messages name the file,
// the field and the pixel, and say why a write failed; a result is committed whole or not at all; the temporaries
// of a killed run are removed by the next; concurrent runs on one output leave one run's table and sidecar.
#include <gtest/gtest.h>

#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../cli/cli_run.hpp"

using afmkit_test::run_shell;
using afmkit_test::slurp;
using afmkit_test::TempDir;

namespace fs = std::filesystem;

namespace {

const std::string kCurve =
    "distance (nm), approach (nN), retract (nN)\n2, 0, 0\n1, -0.5, -0.8\n0, 0, -1\n-1, 2, 1\n-2, 5, 4\n";
const std::string kImpact = "afmkit impact --law table --force-curve curve.csv ";

std::string recorded_spiral() { return std::string(AFMKIT_SOURCE_DIR) + "/examples/recorded/spiral.csv"; }

}  // namespace

TEST(HostileFiles, AnOutputReachingAnInputThroughALinkIsRefusedAndTheInputKept) {
  TempDir dir;
  dir.write("curve.csv", kCurve);
  dir.write("q.toml", "points = 500\n");
  const std::vector<std::string> lines = {
      "ln -s curve.csv link.csv && " + kImpact + "--output link.csv",
      "ln curve.csv hard.csv && " + kImpact + "--output hard.csv",
      "mkdir sub && ln -s ../curve.csv sub/l.csv && " + kImpact + "--output sub/l.csv",
      "ln -s q.toml q.csv.json && " + kImpact + "--config q.toml --output q.csv",  // the sidecar is the config
      kImpact + "--output ./sub/../curve.csv"};
  for (const std::string& line : lines) {
    const auto r = run_shell(line, dir);
    EXPECT_EQ(r.status, 2) << line << "\n" << r.err;
    EXPECT_NE(r.err.find("would replace the file read as"), std::string::npos) << line << "\n" << r.err;
    EXPECT_EQ(slurp(dir.path / "curve.csv"), kCurve) << line;
    EXPECT_EQ(slurp(dir.path / "q.toml"), "points = 500\n") << line;
    for (const char* link : {"link.csv", "hard.csv", "sub", "q.csv.json"}) fs::remove_all(dir.path / link);
  }
  const auto ok = run_shell(kImpact + "--output out.csv", dir);  // the same run to another file works
  EXPECT_EQ(ok.status, 0) << ok.err;
}

TEST(HostileFiles, ARecordedSpiralOrASampleCannotBeAnOutput) {
  TempDir dir;
  fs::copy_file(recorded_spiral(), dir.path / "spiral.csv");
  const std::string before = slurp(dir.path / "spiral.csv");
  for (const std::string flag : {"--output", "--series-output", "--points-output"}) {
    const auto r = run_shell("afmkit scan --recorded spiral.csv --image-resolution 64 " + flag + " spiral.csv", dir);
    EXPECT_EQ(r.status, 2) << flag << "\n" << r.err;
    EXPECT_NE(r.err.find("would replace the file read as recorded = 'spiral.csv'"), std::string::npos) << r.err;
  }
  // an image of the prefix landing on the input
  const auto r = run_shell("cp spiral.csv img_deflection.png && afmkit scan --recorded img_deflection.png "
                           "--image-resolution 64 --image-output img",
                           dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("image_output = 'img' (which writes 'img_deflection.png') would replace"), std::string::npos)
      << r.err;
  EXPECT_EQ(slurp(dir.path / "spiral.csv"), before);
  EXPECT_EQ(slurp(dir.path / "img_deflection.png"), before);
}

TEST(HostileFiles, DeeplyNestedTomlIsRefusedNotACrash) {
  TempDir dir;
  std::string header = "[a", dotted = "a", inline_tables = "x = ";
  for (int i = 0; i < 100000; ++i) header += ".a", dotted += ".a";
  for (int i = 0; i < 3000; ++i) inline_tables += "{a=";
  dir.write("header.toml", header + "]\n");
  dir.write("dotted.toml", dotted + " = 1\n");
  dir.write("inline.toml", inline_tables + "1" + std::string(3000, '}') + "\n");
  for (const char* file : {"header.toml", "dotted.toml", "inline.toml"}) {
    const auto r = run_shell(std::string("afmkit tapping hb --config ") + file, dir);
    EXPECT_EQ(r.status, 2) << file << "\n" << r.err.substr(0, 300);
    EXPECT_NE(r.err.find(std::string(file) + ":1: TOML nested deeper than 100 levels"), std::string::npos)
        << r.err.substr(0, 300);
  }
}

TEST(HostileFiles, AFifoIsRefusedAtOnceAndADirectoryIsCalledOne) {
  TempDir dir;
  const auto fifo = run_shell("mkfifo f.csv && timeout 20 " + std::string(AFMKIT_CLI) +
                                  " impact --law table --force-curve f.csv; echo status $? >&2",
                              dir);
  EXPECT_NE(fifo.err.find("status 2"), std::string::npos) << fifo.err;  // 124: timed out waiting on the FIFO
  EXPECT_NE(fifo.err.find("force curve 'f.csv' is a FIFO (named pipe), not a regular file"), std::string::npos);
  const auto spiral = run_shell("timeout 20 " + std::string(AFMKIT_CLI) + " scan --recorded f.csv; echo status $? >&2",
                                dir);
  EXPECT_NE(spiral.err.find("status 2"), std::string::npos) << spiral.err;
  const auto folder = run_shell("mkdir d.csv && afmkit impact --law table --force-curve d.csv", dir);
  EXPECT_EQ(folder.status, 2);
  EXPECT_NE(folder.err.find("force curve 'd.csv' is a directory, not a regular file"), std::string::npos)
      << folder.err;
  EXPECT_EQ(folder.err.find("header"), std::string::npos) << folder.err;
}

TEST(HostileFiles, AByteOrderMarkIsNamedNotPrinted) {
  TempDir dir;
  dir.write("s.txt", "\xEF\xBB\xBF" "0.5 0.6\n0.7 x\xEF\xBB\xBF\n");  // a leading one is skipped as elsewhere
  const auto r = run_shell("afmkit tapping sweep --separations-file s.txt", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("s.txt:2: 'x<U+FEFF byte-order mark>' is not a finite number"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("\xEF\xBB\xBF"), std::string::npos);
}

TEST(HostileFiles, AFailedWriteSaysWhy) {
  TempDir dir;
  dir.write("curve.csv", kCurve);
  // a file size limit makes the write fail as a full disk would (SIGXFSZ ignored: the write returns EFBIG)
  const auto r = run_shell("trap '' XFSZ; ulimit -f 8; " + kImpact + "--points 1000000 --output big.csv", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("error while writing output file 'big.csv': File too large"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.path / "big.csv"));
  for (const auto& e : fs::directory_iterator(dir.path))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
}

/// Runs `line` in a private mount namespace where `mnt` (a folder of `dir`) is a tmpfs mounted with `options`
/// (unshare -rm: no root needed where user namespaces are allowed); status -1 when that is not possible here.
afmkit_test::RunResult with_mount(const std::string& options, const std::string& line, const TempDir& dir) {
  if (run_shell("unshare -rm true", dir).status != 0) return {-1, "", ""};
  fs::create_directories(dir.path / "mnt");
  return run_shell("unshare -rm bash -c 'mount -t tmpfs -o " + options + " none mnt && afmkit() { \"" +
                       std::string(AFMKIT_CLI) + "\" \"$@\"; }; " + line + "'",
                   dir);
}

TEST(HostileFiles, AReadOnlyOrAFullFileSystemIsCalledOne) {
  TempDir dir;
  dir.write("curve.csv", kCurve);
  const auto ro = with_mount("ro,size=1m", kImpact + "--output mnt/x.csv", dir);
  if (ro.status == -1) GTEST_SKIP() << "no user namespaces here (unshare -rm)";
  EXPECT_EQ(ro.status, 2) << ro.err;
  EXPECT_NE(ro.err.find("'" + (dir.path / "mnt").string() + "' is on a read-only file system"), std::string::npos)
      << ro.err;
  EXPECT_EQ(ro.err.find("GB are free"), std::string::npos) << ro.err;
  const auto hb = with_mount("ro,size=1m", "afmkit tapping hb --output mnt/x.csv", dir);
  EXPECT_EQ(hb.status, 2) << hb.err;
  EXPECT_NE(hb.err.find("cannot write output file 'mnt/x.csv': Read-only file system"), std::string::npos) << hb.err;
  const auto full = with_mount("size=64k", "afmkit tapping hb --points 20000 --output mnt/x.csv", dir);
  EXPECT_EQ(full.status, 2) << full.err;
  EXPECT_NE(full.err.find("'mnt/x.csv': No space left on device"), std::string::npos) << full.err;
}

TEST(HostileFiles, AValueAnImageCannotHoldNamesTheFileAndThePixel) {
  TempDir dir;
  std::ifstream in(recorded_spiral());
  std::ofstream out(dir.path / "spiral.csv");
  int data_row = 0;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != '#' && line[0] != 't' && ++data_row == 400)
      line = line.substr(0, line.rfind(',')) + ",8.39e197";  // one recorded deflection beyond float32
    out << line << "\n";
  }
  out.close();
  const auto r = run_shell("afmkit scan --recorded spiral.csv --image-resolution 64 --image-output img", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  // recorded deflections are bounded by 1 m (docs/scan.md#recorded-data): refused where they are read, naming the
  // file, its line and the column (it was the image writer's, naming the pixel)
  EXPECT_NE(r.err.find("spiral.csv:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(": column 'deflection': 8.39e+197 m is out of range: a recorded deflection must lie in "
                       "[-1, 1] m"),
            std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("data["), std::string::npos) << r.err;
  // an ASCII sample whose heights overflow when scaled
  dir.write("s.txt", "1e308 1\n1 1\n");
  const auto s = run_shell("afmkit scan --sample file --sample-file s.txt --sample-size 1e-2 --sample-z-scale 10", dir);
  EXPECT_EQ(s.status, 2) << s.err;
  // named by the file, its pixel and the key that scales it (the heights check of docs/scan.md#samples)
  EXPECT_NE(s.err.find("sample_z_scale = 10 m is out of range for s.txt: its value 1e+308 at row 1, column 1"),
            std::string::npos) << s.err;
}

TEST(HostileFiles, AScanIsCommittedWholeOrNotAtAll) {
  TempDir dir;
  fs::create_directories(dir.path / "out");
  for (const char* name : {"out/turns.csv", "out/turns.csv.json", "out/img_deflection.gsf", "out/img_deflection.png"})
    dir.write(name, "old");
  // the last image cannot be written: a link to a path under a file, which only writing finds (an output that is a
  // folder is refused before computing, by ParamSet::check_files)
  dir.write("plain.txt", "x");
  fs::create_symlink(dir.path / "plain.txt/img.png", dir.path / "out/img_tilt_free.png");
  const auto r = run_shell("afmkit scan --recorded " + recorded_spiral() +
                               " --image-resolution 64 --image-output out/img --output out/turns.csv",
                           dir);
  EXPECT_EQ(r.status, 2) << r.err;
  for (const char* name : {"out/turns.csv", "out/turns.csv.json", "out/img_deflection.gsf", "out/img_deflection.png"})
    EXPECT_EQ(slurp(dir.path / name), "old") << name << " was replaced: the result was committed in part";
  EXPECT_FALSE(fs::exists(dir.path / "out/img_tilt_free.gsf"));
  for (const auto& e : fs::recursive_directory_iterator(dir.path))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
}

TEST(HostileFiles, TheTemporariesOfAKilledRunAreRemovedByTheNextRun) {
  TempDir dir;
  dir.write("curve.csv", kCurve);
  const pid_t child = ::fork();  // a pid that has ended
  if (child == 0) std::_Exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  fs::create_directories(dir.path / "out");
  const std::string stale = "out/turns.csv.tmp." + std::to_string(child);
  dir.write(stale, std::string(100000, 'x'));
  const auto r = run_shell(kImpact + "--output out/turns.csv", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir.path / stale));
  EXPECT_TRUE(fs::exists(dir.path / "out/turns.csv"));
}

TEST(HostileFiles, ConcurrentRunsOnOneOutputLeaveOneRunsTableAndSidecar) {
  TempDir dir;
  dir.write("curve.csv", kCurve);
  for (int trial = 0; trial < 8; ++trial) {
    const auto r = run_shell(kImpact + "--points 3000 --output o.csv & " + kImpact + "--points 5000 --output o.csv & wait",
                             dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto meta = nlohmann::json::parse(slurp(dir.path / "o.csv.json"));
    std::ifstream table(dir.path / "o.csv");
    long lines = 0;
    for (std::string line; std::getline(table, line);) ++lines;
    const long points = meta["parameters"]["points"].get<long>();
    EXPECT_GE(lines - 1, points) << "trial " << trial << ": the table of one run beside the sidecar of the other";
    EXPECT_LT(lines - 1, points + 1000) << "trial " << trial;
  }
}
