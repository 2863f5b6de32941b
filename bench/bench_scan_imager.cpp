// SpiralImager speed (target: 10^7 samples into a 1024 × 1024 image well under 1.5 s on one core, so that the whole
// virtual scan, simulation + imaging, fits in 3 s). 5000 turns of 2000 samples (table M = 2000), the spiral from the
// axis out to the grid's corners (every pixel filled), one channel holding a plane. The samples are generated with
// a per-turn cos/sin table (about 1 ns each; BM_GenerateOnly measures that alone).
// Counters (thread CPU time): ns_per_sample (whole run / samples), the phases in ms (construction = sorting the pixels, add, finish),
// the memory of the data structures (from their sizes) and the growth of the peak resident memory.
#include <benchmark/benchmark.h>

#include <sys/resource.h>
#include <time.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "afmkit/scan/spiral_imager.hpp"

namespace {

constexpr long kTurns = 5000;
constexpr int kPerTurn = 2000;
constexpr long kSamples = kTurns * kPerTurn;
constexpr long kResolution = 1024;
constexpr double kWidth = 10e-6;

const afmkit::scan::Grid kGrid{kResolution, kResolution, kWidth, kWidth, -kWidth / 2, -kWidth / 2};

long peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

struct Spiral {
  std::vector<double> cosine, sine;
  double pitch;
  Spiral() : cosine(kPerTurn), sine(kPerTurn), pitch(kWidth / std::numbers::sqrt2 * 1.001 / kTurns) {
    for (int k = 0; k < kPerTurn; ++k) {
      cosine[static_cast<std::size_t>(k)] = std::cos(2 * std::numbers::pi * k / kPerTurn);
      sine[static_cast<std::size_t>(k)] = std::sin(2 * std::numbers::pi * k / kPerTurn);
    }
  }
  // Sample n: angle, radius, value of the plane 0.01 x − 0.02 y.
  template <class Sink>
  void run(Sink&& sink) const {
    const double step = 2 * std::numbers::pi / kPerTurn;
    const double dr = pitch / kPerTurn;
    long n = 0;
    for (long turn = 0; turn < kTurns; ++turn)
      for (std::size_t k = 0; k < static_cast<std::size_t>(kPerTurn); ++k, ++n) {
        const double r = dr * static_cast<double>(n);
        const double value = r * (0.01 * cosine[k] - 0.02 * sine[k]);
        sink(step * static_cast<double>(n), r, value);
      }
  }
};

// CPU time of this thread [ms]: the phases are timed on one core, unaffected by other processes on the machine.
double cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

void BM_SpiralImager(benchmark::State& state) {
  const Spiral spiral;
  const long rss_before = peak_rss_kib();
  double construct_ms = 0, add_ms = 0, finish_ms = 0;
  std::size_t valid = 0;
  for (auto _ : state) {
    double t0 = cpu_ms();
    afmkit::scan::SpiralImager imager(kGrid, {"m"}, kPerTurn);
    construct_ms += cpu_ms() - t0;
    t0 = cpu_ms();
    spiral.run([&](double angle, double radius, double value) {
      const double v[1] = {value};
      imager.add(angle, radius, v);
    });
    add_ms += cpu_ms() - t0;
    t0 = cpu_ms();
    const auto maps = imager.finish();
    finish_ms += cpu_ms() - t0;
    valid = maps[0].valid_count();
    benchmark::DoNotOptimize(maps[0].data().data());
  }
  const auto runs = static_cast<double>(state.iterations());
  const double total_ms = (construct_ms + add_ms + finish_ms) / runs;
  state.counters["ns_per_sample"] = total_ms * 1e6 / static_cast<double>(kSamples);
  state.counters["construct_ms"] = construct_ms / runs;
  state.counters["add_ms"] = add_ms / runs;
  state.counters["finish_ms"] = finish_ms / runs;
  state.counters["valid_pixels"] = static_cast<double>(valid);
  const double pixels = static_cast<double>(kResolution * kResolution);
  // images (8 B/pixel/channel) + sorted radius, angle, index (20 B/pixel) + two tables; transient: the sort's
  // (radius, index) pairs (16 B/pixel, construction only) and the mask built by finish (1 B/pixel/channel).
  const double tables = 2.0 * (kPerTurn + 1) * 2 * 8;
  state.counters["structures_MiB"] = (pixels * (8 + 20) + tables) / (1024.0 * 1024.0);
  state.counters["transient_MiB"] = pixels * (16 + 1) / (1024.0 * 1024.0);
  state.counters["peak_rss_growth_MiB"] = static_cast<double>(peak_rss_kib() - rss_before) / 1024.0;
  state.SetItemsProcessed(static_cast<std::int64_t>(kSamples) * state.iterations());
}
BENCHMARK(BM_SpiralImager)->Unit(benchmark::kMillisecond)->Iterations(3);

// The same sample stream without the imager: the cost of generating it (to subtract).
void BM_GenerateOnly(benchmark::State& state) {
  const Spiral spiral;
  for (auto _ : state) {
    double sum = 0;
    spiral.run([&](double angle, double radius, double value) { sum += angle + radius + value; });
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(kSamples) * state.iterations());
}
BENCHMARK(BM_GenerateOnly)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
