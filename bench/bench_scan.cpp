// The virtual rotational scan end to end (issue target: 10^7 samples, about 5000 turns, simulated and imaged to
// 1024 x 1024 in <= 3 s on one core, memory bounded by the image): 50 Hz spindle, 100 kHz sampling (2000 samples per
// turn), a rough tilted sample, the N = 10 controller through the real-time filter. Also the parts alone, so the
// ratios show where the time goes: the simulation with a do-nothing observer, and the controller off.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/scan/uncontrolled_saturation.hpp"
#include "afmkit/scan/virtual_scan.hpp"

namespace {
using namespace afmkit::scan;

InstrumentSpec ten_million() {
  InstrumentSpec s;
  s.spiral.sample_rate = 100e3;
  s.spiral.end_radius = 4e-3;
  s.spiral.radial_speed = 4e-3 / 100.0;  // 100 s: 10^7 samples, 5000 turns, pitch 0.8 µm
  return s;
}

const Surface& sample() {
  static const Surface s = [] {
    const double half = 4.1e-3;
    const Grid g{2048, 2048, 2 * half, 2 * half, -half, -half};
    return Surface(rough(g, RoughSpec{20e-9, 200e-6, 1}), Tilt(0.05 * std::numbers::pi / 180, 0.0));
  }();
  return s;
}

// Arg 1: imaging on a second thread (the default; CPU = the simulating thread's), 0: all on one thread (before).
void BM_ScanAndImage1024(benchmark::State& state) {
  const InstrumentSpec s = ten_million();
  sample();  // generate the sample outside the timing
  VirtualScanOptions o;
  o.compare_without_control = false;
  o.imaging_thread = state.range(0) != 0;
  for (auto _ : state) {
    VirtualScan v = run_virtual_scan(s, sample(), image_grid(s, 1024), o);
    benchmark::DoNotOptimize(v.topography_rms_error);
  }
  state.counters["samples"] = static_cast<double>(s.spiral.samples());
  state.counters["ns_per_sample"] = benchmark::Counter(static_cast<double>(s.spiral.samples()),
                                                       benchmark::Counter::kIsIterationInvariantRate |
                                                           benchmark::Counter::kInvert);
}
BENCHMARK(BM_ScanAndImage1024)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_ScanAndImageWithUncontrolledComparison(benchmark::State& state) {
  const InstrumentSpec s = ten_million();
  for (auto _ : state) {
    VirtualScan v = run_virtual_scan(s, sample(), image_grid(s, 1024));
    benchmark::DoNotOptimize(v.scan_area_gain);
  }
}
BENCHMARK(BM_ScanAndImageWithUncontrolledComparison)->Unit(benchmark::kMillisecond)->Iterations(1);

struct Nothing final : ScanObserver {
  double sink = 0;
  bool sample(const ScanSample& s) override {
    sink += s.deflection;
    return true;
  }
};

void BM_SimulationOnly(benchmark::State& state) {
  InstrumentSpec s = ten_million();
  s.controller.enabled = state.range(0) != 0;
  for (auto _ : state) {
    Nothing o;
    simulate_scan(s, sample(), o);
    benchmark::DoNotOptimize(o.sink);
  }
}
BENCHMARK(BM_SimulationOnly)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(1);


// Issue 28 §4, the parts cut, each against the old path in the same run (counters old_s, new_s, ratio = old/new and
// the agreement): the default 2048² rough sample of `afmkit scan` (the old path: the filter as plain loops, the code
// before the register-blocked passes), and the uncontrolled comparison run (the old path: from sample 0).
double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<double> rough_plain_loops(const Grid& g, const RoughSpec& spec) {  // the pre-blocking generator
  const long nx = g.x_resolution, ny = g.y_resolution;
  const auto kernel = [&](double step) {
    const long half = static_cast<long>(std::ceil(3.0 * spec.correlation_length / step));
    std::vector<double> k;
    for (long m = -half; m <= half; ++m) {
      const double d = static_cast<double>(m) * step / spec.correlation_length;
      k.push_back(std::exp(-2.0 * d * d));
    }
    return k;
  };
  const std::vector<double> kx = kernel(g.x_size / nx), ky = kernel(g.y_size / ny);
  const long px = nx + static_cast<long>(kx.size()) - 1, py = ny + static_cast<long>(ky.size()) - 1;
  std::mt19937_64 generator(spec.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> noise(static_cast<std::size_t>(px)), along_x(static_cast<std::size_t>(py * nx), 0.0),
      out(static_cast<std::size_t>(nx * ny), 0.0);
  for (long j = 0; j < py; ++j) {
    for (double& w : noise) w = normal(generator);
    double* t = along_x.data() + j * nx;
    for (std::size_t m = 0; m < kx.size(); ++m)
      for (long i = 0; i < nx; ++i) t[i] += kx[m] * noise[static_cast<std::size_t>(i) + m];
  }
  for (long j = 0; j < ny; ++j) {
    double* t = out.data() + j * nx;
    for (std::size_t m = 0; m < ky.size(); ++m) {
      const double* src = along_x.data() + (j + static_cast<long>(m)) * nx;
      for (long i = 0; i < nx; ++i) t[i] += ky[m] * src[i];
    }
  }
  double mean = 0.0;
  for (double z : out) mean += z;
  mean /= static_cast<double>(out.size());
  double squares = 0.0;
  for (double& z : out) {
    z -= mean;
    squares += z * z;
  }
  const double scale = spec.rms / std::sqrt(squares / static_cast<double>(out.size()));
  for (double& z : out) z *= scale;
  return out;
}

void BM_RoughSample2048_OldVsNew(benchmark::State& state) {  // afmkit scan's default: 2.04 × 4 mm, ξ = 100 µm
  const double half = 1.02 * 4e-3;
  const Grid g{2048, 2048, 2 * half, 2 * half, -half, -half};
  const RoughSpec spec{20e-9, 100e-6, 1};
  double old_s = 0, new_s = 0, differing = 0;
  for (auto _ : state) {
    auto start = std::chrono::steady_clock::now();
    const std::vector<double> old_map = rough_plain_loops(g, spec);
    old_s += seconds_since(start);
    start = std::chrono::steady_clock::now();
    const HeightMap new_map = rough(g, spec);
    new_s += seconds_since(start);
    for (std::size_t k = 0; k < old_map.size(); ++k)
      differing += std::memcmp(&old_map[k], &new_map.data()[k], sizeof(double)) != 0;
  }
  const auto n = static_cast<double>(state.iterations());
  state.counters["old_s"] = old_s / n;
  state.counters["new_s"] = new_s / n;
  state.counters["ratio"] = old_s / new_s;
  state.counters["differing_values"] = differing;  // 0: bit-identical
}
BENCHMARK(BM_RoughSample2048_OldVsNew)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_UncontrolledComparison_OldVsNew(benchmark::State& state) {
  const InstrumentSpec s = ten_million();
  double old_s = 0, new_s = 0, same = 1, skipped = 0;
  for (auto _ : state) {
    auto start = std::chrono::steady_clock::now();
    const UncontrolledSaturation full = first_uncontrolled_saturation_full(s, sample());
    old_s += seconds_since(start);
    start = std::chrono::steady_clock::now();
    const UncontrolledSaturation fast = first_uncontrolled_saturation(s, sample());
    new_s += seconds_since(start);
    same = same && full.radius == fast.radius && full.saturates == fast.saturates;
    skipped = static_cast<double>(fast.first_sample);
  }
  state.counters["old_s"] = old_s / static_cast<double>(state.iterations());
  state.counters["new_s"] = new_s / static_cast<double>(state.iterations());
  state.counters["ratio"] = old_s / new_s;
  state.counters["same_radius"] = same;  // 1: the same first saturated sample
  state.counters["samples_skipped"] = skipped;
}
BENCHMARK(BM_UncontrolledComparison_OldVsNew)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
