// Files a user names: inputs that would hang or exhaust memory are refused, an output never replaces an input or
// another output, paths with a NUL are refused, TOML nested beyond reason is refused before it is parsed, and
// outputs are written by each writer through its own temporary and committed as a set.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/zarr_store.hpp"

namespace fs = std::filesystem;
using afmkit::InputError;
using afmkit::InvalidParameter;
using afmkit::io::ParamSet;

namespace {

struct Folder {
  fs::path path;
  explicit Folder(const std::string& name) {
    path = fs::temp_directory_path() / ("afmkit_file_safety_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Folder() { fs::remove_all(path); }
  std::string file(const std::string& name) const { return (path / name).string(); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(path / name) << text; }
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no exception)";
}

/// A command's file parameters: two inputs and three outputs (a table, a folder, a plain file).
ParamSet files() {
  ParamSet p;
  p.file("force_curve", "", "read")
      .file("separations_file", "", "read")
      .file("output", "", "table")
      .writes(afmkit::io::table_and_sidecar)
      .file("store", "", "folder")
      .writes([](const std::string& s) { return std::vector<afmkit::io::WrittenPath>{{s, true}}; })
      .file("points_output", "", "file")
      .writes();
  return p;
}

/// A pid that belonged to a process that has ended.
pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) std::_Exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

}  // namespace

// ---- inputs -------------------------------------------------------------------------------------------------------

TEST(InputFile, AFifoIsRefusedAtOnceInsteadOfBlocking) {
  const Folder dir("fifo");
  const std::string fifo = dir.file("curve.csv");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto start = std::chrono::steady_clock::now();
  const std::string m = message_of([&] { afmkit::files::read_input_file(fifo, "force curve"); });
  EXPECT_NE(m.find("force curve '" + fifo + "' is a FIFO (named pipe), not a regular file"), std::string::npos) << m;
  const std::string s = message_of([&] { afmkit::files::open_input_file(fifo, "recorded spiral"); });
  EXPECT_NE(s.find("is a FIFO"), std::string::npos) << s;
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(InputFile, ADirectoryOrADeviceIsSaidToBeOne) {
  const Folder dir("kinds");
  EXPECT_NE(message_of([&] { afmkit::files::read_input_file(dir.path.string(), "force curve"); })
                .find("is a directory, not a regular file"),
            std::string::npos);
  EXPECT_NE(message_of([&] { afmkit::files::read_input_file("/dev/zero", "force curve"); })
                .find("'/dev/zero' is a character device, not a regular file"),
            std::string::npos);
  EXPECT_NE(message_of([&] { afmkit::files::read_input_file(dir.file("none.csv"), "force curve"); })
                .find("cannot open force curve '" + dir.file("none.csv") + "': No such file or directory"),
            std::string::npos);
}

TEST(InputFile, WhatIsReadIsBoundedByTheFormatAndByTheMemoryLimit) {
  const Folder dir("size");
  dir.write("big.csv", std::string(200000, '1'));
  EXPECT_EQ(afmkit::files::read_input_file(dir.file("big.csv"), "force curve").size(), 200000u);
  EXPECT_NE(message_of([&] { afmkit::files::read_input_file(dir.file("big.csv"), "GSF file", 1000); })
                .find("more than the 1000 bytes such a file may have"),
            std::string::npos);
  ::setenv("AFMKIT_MEMORY_LIMIT", "400K", 1);  // a quarter of it: 100 KiB may be read
  const std::string m = message_of([&] { afmkit::files::read_input_file(dir.file("big.csv"), "force curve"); });
  ::unsetenv("AFMKIT_MEMORY_LIMIT");
  EXPECT_NE(m.find("force curve '" + dir.file("big.csv") + "' has 195 KiB, more than the 100 KiB this run may read"),
            std::string::npos) << m;
  EXPECT_NE(m.find("AFMKIT_MEMORY_LIMIT"), std::string::npos);
}

TEST(InputFile, TheStreamReadsTheWholeFile) {
  const Folder dir("stream");
  std::string text;
  for (int i = 0; i < 50000; ++i) text += std::to_string(i) + "\n";
  dir.write("s.csv", text);
  const auto in = afmkit::files::open_input_file(dir.file("s.csv"), "recorded spiral");
  std::stringstream back;
  back << in->rdbuf();
  EXPECT_EQ(back.str(), text);
}

// ---- parameters: outputs against inputs ----------------------------------------------------------------------------

TEST(FileRoles, AnOutputThatIsAnInputIsRefusedNamingBoth) {
  const Folder dir("same");
  dir.write("curve.csv", "data");
  ParamSet p = files();
  p.set_value("force_curve", dir.file("curve.csv"));
  p.set_value("output", dir.file("curve.csv"));
  try {
    p.check_files();
    FAIL() << "not refused";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "output");
    EXPECT_NE(std::string(e.what()).find("output = '" + dir.file("curve.csv") + "' would replace the file read as "
                                         "force_curve = '" + dir.file("curve.csv") + "'"),
              std::string::npos) << e.what();
  }
  p.set_value("output", dir.file("other.csv"));
  EXPECT_NO_THROW(p.check_files());
}

TEST(FileRoles, LinksDotsAndSidecarsAreSeenThrough) {
  const Folder dir("links");
  dir.write("curve.csv", "data");
  dir.write("list.txt", "1 2 3");
  fs::create_symlink(dir.file("curve.csv"), dir.file("link.csv"));
  ASSERT_EQ(::link(dir.file("list.txt").c_str(), dir.file("hard.txt").c_str()), 0);
  const struct {
    std::string key, value;
  } outputs[] = {{"output", dir.file("link.csv")},                      // a symbolic link to the input
                 {"points_output", dir.file("hard.txt")},               // a hard link to the other input
                 {"output", dir.path.string() + "/./sub/../curve.csv"}};  // the same path spelled otherwise
  for (std::size_t i = 0; i < 3; ++i) {
    ParamSet p = files();
    p.set_value("force_curve", dir.file("curve.csv"));
    p.set_value("separations_file", dir.file("list.txt"));
    p.set_value(outputs[i].key, outputs[i].value);
    EXPECT_THROW(p.check_files(), InvalidParameter) << outputs[i].value;
  }
  // the sidecar <output>.json of a table is an output too
  dir.write("t.csv.json", "{}");
  ParamSet p = files();
  p.set_config_path(dir.file("t.csv.json"));
  p.set_value("output", dir.file("t.csv"));
  const std::string m = message_of([&] { p.check_files(); });
  EXPECT_NE(m.find("(which writes '" + dir.file("t.csv.json") + "') would replace the file read as config"),
            std::string::npos) << m;
}

TEST(FileRoles, AnInputInsideAWrittenFolderAndTwoOutputsOnOneFileAreRefused) {
  const Folder dir("folder");
  fs::create_directories(dir.path / "store.zarr");
  dir.write("store.zarr/curve.csv", "data");
  ParamSet p = files();
  p.set_value("force_curve", dir.file("store.zarr/curve.csv"));
  p.set_value("store", dir.file("store.zarr"));
  EXPECT_THROW(p.check_files(), InvalidParameter);
  ParamSet q = files();
  q.set_value("output", dir.file("a.csv"));  // not existing yet: compared by path
  q.set_value("points_output", dir.file("a.csv.json"));
  const std::string m = message_of([&] { q.check_files(); });
  EXPECT_NE(m.find("name the same file"), std::string::npos) << m;
  EXPECT_NE(m.find("points_output"), std::string::npos) << m;
  ParamSet r = files();  // a store beside, not around, the input
  r.set_value("force_curve", dir.file("store.zarr/curve.csv"));
  r.set_value("store", dir.file("store"));
  EXPECT_NO_THROW(r.check_files());
}

TEST(FileRoles, APathWithANulIsRefusedNamingTheKey) {
  ParamSet p = files();
  const std::string m = message_of([&] { p.set_value("output", std::string("a\0b.csv", 7)); });
  EXPECT_NE(m.find("output holds a NUL character"), std::string::npos) << m;
  ParamSet q = files();
  const std::string t = message_of([&] { q.load_toml_text("output = \"a\\u0000b.csv\"\n", "c.toml"); });
  EXPECT_NE(t.find("c.toml: output holds a NUL character"), std::string::npos) << t;
  ParamSet r = files();
  r.set_config_path(std::string("c\0.toml", 7));
  EXPECT_THROW(r.resolve(), InvalidParameter);
}

// ---- TOML nesting ---------------------------------------------------------------------------------------------------

TEST(TomlNesting, DeepTableHeadersAndDottedKeysAreRefusedBeforeParsing) {
  std::string header = "quality_factor = 1\n[a", dotted = "a";
  for (int i = 0; i < 20000; ++i) header += ".a", dotted += ".a";
  header += "]\nx = 1\n";
  dotted += " = 1\n";
  for (const std::string& text : {header, dotted, "x = " + std::string(5000, '[') + std::string(5000, ']') + "\n"}) {
    ParamSet p = files();
    const std::string m = message_of([&] { p.load_toml_text(text, "deep.toml"); });
    EXPECT_NE(m.find("TOML nested deeper than 100 levels"), std::string::npos) << m.substr(0, 200);
    EXPECT_EQ(m.rfind("deep.toml:", 0), 0u) << m.substr(0, 200);
  }
  EXPECT_NE(message_of([&] { files().load_toml_text(header, "deep.toml"); }).find("deep.toml:2:"), std::string::npos);
  // dots inside strings, numbers and comments are not nesting
  std::string flat = "force_curve = '" + std::string(300, '.') + "' # " + std::string(300, '.') + "\n";
  ParamSet p = files();
  EXPECT_NO_THROW(p.load_toml_text(flat, "flat.toml"));
  ParamSet q;
  q.reals("values", {}, "numbers").unit("nm");
  std::string numbers = "values = [";
  for (int i = 0; i < 500; ++i) numbers += "1.5, ";
  EXPECT_NO_THROW(q.load_toml_text(numbers + "2.5]\n", "numbers.toml"));
}

// ---- outputs --------------------------------------------------------------------------------------------------------

TEST(OutputSafety, TwoThreadsWritingOneOutputEachLeaveAWholeTableAndItsOwnSidecar) {
  const Folder dir("threads");
  const std::string path = dir.file("t.csv");
  for (int trial = 0; trial < 5; ++trial) {
    auto writer = [&](int id) {
      afmkit::io::TableWriter out(path, {{"writer", "count", "which writer"}, {"row", "count", "row"}});
      for (int i = 0; i < 20000; ++i) out.row(id, i);
      out.commit(afmkit::io::make_sidecar("test", {{"writer", id}}));
    };
    std::thread a(writer, 1), b(writer, 2);
    a.join();
    b.join();
    const std::string text = slurp(path);
    const std::string id = text.substr(text.find('\n') + 1, 1);
    std::string expected = "writer,row\n";
    for (int i = 0; i < 20000; ++i) expected += id + "," + std::to_string(i) + "\n";
    ASSERT_EQ(text, expected) << "trial " << trial;  // one writer's table, whole
    const auto meta = nlohmann::json::parse(slurp(path + ".json"));
    EXPECT_EQ(std::to_string(meta["parameters"]["writer"].get<int>()), id);  // and its own sidecar
  }
  for (const auto& e : fs::directory_iterator(dir.path))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
}

// One folder named two ways in one set (as `control chart --output /abs/dir/t.csv --boundaries-output b.csv` from
// inside /abs/dir): locked once, so the commit does not wait for its own lock (it hung before). Run in a child
// with an alarm, so that a regression fails in seconds instead of hanging the suite.
TEST(OutputSafety, OneFolderSpeltTwoWaysIsLockedOnce) {
  const Folder dir("spelt");
  fs::create_directories(dir.path / "sub");
  const std::string plain = (dir.path / "sub" / "a.csv").string();
  const std::string detour = (dir.path / "sub" / ".." / "sub" / "b.csv").string();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::alarm(10);
    afmkit::io::OutputSet set;
    set.add(plain, "a");
    set.add(detour, "b");
    set.commit();
    std::_Exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the commit did not finish (killed by signal " << WTERMSIG(status) << ")";
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_TRUE(fs::exists(dir.path / "sub" / "a.csv"));
  EXPECT_TRUE(fs::exists(dir.path / "sub" / "b.csv"));
}

TEST(OutputSafety, ASetIsCommittedWholeOrNotAtAll) {
  const Folder dir("set");
  for (const char* name : {"a.gsf", "b.png", "c.csv"}) dir.write(name, "old");
  afmkit::io::OutputSet set;
  set.add(dir.file("a.gsf"), "new");
  set.add(dir.file("b.png"), "new");
  set.add(dir.file("c.csv"), "new");
  fs::remove(dir.path / "c.csv");
  fs::create_directories(dir.path / "c.csv" / "x");  // the last move fails (a folder is in the way)
  EXPECT_THROW(set.commit(), InputError);
  EXPECT_EQ(slurp(dir.path / "a.gsf"), "old");  // the files moved first are put back
  EXPECT_EQ(slurp(dir.path / "b.png"), "old");
  for (const auto& e : fs::directory_iterator(dir.path))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  fs::remove_all(dir.path / "c.csv");
  afmkit::io::OutputSet ok;
  ok.add(dir.file("a.gsf"), "new");
  ok.add(dir.file("c.csv"), "new");
  ok.commit();
  EXPECT_EQ(slurp(dir.path / "a.gsf"), "new");
  EXPECT_EQ(slurp(dir.path / "c.csv"), "new");
}

TEST(OutputSafety, TheTemporariesOfAKilledRunAreRemovedByTheNextRun) {
  const Folder dir("stale");
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  const pid_t dead = dead_pid(), alive = ::getppid();
  const std::string old_style = "turns.csv.tmp." + std::to_string(dead);
  const std::string new_style = "turns.csv.tmp." + std::to_string(dead) + "." + host + ".Ab12Cd";
  const std::string running = "turns.csv.tmp." + std::to_string(alive) + "." + host + ".Ab12Cd";
  const std::string other_host = "turns.csv.tmp." + std::to_string(dead) + ".elsewhere-" + host + ".Ab12Cd";
  for (const std::string& n : {old_style, new_style, running, other_host}) dir.write(n, "partial");
  afmkit::io::write_file_atomic(dir.file("turns.csv"), "new\n");
  EXPECT_FALSE(fs::exists(dir.path / old_style));
  EXPECT_FALSE(fs::exists(dir.path / new_style));
  EXPECT_TRUE(fs::exists(dir.path / running));     // a process that still runs
  EXPECT_TRUE(fs::exists(dir.path / other_host));  // a pid of another machine cannot be checked
  EXPECT_EQ(slurp(dir.path / "turns.csv"), "new\n");
}

TEST(OutputSafety, AWriteErrorSaysWhy) {
  const Folder dir("reason");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // a file size limit: the write fails as on a full disk, with the C library's reason
    std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit{4096, 4096};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    try {
      afmkit::io::TableWriter out(dir.file("t.csv"), {{"x", "count", "x"}});
      for (int i = 0; i < 100000; ++i) out.row(i);
      out.commit(nlohmann::json::object());
    } catch (const InputError& e) {
      std::_Exit(std::string(e.what()).find(std::strerror(EFBIG)) != std::string::npos ? 0 : 2);
    }
    std::_Exit(1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: no error, 2: the error without its reason";
  EXPECT_FALSE(fs::exists(dir.path / "t.csv"));
}

TEST(OutputSafety, TheFoldersOfAKilledStoreCommitAreRemovedByTheNextCommit) {
  const Folder dir("zarr");
  const pid_t dead = dead_pid();
  const fs::path tmp = dir.path / (".s.zarr.tmp." + std::to_string(dead));
  const fs::path old = dir.path / (".s.zarr.old." + std::to_string(dead));
  fs::create_directories(tmp / "x");
  fs::create_directories(old / "x");
  afmkit::io::ZarrStoreWriter store(dir.file("s.zarr"), "store");
  store.attribute("afmkit_study_format", 1);
  store.coordinate("x", {1.0, 2.0}, nlohmann::json::object());
  store.commit();
  EXPECT_TRUE(fs::exists(dir.path / "s.zarr" / ".zattrs"));
  EXPECT_FALSE(fs::exists(tmp));
  EXPECT_FALSE(fs::exists(old));
}

// issue 24 §3: an output path that is an existing folder was found only when the outputs were staged, after the
// computation (`afmkit scan --output <folder>`); check_files refuses it before anything runs, and the same kind:
// a path under a file, a device. (Folder outputs are checked by their writers, before computing too.)
TEST(FileRoles, AnOutputThatCannotBeWrittenWhereItIsNamedIsRefusedBeforeComputing) {
  const Folder dir("kinds");
  fs::create_directories(dir.path / "sub");
  dir.write("plain.txt", "x");
  const struct {
    std::string key, value, message;
  } cases[] = {{"output", dir.file("sub"), "output '" + dir.file("sub") + "' is not a regular file (a folder; output = '"},
               {"points_output", dir.file("sub"), "is not a regular file (a folder; points_output = '"},
               {"points_output", "/dev/zero", "output '/dev/zero' is not a regular file (a character device;"},
               {"output", dir.file("plain.txt/t.csv"), "its folder '" + dir.file("plain.txt") + "' is a file"},
               {"points_output", dir.file("plain.txt/a/b"), "its folder '" + dir.file("plain.txt") + "' is a file"}};
  for (const auto& c : cases) {
    ParamSet p = files();
    p.set_value(c.key, c.value);
    try {
      p.check_files();
      ADD_FAILURE() << c.key << " = " << c.value << ": not refused";
    } catch (const InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), c.key);
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    }
  }
  // what can be written is not refused: a new file in a new folder, an existing file, an existing folder as a store
  ParamSet p = files();
  p.set_value("output", dir.file("new/deeper/t.csv"));
  p.set_value("points_output", dir.file("plain.txt"));
  p.set_value("store", dir.file("sub"));
  EXPECT_NO_THROW(p.check_files());
}
