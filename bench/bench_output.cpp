// Table output speed (target: a 10^6-row table written at >= 50 MB/s, memory bounded by a buffer). The HB
// table (5 numbers + a word per row, as `tapping hb` writes it) through io::TableWriter, against a baseline in
// the same process: the same rows through std::ofstream with 17 significant digits (the usual hand-written way).
// Counters: bytes_per_second (MB/s) and the growth of the peak resident memory during the run.
#include <benchmark/benchmark.h>

#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <string>

#include "afmkit/io/output.hpp"

namespace {

constexpr long rows = 1000000;

std::string path(const char* name) {
  return (std::filesystem::temp_directory_path() / (std::string(name) + std::to_string(::getpid()) + ".csv")).string();
}

long peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

// Values with full-length mantissas, as real results have.
inline double value(long i, int column) { return std::sin(0.001 * static_cast<double>(i) + column) * 12.3456789; }

void BM_TableWriter(benchmark::State& state) {
  const std::string file = path("afmkit_bench_table");
  const long rss_before = peak_rss_kib();
  std::size_t bytes = 0;
  for (auto _ : state) {
    afmkit::io::TableWriter out(file, {{"q", "dimensionless", "q"},
                                       {"separation", "L", "separation"},
                                       {"amplitude", "L", "amplitude"},
                                       {"offset", "L", "offset"},
                                       {"phase", "rad", "phase"},
                                       {"branch", "label", "branch"}});
    for (long i = 0; i < rows; ++i)
      out.row(value(i, 0), value(i, 1), value(i, 2), value(i, 3), value(i, 4), i % 2 ? "plus" : "minus");
    out.commit(afmkit::io::make_sidecar("bench", nlohmann::json::object()));
    bytes = std::filesystem::file_size(file);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes) * state.iterations());
  state.counters["peak_rss_growth_MiB"] = static_cast<double>(peak_rss_kib() - rss_before) / 1024.0;
  std::filesystem::remove(file);
  std::filesystem::remove(file + ".json");
}
BENCHMARK(BM_TableWriter)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_BaselineOfstream(benchmark::State& state) {
  const std::string file = path("afmkit_bench_ofstream");
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::ofstream out(file);
    out << "q,separation,amplitude,offset,phase,branch\n" << std::setprecision(17);
    for (long i = 0; i < rows; ++i)
      out << value(i, 0) << ',' << value(i, 1) << ',' << value(i, 2) << ',' << value(i, 3) << ',' << value(i, 4) << ','
          << (i % 2 ? "plus" : "minus") << '\n';
    out.close();
    bytes = std::filesystem::file_size(file);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes) * state.iterations());
  std::filesystem::remove(file);
}
BENCHMARK(BM_BaselineOfstream)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
