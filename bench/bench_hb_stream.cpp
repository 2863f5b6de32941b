// `tapping hb` as it writes its table (issue 28 §6: 10^6 rows with the CSV ≤ 0.5 s, memory bounded by a chunk):
// the closed-form curve of the default law (q in [-1, 1.5], 725000 refined samples: 10^6 rows with both
// branches) sampled and written through io::TableWriter as the command writes it. Baseline in the same run: the
// curve held in memory (harmonic_balance_curve, 96 bytes a sample) and then written. Counters: rows, rows per
// second, growth of the peak resident memory; at the end the ratio streamed/held and whether both files are
// byte-identical.
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <span>
#include <string>

#include <benchmark/benchmark.h>

#include "afmkit/io/output.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"

namespace {

using namespace afmkit;
using namespace afmkit::tapping;

const TappingModel hbs_model(Cantilever(1.0, 100.0), Drive(0.2, 0.995),
                             impact::PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6), 0.0);

HbCurveOptions hbs_options() {
  HbCurveOptions o;
  o.q_min = -1.0;
  o.q_max = 1.5;
  o.points = 725000;  // 1.0·10^6 rows (the "−" branch exists on part of the range)
  return o;
}

std::string hbs_path(const char* name) {
  return (std::filesystem::temp_directory_path() / (std::string(name) + std::to_string(::getpid()) + ".csv")).string();
}

long hbs_peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

std::vector<io::Column> hbs_columns() {
  return {{"q", "dimensionless", "q"}, {"separation", "L", "l"}, {"amplitude", "L", "B"},
          {"offset", "L", "A"},       {"phase", "rad", "phase"}, {"branch", "label", "branch"}};
}

void hbs_rows(io::TableWriter& out, std::span<const HbPoint> points) {  // the cells of apps/tapping_tables.cpp hb_table
  for (const HbPoint& p : points)
    out.row(p.q, p.separation, p.amplitude, p.offset, p.phase, branch_name(p.branch));
}

double held_seconds = 0.0, streamed_seconds = 0.0;

void BM_HbHeldThenWritten(benchmark::State& state) {  // the baseline: as `tapping hb` did before
  const std::string file = hbs_path("afmkit_bench_hb_held");
  const long rss = hbs_peak_rss_kib();
  std::size_t rows = 0;
  for (auto _ : state) {
    io::TableWriter out(file, hbs_columns());
    const std::vector<HbPoint> curve = harmonic_balance_curve(hbs_model, hbs_options());
    hbs_rows(out, curve);
    rows = out.size();
    out.commit(io::make_sidecar("bench", nlohmann::json::object()));
  }
  state.counters["rows"] = static_cast<double>(rows);
  state.counters["rows_per_second"] = benchmark::Counter(static_cast<double>(rows), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["peak_rss_growth_MiB"] = static_cast<double>(hbs_peak_rss_kib() - rss) / 1024.0;
}

void BM_HbStreamed(benchmark::State& state) {
  const std::string file = hbs_path("afmkit_bench_hb_streamed");
  const long rss = hbs_peak_rss_kib();
  std::size_t rows = 0;
  for (auto _ : state) {
    io::TableWriter out(file, hbs_columns());
    harmonic_balance_curve_chunks(hbs_model, hbs_options(), [&](std::span<const HbPoint> chunk) { hbs_rows(out, chunk); });
    rows = out.size();
    out.commit(io::make_sidecar("bench", nlohmann::json::object()));
  }
  state.counters["rows"] = static_cast<double>(rows);
  state.counters["rows_per_second"] = benchmark::Counter(static_cast<double>(rows), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["peak_rss_growth_MiB"] = static_cast<double>(hbs_peak_rss_kib() - rss) / 1024.0;
}
// streamed first: the held run's peak would otherwise hide the streamed one's
BENCHMARK(BM_HbStreamed)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_HbHeldThenWritten)->Unit(benchmark::kMillisecond)->Iterations(5);

class HbsReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration || run.error_occurred) continue;
      const double s = run.GetAdjustedRealTime() / benchmark::GetTimeUnitMultiplier(run.time_unit);
      if (run.run_name.function_name == "BM_HbStreamed") streamed_seconds = s;
      if (run.run_name.function_name == "BM_HbHeldThenWritten") held_seconds = s;
    }
  }
};

std::string hbs_slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  HbsReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const std::string a = hbs_path("afmkit_bench_hb_streamed"), b = hbs_path("afmkit_bench_hb_held");
  const bool identical = hbs_slurp(a) == hbs_slurp(b);
  std::printf("\nstreamed %.3f s, held then written %.3f s: ratio %.2f; tables byte-identical: %s (target: <= 0.5 s "
              "for 10^6 rows)\n",
              streamed_seconds, held_seconds, held_seconds > 0 ? streamed_seconds / held_seconds : 0.0,
              identical ? "yes" : "NO");
  for (const std::string& f : {a, b}) {
    std::filesystem::remove(f);
    std::filesystem::remove(f + ".json");
  }
  benchmark::Shutdown();
  return identical ? 0 : 1;
}
