// Benchmarks of the seed-2 closed-loop spectra (spectrum.hpp, delay_margin.hpp, stability_chart.hpp, tuning.hpp).
//   delay margin for one (α, β)                              target ≤ 1 ms
//   200 × 200 spectral-abscissa chart on 2 threads           target ≤ 2 s (N ≤ 10, N = ∞); N = 1000: ≤ 15 s
//   robust tuning (defaults of `control tune`), N = 1000     target ≤ 20 s
//   Δ(s) and Δ'(s) of a bank of N = 1000: fast evaluator of the spectra vs loop.hpp's scaled one (ratio)
//   rightmost roots; counters: max distance to the collocation eigenvalues (80 nodes per delay) and the largest
//   final Newton correction.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "afmkit/control/dde_collocation.hpp"
#include "afmkit/control/delay_margin.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/control/stability_chart.hpp"
#include "afmkit/control/tuning.hpp"
#include "../src/control/spectra/fast_characteristic.hpp"

using namespace afmkit::control;

namespace {
constexpr double kOmega = 1.0, kGamma = 20.0;
const double kT = 2.0 * std::numbers::pi;

LoopSpec infinite_loop(double tau) { return LoopSpec(InfiniteBank(kOmega, 0.1, -0.1, kGamma), PlantKind::Static, kGamma, tau); }
LoopSpec bank_loop(double tau) {
  return LoopSpec(OscillatorBank::with_couplings(kOmega, 10, 0.1, -0.1, kGamma), PlantKind::Static, kGamma, tau);
}
LoopSpec bank1000_loop(double tau) {
  return LoopSpec(OscillatorBank::with_couplings(kOmega, 1000, 0.1, -0.1, kGamma), PlantKind::Static, kGamma, tau);
}
LoopSpec single_loop(double tau) { return LoopSpec(OscillatorBank::single(kOmega, 0.5, 0.0, kGamma), PlantKind::Static, kGamma, tau); }

void BM_DelayMarginInfinite(benchmark::State& st) {
  const LoopSpec loop = infinite_loop(0.0);
  for (auto _ : st) benchmark::DoNotOptimize(delay_margin(loop).upper);
}
BENCHMARK(BM_DelayMarginInfinite)->Unit(benchmark::kMicrosecond);

void BM_DelayMarginBank10(benchmark::State& st) {
  const LoopSpec loop = bank_loop(0.0);
  for (auto _ : st) benchmark::DoNotOptimize(delay_margin(loop).upper);
}
BENCHMARK(BM_DelayMarginBank10)->Unit(benchmark::kMicrosecond);

void BM_DelayMarginSingleE1(benchmark::State& st) {
  const LoopSpec loop = single_loop(0.0);
  for (auto _ : st) benchmark::DoNotOptimize(delay_margin(loop).upper);
}
BENCHMARK(BM_DelayMarginSingleE1)->Unit(benchmark::kMicrosecond);

void rightmost(benchmark::State& st, const LoopSpec& loop) {
  Spectrum sp;
  for (auto _ : st) sp = rightmost_roots(loop);
  double corr = 0.0;
  for (const auto& r : sp.roots) corr = std::max(corr, r.correction);
  st.counters["roots"] = static_cast<double>(sp.roots.size());
  st.counters["max_newton_correction"] = corr;
  if (!std::holds_alternative<InfiniteBank>(loop.controller)) {
    const auto ev = collocation_eigenvalues(closed_loop_dde(loop), 80);
    double dist = 0.0;
    for (const auto& r : sp.roots) {
      double d = INFINITY;
      for (auto e : ev) d = std::min(d, std::abs(e - r.value));
      dist = std::max(dist, d);
    }
    st.counters["max_distance_to_collocation"] = dist;
  }
}
void BM_RightmostRootsSingle(benchmark::State& st) { rightmost(st, single_loop(0.2 * kT)); }
void BM_RightmostRootsBank10(benchmark::State& st) { rightmost(st, bank_loop(0.1 * kT)); }
void BM_RightmostRootsInfinite(benchmark::State& st) { rightmost(st, infinite_loop(0.1 * kT)); }
BENCHMARK(BM_RightmostRootsSingle)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RightmostRootsBank10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RightmostRootsInfinite)->Unit(benchmark::kMillisecond);

void chart(benchmark::State& st, const LoopSpec& loop, double x0, double x1, double y0, double y1) {
  ChartSpec s;
  s.family = LoopFamily::from_loop(loop);
  s.x_min = x0;
  s.x_max = x1;
  s.y_min = y0;
  s.y_max = y1;
  s.x_points = s.y_points = 200;
  s.threads = 2;
  long regions = 0, mismatched = 0;
  for (auto _ : st) {
    const StabilityChart c = stability_chart(s);
    regions = static_cast<long>(c.regions.size());
    mismatched = c.mismatched_points;
  }
  st.counters["regions"] = static_cast<double>(regions);
  st.counters["mismatched_points"] = static_cast<double>(mismatched);
}
void BM_Chart200Fig2Single(benchmark::State& st) { chart(st, single_loop(0.1 * kT), -0.5, 2.0, -2.0, 1.5); }
void BM_Chart200Fig4Infinite(benchmark::State& st) { chart(st, infinite_loop(0.1 * kT), -0.1, 1.0, -0.4, 1.0); }
void BM_Chart200Bank10(benchmark::State& st) { chart(st, bank_loop(0.1 * kT), -0.1, 1.0, -0.4, 1.0); }
BENCHMARK(BM_Chart200Fig2Single)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_Chart200Fig4Infinite)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
void BM_Chart200Bank1000(benchmark::State& st) { chart(st, bank1000_loop(0.1 * kT), -0.1, 1.0, -0.4, 1.0); }
BENCHMARK(BM_Chart200Bank10)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_Chart200Bank1000)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// Δ and Δ' at N = 1000 along a vertical line: the fast evaluator of the spectra (vectorised bank sums) against
// the scaled evaluation of loop.hpp (the baseline).
template <class Eval>
void characteristic_bench(benchmark::State& st, Eval&& eval) {
  std::complex<double> s(-0.03, 0.37), acc = 0.0;
  for (auto _ : st) {
    acc += eval(s);
    s += std::complex<double>(0.0, 1.7);
    if (s.imag() > 1200.0) s.imag(0.37);
  }
  benchmark::DoNotOptimize(acc);
  st.SetItemsProcessed(st.iterations());
}
void BM_CharacteristicBank1000Fast(benchmark::State& st) {
  const LoopSpec loop = bank1000_loop(0.1 * kT);
  const afmkit::control::spectra_detail::FastCharacteristic f(loop);
  characteristic_bench(st, [&f](std::complex<double> s) {
    std::complex<double> v, d;
    f.entire(s, v, d);
    return d / v;
  });
}
void BM_CharacteristicBank1000Scaled(benchmark::State& st) {
  const LoopSpec loop = bank1000_loop(0.1 * kT);
  characteristic_bench(st, [&loop](std::complex<double> s) {
    const auto c = characteristic_scaled(loop, s);
    return c.derivative / c.value;
  });
}
BENCHMARK(BM_CharacteristicBank1000Fast)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CharacteristicBank1000Scaled)->Unit(benchmark::kMicrosecond);

// robust tuning with the window and ranges of `control tune`'s defaults
void tuning(benchmark::State& st, const LoopSpec& loop) {
  RobustTuningSpec s;
  s.family = LoopFamily::from_loop(loop);
  s.delay_max = 0.25 * kT;
  s.gain_ratio_min = 0.5;
  s.gain_ratio_max = 2.0;
  s.x_min = 0.01;
  s.x_max = 0.6;
  s.y_min = -0.24;
  s.y_max = 0.3;
  s.threads = 2;
  RobustTuning r;
  for (auto _ : st) r = robust_tuning(s);
  st.counters["alpha"] = r.x;
  st.counters["beta"] = r.y;
  st.counters["worst_decay"] = r.worst_decay;
  st.counters["certified_worst_decay"] = r.certified_worst_decay;
}
void BM_RobustTuningInfinite(benchmark::State& st) { tuning(st, infinite_loop(0.0)); }
void BM_RobustTuningBank1000(benchmark::State& st) { tuning(st, bank1000_loop(0.0)); }
BENCHMARK(BM_RobustTuningInfinite)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_RobustTuningBank1000)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
}  // namespace

BENCHMARK_MAIN();
