// The virtual rotational scan end to end (issue target: 10^7 samples, about 5000 turns, simulated and imaged to
// 1024 x 1024 in <= 3 s on one core, memory bounded by the image): 50 Hz spindle, 100 kHz sampling (2000 samples per
// turn), a rough tilted sample, the N = 10 controller through the real-time filter. Also the parts alone, so the
// ratios show where the time goes: the simulation with a do-nothing observer, and the controller off.
#include <benchmark/benchmark.h>

#include <numbers>

#include "afmkit/scan/sample_generators.hpp"
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

void BM_ScanAndImage1024(benchmark::State& state) {
  const InstrumentSpec s = ten_million();
  sample();  // generate the sample outside the timing
  VirtualScanOptions o;
  o.compare_without_control = false;
  for (auto _ : state) {
    VirtualScan v = run_virtual_scan(s, sample(), image_grid(s, 1024), o);
    benchmark::DoNotOptimize(v.topography_rms_error);
  }
  state.counters["samples"] = static_cast<double>(s.spiral.samples());
  state.counters["ns_per_sample"] = benchmark::Counter(static_cast<double>(s.spiral.samples()),
                                                       benchmark::Counter::kIsIterationInvariantRate |
                                                           benchmark::Counter::kInvert);
}
BENCHMARK(BM_ScanAndImage1024)->Unit(benchmark::kMillisecond)->Iterations(1);

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

}  // namespace

BENCHMARK_MAIN();
