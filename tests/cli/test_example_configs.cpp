// The example configurations examples/configs/<command>.toml (one per leaf command, the command's words joined by
// '_'): each runs as documented in its header with its outputs redirected into a temporary folder, and every CSV
// it writes is described by its JSON sidecar: the sidecar's "columns" array names the CSV's header columns in
// order, each with a unit and a description (docs/units.md), and every row has as many cells as the header.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "cli_run.hpp"
#include "help_walk.hpp"

using namespace afmkit_test;
namespace fs = std::filesystem;

namespace {

const fs::path kConfigDir = fs::path(AFMKIT_SOURCE_DIR) / "examples" / "configs";

/// The stems of examples/configs/*.toml, sorted ("tapping_hb", ...).
std::vector<std::string> config_names() {
  std::vector<std::string> names;
  if (fs::is_directory(kConfigDir))
    for (const auto& entry : fs::directory_iterator(kConfigDir))
      if (entry.path().extension() == ".toml") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string underscored(std::string command) {
  std::replace(command.begin(), command.end(), ' ', '_');
  return command;
}

/// The command a config file is for ("tapping_hb" -> "tapping hb"), "" if none.
std::string command_of(const std::string& name) {
  for (const std::string& command : kCommands)
    if (underscored(command) == name) return command;
  return "";
}

/// Keys of a config that name files or folders the command writes: output, *_output, output_dir, and a study's
/// store and netcdf.
bool is_output_key(const std::string& key) {
  return key == "output" || key == "output_dir" || key == "store" || key == "netcdf" ||
         (key.size() > 7 && key.compare(key.size() - 7, 7, "_output") == 0);
}

/// The config's output keys with their values.
std::vector<std::pair<std::string, std::string>> output_keys(const fs::path& config) {
  std::vector<std::pair<std::string, std::string>> out;
  const toml::table table = toml::parse_file(config.string());
  for (auto&& [key, node] : table)
    if (is_output_key(std::string(key.str()))) out.emplace_back(std::string(key.str()), node.value_or(std::string()));
  return out;
}

/// The cells of each record of a CSV text (RFC 4180: a quoted cell may hold commas, quotes "" and line breaks).
std::vector<std::vector<std::string>> csv_records(const std::string& text) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string cell;
  bool quoted = false, any = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"') {
      quoted = any = true;
    } else if (c == ',') {
      record.push_back(cell);
      cell.clear();
      any = true;
    } else if (c == '\n') {
      record.push_back(cell);
      records.push_back(record);
      record.clear();
      cell.clear();
      any = false;
    } else if (c != '\r') {
      cell += c;
      any = true;
    }
  }
  if (any) {
    record.push_back(cell);
    records.push_back(record);
  }
  return records;
}

/// Runs the example config `name` with every output key redirected into `dir`/redirected/ and its input `file` or `input` (a
/// path relative to the source tree, as the header's command runs there) made absolute; returns the result.
RunResult run_config(const std::string& name, const TempDir& dir) {
  const fs::path config = kConfigDir / (name + ".toml");
  std::string args = command_of(name) + " --config '" + config.string() + "'";
  const auto table = toml::parse_file(config.string());
  for (const char* key : {"file", "input"})  // the input file keys (scan, spectroscopy fit: file; prepare: input)
    if (const auto input = table[key].value<std::string>())
      args += std::string(" --") + key + " '" + (fs::path(AFMKIT_SOURCE_DIR) / *input).string() + "'";
  for (const auto& [key, value] : output_keys(config)) {
    std::string flag = key;
    std::replace(flag.begin(), flag.end(), '_', '-');
    args += " --" + flag + " '" + (dir.path / "redirected" / fs::path(value).filename()).string() + "'";
  }
  return run_cli(args, dir);
}

/// Every CSV file below `root`, sorted.
std::vector<fs::path> csv_files(const fs::path& root) {
  std::vector<fs::path> out;
  if (fs::exists(root))
    for (const auto& e : fs::recursive_directory_iterator(root))
      if (e.is_regular_file() && e.path().extension() == ".csv") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

class ExampleConfig : public ::testing::TestWithParam<std::string> {};

}  // namespace

TEST(ExampleConfigs, OneForEveryLeafCommandAndNoOther) {
  std::set<std::string> expected;
  for (const std::string& command : leaf_commands()) expected.insert(underscored(command));
  ASSERT_FALSE(expected.empty()) << "no leaf command found by walking afmkit --help";
  const auto names = config_names();
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()), expected)
      << "examples/configs/ must hold one <command>.toml per leaf command of afmkit --help";
}

TEST_P(ExampleConfig, HeaderShowsItsCommandLineAndOutputsGoUnderOutExamples) {
  const std::string name = GetParam();
  ASSERT_NE(command_of(name), "") << name << ".toml is not named after a leaf command";
  const std::string text = source_file("examples/configs/" + name + ".toml");
  const std::string line = "#   afmkit " + command_of(name) + " --config examples/configs/" + name + ".toml";
  EXPECT_NE(text.find(line + "\n"), std::string::npos) << name << ".toml: its header must show `" << line << "`";
  EXPECT_EQ(text.rfind("# afmkit " + command_of(name) + ": ", 0), 0u)
      << name << ".toml must start with `# afmkit " << command_of(name) << ": <what it computes>`";
  const auto outputs = output_keys(kConfigDir / (name + ".toml"));
  EXPECT_FALSE(outputs.empty()) << name << ".toml sets no output path (it should write under out/examples/)";
  for (const auto& [key, value] : outputs)
    EXPECT_EQ(value.rfind("out/examples/", 0), 0u) << name << ".toml: " << key << " = '" << value << "'";
}

/// Commands whose output is not a table: the file they write instead (extension) and a text it must contain.
struct NonTableOutput {
  std::string extension, must_contain;
};
const std::map<std::string, NonTableOutput> kNonTable = {
    {"control_export", {".h", "#define AFMKIT_EXPORT_STATE_SIZE"}},  // a C header (docs/embedding.md)
    {"report", {".html", "<img "}},                                   // an HTML page with its figures
    {"study_run", {".nc", "HDF"}},  // a Zarr store (a folder) and, asked for here, the same results in NetCDF-4
    {"tapping_grid", {".zarr", "zarr_consolidated_format"}},  // a Zarr store: a folder, checked by its .zmetadata
};

/// `afmkit report` and `afmkit study run` run the Python package, which the sanitizer build does not build.
static bool runnable_here(const std::string& name) { return (name != "report" && name != "study_run") || kHasPython; }

std::vector<fs::path> files_with_extension(const fs::path& dir, const std::string& ext) {
  std::vector<fs::path> out;
  if (fs::is_directory(dir))
    for (const auto& e : fs::recursive_directory_iterator(dir))
      if (e.path().extension() == ext) out.push_back(e.path());
  return out;
}

TEST_P(ExampleConfig, RunsWithItsOutputsRedirectedAndWritesOnlyThere) {
  const std::string name = GetParam();
  if (!runnable_here(name)) GTEST_SKIP() << "no Python module in this build";
  ASSERT_NE(command_of(name), "") << name << ".toml is not named after a leaf command";
  TempDir dir;
  const RunResult r = run_config(name, dir);
  ASSERT_EQ(r.status, 0) << "afmkit " << command_of(name) << " --config examples/configs/" << name << ".toml\n"
                         << r.err;
  if (const auto it = kNonTable.find(name); it != kNonTable.end()) {
    const auto files = files_with_extension(dir.path / "redirected", it->second.extension);
    ASSERT_EQ(files.size(), 1u) << name << ": expected one " << it->second.extension << " file";
    const fs::path file = fs::is_directory(files.front()) ? files.front() / ".zmetadata" : files.front();
    EXPECT_NE(slurp(file).find(it->second.must_contain), std::string::npos) << file;
  } else {
    EXPECT_FALSE(csv_files(dir.path / "redirected").empty()) << name << ": no CSV written";
  }
  for (const auto& e : fs::directory_iterator(dir.path))
    EXPECT_EQ(e.path().filename(), "redirected") << name << " wrote " << e.path() << " outside its redirected outputs";
}

TEST_P(ExampleConfig, EveryCsvColumnHasItsUnitAndDescriptionInTheSidecar) {
  const std::string name = GetParam();
  if (!runnable_here(name)) GTEST_SKIP() << "no Python module in this build";
  ASSERT_NE(command_of(name), "") << name << ".toml is not named after a leaf command";
  TempDir dir;
  const RunResult r = run_config(name, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto files = csv_files(dir.path / "redirected");
  if (kNonTable.count(name)) {  // writes no table: nothing to describe (its file is checked above)
    EXPECT_TRUE(files.empty()) << name << " wrote a CSV";
    return;
  }
  ASSERT_FALSE(files.empty()) << name << ": no CSV written";
  for (const fs::path& csv : files) {
    const std::string file = name + ": " + csv.filename().string();
    const auto records = csv_records(slurp(csv));
    ASSERT_FALSE(records.empty()) << file << " is empty (no header row)";
    const std::vector<std::string>& header = records.front();
    const fs::path sidecar_path = csv.string() + ".json";
    ASSERT_TRUE(fs::exists(sidecar_path)) << file << " has no sidecar " << sidecar_path.filename();
    const auto sidecar = nlohmann::json::parse(slurp(sidecar_path));
    ASSERT_TRUE(sidecar.contains("columns") && sidecar["columns"].is_array())
        << file << ".json has no \"columns\" array";
    const auto& columns = sidecar["columns"];
    std::vector<std::string> described;
    for (const auto& c : columns) described.push_back(c.value("name", std::string()));
    for (const std::string& column : header) {
      const auto at = std::find(described.begin(), described.end(), column);
      if (at == described.end()) {
        ADD_FAILURE() << file << ": column '" << column << "' has no entry in the sidecar's \"columns\"";
        continue;
      }
      const auto& entry = columns[static_cast<std::size_t>(at - described.begin())];
      for (const char* field : {"unit", "description"}) {
        const bool text = entry.contains(field) && entry[field].is_string();
        const std::string value = text ? entry[field].get<std::string>() : std::string();
        // "?" is the placeholder of columns declared without units (transitional TableWriter)
        EXPECT_TRUE(text && !value.empty() && value != "?")
            << file << ": column '" << column << "' has " << (text ? "the " + std::string(field) + " '" + value + "'"
                                                                   : "no " + std::string(field) + " string");
      }
    }
    EXPECT_EQ(described, header) << file << ": the sidecar's \"columns\" must list the CSV header columns in order";
  }
}

TEST_P(ExampleConfig, EveryCsvRowHasAsManyCellsAsTheHeader) {
  const std::string name = GetParam();
  if (!runnable_here(name)) GTEST_SKIP() << "no Python module in this build";
  ASSERT_NE(command_of(name), "") << name << ".toml is not named after a leaf command";
  TempDir dir;
  const RunResult r = run_config(name, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const fs::path& csv : csv_files(dir.path / "redirected")) {
    const auto records = csv_records(slurp(csv));
    ASSERT_FALSE(records.empty()) << csv;
    int bad = 0;
    for (std::size_t i = 1; i < records.size() && bad < 3; ++i)
      if (records[i].size() != records.front().size()) {
        ++bad;
        std::string row;
        for (const std::string& cell : records[i]) row += (row.empty() ? "" : " | ") + cell;
        ADD_FAILURE() << name << ": " << csv.filename().string() << " record " << i << " has " << records[i].size()
                      << " cells for " << records.front().size() << " columns (a cell holding ',' must be quoted): "
                      << row;
      }
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, ExampleConfig, ::testing::ValuesIn(config_names()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(ExampleConfig);
