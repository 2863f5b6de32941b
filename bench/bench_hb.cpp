// Harmonic-balance speed: the sampled curve (target: 10^4 points in ≤ 10 ms), single branch points, the
// branch scan of HarmonicBalance and the solutions at one separation.
#include <benchmark/benchmark.h>

#include "afmkit/tapping/harmonic_balance.hpp"

namespace {

using afmkit::impact::PiecewiseLinearLaw;
using namespace afmkit::tapping;

TappingModel example() {
  return TappingModel(Cantilever(1.0, 100.0), Drive(0.2, 0.995), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6),
                      14.5);
}

void BM_CurvePoints(benchmark::State& state) {
  const TappingModel model = example();
  HbCurveOptions o;
  o.q_min = -2.0;
  o.q_max = 1.5;
  o.points = static_cast<std::size_t>(state.range(0));
  o.include_minus = state.range(1) != 0;
  std::vector<HbPoint> out;
  out.reserve(2 * o.points);
  for (auto _ : state) {
    harmonic_balance_curve(model, o, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["points_out"] = static_cast<double>(out.size());
  state.counters["ns_per_q"] = benchmark::Counter(static_cast<double>(o.points), benchmark::Counter::kIsIterationInvariantRate |
                                                                                  benchmark::Counter::kInvert);
}
BENCHMARK(BM_CurvePoints)->Args({10000, 0})->Args({10000, 1})->Unit(benchmark::kMillisecond);

void BM_BranchPoint(benchmark::State& state) {
  const HbCoefficients c(example());
  double gap = 1e-3;
  for (auto _ : state) {
    benchmark::DoNotOptimize(evaluate_branch_at_gap(c, gap, +1));
    gap = gap * 1.0001 < 1.9 ? gap * 1.0001 : 1e-3;
  }
}
BENCHMARK(BM_BranchPoint)->Unit(benchmark::kNanosecond);

void BM_Scan(benchmark::State& state) {
  const TappingModel model = example();
  for (auto _ : state) benchmark::DoNotOptimize(HarmonicBalance(model));
}
BENCHMARK(BM_Scan)->Unit(benchmark::kMicrosecond);

void BM_SolutionsAtSeparation(benchmark::State& state) {
  const HarmonicBalance hb(example());
  for (auto _ : state) benchmark::DoNotOptimize(hb.solutions(14.5));
}
BENCHMARK(BM_SolutionsAtSeparation)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
