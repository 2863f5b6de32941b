// Speed of continuation in the drive frequency (issue 27, "frequency continuation of 500 points ≤ 1 s,
// piecewise-linear law"): a resonance curve with contact — the attractive piecewise-linear law of seed-1 eq. 26
// (K_a = 10, K_b = 8, F_a = 1, F_b = 2 per unit mass), ω_n = 1, Q = 100, Γ = 0.2 (free amplitude 20 at resonance),
// l = 14 — so that the branch folds twice and has an unstable middle part. Both the pseudo-arclength continuation
// (500 points, metrics and harmonic balance of every point as `afmkit tapping sweep --mode continuation` computes
// them) and the instrument sweep (500 frequencies down, then 500 up, jumps located), each on one core and on two.
#include <benchmark/benchmark.h>
#include <omp.h>

#include "afmkit/tapping/continuation.hpp"
#include "afmkit/tapping/sweep.hpp"

namespace {

using namespace afmkit;
using namespace afmkit::tapping;

TappingModel resonance_model() {
  return {Cantilever(1.0, 100.0), Drive(0.2, 1.0), impact::ForceLaw(impact::PiecewiseLinearLaw(10.0, 8.0, 1.0, 2.0)),
          14.0};
}

void BM_FrequencyContinuation500(benchmark::State& state, bool parallel) {
  const TappingModel model = resonance_model();
  ContinuationOptions options;
  options.max_points = 500;
  // (from ω = 0.997, above the corner at 0.9949 where the contact branch turns non-smoothly) steps of at most 0.1
  // (of the arclength, a length in L): 500 points pass both folds and the grazing hop (834 points to ω = 1.1)
  options.max_step = 0.1;
  options.parallel = parallel;
  const int threads = omp_get_max_threads();
  if (!parallel) omp_set_num_threads(1);
  ContinuationResult c;
  for (auto _ : state) {
    c = sweep_continuation(model, SweepParameter::drive_frequency(), 0.997, 1.1, options);
    benchmark::DoNotOptimize(c);
  }
  omp_set_num_threads(threads);
  state.counters["points"] = static_cast<double>(c.points.size());
  state.counters["folds"] = static_cast<double>(c.folds.size());
  state.counters["last_frequency"] = c.points.empty() ? 0.0 : c.points.back().parameter;
}
BENCHMARK_CAPTURE(BM_FrequencyContinuation500, one_core, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FrequencyContinuation500, two_cores, true)->Unit(benchmark::kMillisecond);

void BM_FrequencySweep500(benchmark::State& state, bool parallel) {
  const TappingModel model = resonance_model();
  SweepOptions options;
  options.parallel = parallel;
  const int threads = omp_get_max_threads();
  if (!parallel) omp_set_num_threads(1);
  SweepResult r;
  for (auto _ : state) {
    r = sweep_instrument(model, SweepParameter::drive_frequency(), 0.95, 1.05, 500, options);
    benchmark::DoNotOptimize(r);
  }
  omp_set_num_threads(threads);
  state.counters["points"] = static_cast<double>(r.approach.size() + r.retract.size());
  state.counters["jumps"] = static_cast<double>(r.jumps.size());
}
BENCHMARK_CAPTURE(BM_FrequencySweep500, one_core, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FrequencySweep500, two_cores, true)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
