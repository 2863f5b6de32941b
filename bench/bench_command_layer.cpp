// Cost of the command layer (issue 26: "the command layer adds <= 5 % to a 1 ms command"): `tapping orbit` at a
// setting where the orbit search takes about a millisecond, run
//   * Library:       tapping::find_orbits on a model and options built once (the computation alone);
//   * Command:       the command's run on a ParamSet (declare, defaults, resolve, the keyword values, checks), the
//                    table captured and the summary document made and read as the Python module hands it over
//                    (no process start, nothing printed);
//   * CommandReused: the same with the parameters declared once and their values reset per call
//                    (ParamSet::reset_values), as the Python module runs a command again; the summary is made
//                    where it is read (Captured::take_results_maker), and not read (CommandReusedRead: read);
//   * CommandFiles:  the same writing the CSV table and its JSON sidecar (what the command line does; no process).
// bench/command_layer.py runs this program and afmkit.tapping.orbit in one run and prints the ratios.
//   build/bin/bench_command_layer --benchmark_min_time=1
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>

#include "afmkit/tapping/orbit.hpp"
#include "command.hpp"
#include "tapping_params.hpp"
#include "tapping_sim_params.hpp"

namespace {

using namespace afmkit;

/// The ~1 ms case (one thread: OMP_NUM_THREADS=1): a low quality factor (transients settle in a few periods),
/// period-1 responses only, the free oscillation (48 seeds, all converging to it). The values as keyword
/// arguments (TOML keys).
const std::map<std::string, std::string>& orbit_case() {
  static const std::map<std::string, std::string> kw = {
      {"quality_factor", "2"}, {"separation", "5"}, {"max_period_multiple", "1"}};
  return kw;
}

/// A capture as the Python module makes it: the summary document handed over (its values counted) where the
/// command makes it, not copied into the capture; from a command that makes its summary where it is read
/// (CommandOutput::finish(ResultsMaker)), the maker, kept as afmkit.Result keeps it until r.results is read, and
/// called only when `read` (the summary read: its values counted).
cli::Captured handed_over(std::size_t& values, cli::ResultsMaker& maker, bool read) {
  cli::Captured c;
  c.take_results = [&values](const nlohmann::json& document) {
    values = 0;
    for (const auto& item : document.items()) values += item.value().size();
  };
  c.take_results_maker = [&values, &maker, read](cli::ResultsMaker m) {
    maker = std::move(m);
    if (!read) return;
    values = 0;
    const nlohmann::json document = maker();
    for (const auto& item : document.items()) values += item.value().size();
  };
  return c;
}

const cli::CommandSpec& orbit_spec() {
  static const std::vector<cli::CommandSpec> specs = cli::command_specs();
  for (const cli::CommandSpec& s : specs)
    if (s.path == "tapping orbit") return s;
  throw std::logic_error("no command tapping orbit");
}

/// The ParamSet of a run as the Python module builds it (python/src/params_from_python.cpp): declared, the table
/// kept in memory (output = "", json), resolved, then the given values.
io::ParamSet declared_params(const std::string& output) {
  io::ParamSet p;
  orbit_spec().declare(p);
  p.set_default("output", output);
  p.set_default("json", "true");
  return p;
}
io::ParamSet orbit_params(const std::string& output) {
  io::ParamSet p = declared_params(output);
  p.resolve();
  for (const auto& [k, v] : orbit_case()) p.set_from_string(k, v);
  p.check_files();
  return p;
}

void Library(benchmark::State& state) {
  const io::ParamSet p = orbit_params("");
  const tapping::TappingModel model = cli::tapping_model_from(p);
  tapping::OrbitSearchOptions options;
  options.shooting = cli::shooting_options_from(p);
  options.transient = cli::transient_options_from(p);
  std::size_t orbits = 0;
  for (auto _ : state) {
    const tapping::OrbitSearchResult r = tapping::find_orbits(model, options);
    orbits = r.orbits.size();
    benchmark::DoNotOptimize(r);
  }
  state.counters["orbits"] = static_cast<double>(orbits);
}
BENCHMARK(Library)->Unit(benchmark::kMicrosecond);

// One run of the command with the summary handed over as Python takes it (`read`: and read, as r.results is); the
// rows it gave. The maker (what a Result holds) is released at the end, as Python releases a Result.
std::size_t run_once(const cli::CommandSpec& spec, const io::ParamSet& p, std::size_t& values, bool read = false) {
  cli::ResultsMaker maker;
  cli::Captured captured = handed_over(values, maker, read);
  spec.run(p, &captured);
  benchmark::DoNotOptimize(captured);
  return captured.rows.size();
}

void Command(benchmark::State& state) {
  const cli::CommandSpec& spec = orbit_spec();
  std::size_t rows = 0;
  std::size_t values = 0;
  for (auto _ : state) rows = run_once(spec, orbit_params(""), values, true);
  benchmark::DoNotOptimize(values);
  state.counters["orbits"] = static_cast<double>(rows);
}
BENCHMARK(Command)->Unit(benchmark::kMicrosecond);

// Command with the declarations made once (as the Python module does: python/src/params_from_python.cpp), the values
// reset and given again per call.
void command_reused(benchmark::State& state, bool read) {
  const cli::CommandSpec& spec = orbit_spec();
  const io::ParamSet declared = declared_params("");
  io::ParamSet p = declared;
  std::size_t rows = 0, values = 0;
  for (auto _ : state) {
    p.reset_values(declared);
    p.resolve();
    for (const auto& [k, v] : orbit_case()) p.set_from_string(k, v);
    p.check_files();
    rows = run_once(spec, p, values, read);
  }
  benchmark::DoNotOptimize(values);
  state.counters["orbits"] = static_cast<double>(rows);
}
void CommandReused(benchmark::State& state) { command_reused(state, false); }
BENCHMARK(CommandReused)->Unit(benchmark::kMicrosecond);

// CommandReused with the summary document read after each run (as r.results is when a caller reads it).
void CommandReusedRead(benchmark::State& state) { command_reused(state, true); }
BENCHMARK(CommandReusedRead)->Unit(benchmark::kMicrosecond);

// The part of Command that builds the ParamSet (declare, defaults, resolve, values, checks).
void Params(benchmark::State& state) {
  for (auto _ : state) {
    const io::ParamSet p = orbit_params("");
    benchmark::DoNotOptimize(p);
  }
}
BENCHMARK(Params)->Unit(benchmark::kMicrosecond);

// The command's run alone on a ParamSet built once (no rows kept: only the summary document is made).
void RunOnly(benchmark::State& state) {
  const cli::CommandSpec& spec = orbit_spec();
  const io::ParamSet p = orbit_params("");
  for (auto _ : state) {
    cli::Captured captured;
    captured.want_rows = false;
    spec.run(p, &captured);
    benchmark::DoNotOptimize(captured);
  }
}
BENCHMARK(RunOnly)->Unit(benchmark::kMicrosecond);

// The library call with the model built from the ParamSet on each call (as the command does).
void LibraryWithModel(benchmark::State& state) {
  const io::ParamSet p = orbit_params("");
  for (auto _ : state) {
    const tapping::TappingModel model = cli::tapping_model_from(p);
    tapping::OrbitSearchOptions options;
    options.shooting = cli::shooting_options_from(p);
    options.transient = cli::transient_options_from(p);
    benchmark::DoNotOptimize(tapping::find_orbits(model, options));
  }
}
BENCHMARK(LibraryWithModel)->Unit(benchmark::kMicrosecond);

// The library call with the progress callback the command installs (a no-op here).
void LibraryWithProgress(benchmark::State& state) {
  const io::ParamSet p = orbit_params("");
  const tapping::TappingModel model = cli::tapping_model_from(p);
  tapping::OrbitSearchOptions options;
  options.shooting = cli::shooting_options_from(p);
  options.transient = cli::transient_options_from(p);
  long periods = 0;
  options.transient.on_periods = [&periods](int n) { periods += n; };
  for (auto _ : state) benchmark::DoNotOptimize(tapping::find_orbits(model, options));
  benchmark::DoNotOptimize(periods);
}
BENCHMARK(LibraryWithProgress)->Unit(benchmark::kMicrosecond);

// The part that records the parameters as run (what every sidecar and r.params hold).
void ParamsRecord(benchmark::State& state) {
  const io::ParamSet p = orbit_params("");
  for (auto _ : state) benchmark::DoNotOptimize(p.to_json());
}
BENCHMARK(ParamsRecord)->Unit(benchmark::kMicrosecond);

void CommandFiles(benchmark::State& state) {
  const cli::CommandSpec& spec = orbit_spec();
  const std::string path = (std::filesystem::temp_directory_path() / "afmkit_bench_command_layer.csv").string();
  for (auto _ : state) {
    const io::ParamSet p = orbit_params(path);
    cli::Captured captured;
    captured.want_rows = false;
    spec.run(p, &captured);
    benchmark::DoNotOptimize(captured);
  }
  std::filesystem::remove(path);
  std::filesystem::remove(path + ".json");
}
BENCHMARK(CommandFiles)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
