// The streaming table writer: round-trip text, atomic placement, streaming (bounded memory), sidecars.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include <csignal>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"

namespace fs = std::filesystem;
using afmkit::io::TableWriter;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("afmkit_test_output_" + name + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

std::string read_output(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Columns named `names`, each a dimensionless test column.
std::vector<afmkit::io::Column> cols(std::initializer_list<const char*> names) {
  std::vector<afmkit::io::Column> c;
  for (const char* n : names) c.push_back({n, "dimensionless", std::string("test column ") + n});
  return c;
}

bool any_temporary(const fs::path& dir) {
  for (const auto& f : fs::directory_iterator(dir))
    if (f.path().string().find(".tmp.") != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(TableWriter, DoublesRoundTripBitExactAndCellsHaveTheirText) {
  const fs::path dir = fresh_dir("roundtrip");
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-300, 300);
  std::vector<double> values;
  for (int i = 0; i < 2000; ++i) values.push_back(std::ldexp(mantissa(rng), exponent(rng)));
  values.push_back(0.1);
  values.push_back(-0.0);
  values.push_back(std::numeric_limits<double>::denorm_min());
  {
    TableWriter out((dir / "sub/t.csv").string(), cols({"x", "n", "flag", "name"}));
    for (std::size_t i = 0; i < values.size(); ++i) out.row(values[i], static_cast<long>(i) - 5, i % 2 == 0, "abc");
    out.row(std::numeric_limits<double>::quiet_NaN(), 0L, false, "undefined");
    EXPECT_EQ(out.size(), values.size() + 1);
    out.commit(afmkit::io::make_sidecar("test", {{"x", 1}}, {{"rows", values.size() + 1}}));
  }
  std::ifstream in(dir / "sub/t.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,n,flag,name");
  for (std::size_t i = 0; i < values.size(); ++i) {
    ASSERT_TRUE(std::getline(in, line));
    std::istringstream row(line);
    std::string x, n, flag, name;
    std::getline(row, x, ',');
    std::getline(row, n, ',');
    std::getline(row, flag, ',');
    std::getline(row, name, ',');
    const double back = std::strtod(x.c_str(), nullptr);
    EXPECT_EQ(std::memcmp(&back, &values[i], sizeof back), 0) << x;
    EXPECT_EQ(std::stol(n), static_cast<long>(i) - 5);
    EXPECT_EQ(flag, i % 2 == 0 ? "1" : "0");
    EXPECT_EQ(name, "abc");
  }
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "nan,0,0,undefined");  // the one spelling of "undefined" (docs/conventions.md)
  EXPECT_FALSE(std::getline(in, line));
  const auto meta = nlohmann::json::parse(read_output(dir / "sub/t.csv.json"));
  EXPECT_EQ(meta["results"]["rows"], values.size() + 1);
  EXPECT_EQ(meta["command"], "test");
  EXPECT_FALSE(any_temporary(dir / "sub"));
  fs::remove_all(dir);
}

TEST(TableWriter, RowWidthIsChecked) {
  const fs::path dir = fresh_dir("width");
  TableWriter out((dir / "t.csv").string(), cols({"a", "b"}));
  EXPECT_THROW(out.row(1.0), std::logic_error);
  EXPECT_THROW(out.row(1.0, 2.0, 3.0), std::logic_error);
  fs::remove_all(dir);
}

TEST(TableWriter, AbandonedWriterLeavesNothingAndKeepsTheOldFile) {
  const fs::path dir = fresh_dir("abandon");
  fs::create_directories(dir);
  { std::ofstream(dir / "t.csv") << "old\n"; }
  try {
    TableWriter out((dir / "t.csv").string(), cols({"a"}));
    for (int i = 0; i < 100000; ++i) out.row(i * 0.5);
    throw std::runtime_error("interrupted");  // e.g. a numerical failure half way
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(read_output(dir / "t.csv"), "old\n");
  EXPECT_FALSE(fs::exists(dir / "t.csv.json"));
  EXPECT_FALSE(any_temporary(dir));
  fs::remove_all(dir);
}

TEST(TableWriter, RowsAreStreamedToDiskNotHeldInMemory) {
  // Before commit, all but the last buffer of the rows must already be in the temporary file.
  const fs::path dir = fresh_dir("stream");
  TableWriter out((dir / "t.csv").string(), cols({"a", "b", "c"}));
  std::size_t bytes = 6;  // header "a,b,c\n"
  for (int i = 0; i < 200000; ++i) {
    out.row(i + 0.25, i, true);
    bytes += std::to_string(i + 0.25).size() - 4 /* "0000" of to_string */ + std::to_string(i).size() + 4;
  }
  fs::path temporary;
  for (const auto& f : fs::directory_iterator(dir))
    if (f.path().string().find(".tmp.") != std::string::npos) temporary = f.path();
  ASSERT_FALSE(temporary.empty());
  EXPECT_GE(fs::file_size(temporary) + (1u << 16), bytes);
  EXPECT_FALSE(fs::exists(dir / "t.csv"));  // not in place before commit
  out.commit(afmkit::io::make_sidecar("test", nlohmann::json::object()));
  EXPECT_EQ(fs::file_size(dir / "t.csv"), bytes);
  fs::remove_all(dir);
}

TEST(TableWriter, UnwritableTargetIsAnInputError) {
  EXPECT_THROW(TableWriter("/proc/afmkit_cannot_write/t.csv", cols({"a"})), afmkit::InputError);
}

TEST(TableWriter, ATerminatingSignalRemovesTheTemporaries) {
  const fs::path dir = fresh_dir("signal");
  fs::create_directories(dir);
  const std::string path = (dir / "out.csv").string();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the child writes half a table and is terminated by SIGTERM
    afmkit::io::remove_temporaries_on_signal();
    TableWriter out(path, cols({"a"}));
    for (int i = 0; i < 100000; ++i) out.row(i);  // flushed to the temporary as it goes
    std::raise(SIGTERM);
    std::_Exit(3);  // not reached
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));  // ended by the signal, as without the handler
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  int left = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    ++left;
    ADD_FAILURE() << "left behind: " << e.path();
  }
  EXPECT_EQ(left, 0);
  fs::remove_all(dir);
}

TEST(TableWriter, ANonRegularTargetIsRefusedAndASymbolicLinkIsFollowed) {
  const fs::path dir = fresh_dir("targets");
  fs::create_directories(dir);
  const std::string fifo = (dir / "fifo.csv").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(TableWriter(fifo, cols({"a"})), afmkit::InputError);
  EXPECT_THROW(TableWriter(dir.string(), cols({"a"})), afmkit::InputError);  // a directory
  // a link to a file that does not exist yet: the file is created, the link stays a link
  fs::create_directories(dir / "data");
  fs::create_symlink("data/real.csv", dir / "link.csv");
  {
    TableWriter out((dir / "link.csv").string(), cols({"a"}));
    out.row(1.5);
    out.commit(nlohmann::json::object());
  }
  EXPECT_TRUE(fs::is_symlink(dir / "link.csv"));
  EXPECT_EQ(read_output(dir / "data" / "real.csv"), "a\n1.5\n");
  EXPECT_TRUE(fs::exists(dir / "link.csv.json"));
  fs::remove_all(dir);
}

TEST(TableWriter, TheSidecarDescribesEveryColumnAndAColumnNeedsAUnit) {
  const fs::path dir = fresh_dir("columns");
  {
    TableWriter out((dir / "t.csv").string(), {{"separation", "nm", "separation l"}, {"phase", "rad", "phase φ"}});
    out.row(1.0, 0.5);
    out.commit(afmkit::io::make_sidecar("test", nlohmann::json::object()));
  }
  const auto meta = nlohmann::json::parse(read_output(dir / "t.csv.json"));
  ASSERT_EQ(meta["columns"].size(), 2u);
  EXPECT_EQ(meta["columns"][0], (nlohmann::json{{"name", "separation"}, {"unit", "nm"}, {"description", "separation l"}}));
  EXPECT_EQ(meta["columns"][1]["unit"], "rad");
  EXPECT_THROW(TableWriter((dir / "u.csv").string(), std::vector<afmkit::io::Column>{{"separation", "", "separation l"}}), std::logic_error);
  EXPECT_THROW(TableWriter((dir / "u.csv").string(), std::vector<afmkit::io::Column>{{"separation", "nm", ""}}), std::logic_error);
  fs::remove_all(dir);
}

TEST(JsonConvention, NotDefinedIsNullAndInfiniteIsASignedString) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const nlohmann::json in = {{"a", nan}, {"b", {1.5, inf, -inf}}, {"c", {{"d", nan}}}, {"e", "text"}, {"f", 2}};
  const nlohmann::json out = afmkit::io::finite_json(in);
  EXPECT_TRUE(out["a"].is_null());
  EXPECT_EQ(out["b"], (nlohmann::json{1.5, "inf", "-inf"}));
  EXPECT_TRUE(out["c"]["d"].is_null());
  EXPECT_EQ(out["e"], "text");
  EXPECT_EQ(out["f"], 2);
  // what nlohmann alone would write: both as null (the distinction would be lost)
  EXPECT_EQ(nlohmann::json(inf).dump(), "null");
  EXPECT_EQ(nlohmann::json::parse(afmkit::io::json_text(in))["b"][1], "inf");
}

TEST(TableWriter, TextCellsWithCommasOrQuotesAreQuotedAsRfc4180) {
  const fs::path dir = fresh_dir("quote");
  {
    TableWriter out((dir / "t.csv").string(), cols({"name", "x"}));
    out.row("plain", 1.0);
    out.row("bank N=10, rejected 1,3", 2.0);
    out.row("say \"hi\"", 3.0);
    out.commit(afmkit::io::make_sidecar("test", nlohmann::json::object()));
  }
  EXPECT_EQ(read_output(dir / "t.csv"), "name,x\nplain,1\n\"bank N=10, rejected 1,3\",2\n\"say \"\"hi\"\"\",3\n");
  fs::remove_all(dir);
}

TEST(TableWriter, EveryNaNIsWrittenNanAndInfinitiesInf) {
  // A NaN with its sign bit set (what 0·inf or inf − inf give on x86) printed as "-nan" by fmt: the table must
  // still spell it `nan` (docs/conventions.md#undefined-values).
  const fs::path dir = fresh_dir("nan");
  const double negative_nan = -std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(std::signbit(negative_nan));
  volatile double inf = std::numeric_limits<double>::infinity();
  const double computed = inf - inf;  // sign as the hardware gives it
  {
    TableWriter out((dir / "t.csv").string(), cols({"a", "b", "c", "d"}));
    out.row(negative_nan, computed, inf, -static_cast<double>(inf));
    out.commit(afmkit::io::make_sidecar("test", {{"x", 1}}));
  }
  EXPECT_EQ(read_output(dir / "t.csv"), "a,b,c,d\nnan,nan,inf,-inf\n");
  fs::remove_all(dir);
}
