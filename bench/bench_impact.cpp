// Impact solvers (seed-1 §II): closed form vs Dormand–Prince integration, DMT integration, eq. (6) quadrature.
#include <benchmark/benchmark.h>

#include "afmkit/impact/impact.hpp"

using namespace afmkit::impact;

namespace {
const ImpactProblem linear_problem =
    ImpactProblem::head_on(1.0, 2.0, 1.0, 0.2, PiecewiseLinearLaw(100.0, 64.0, 0.3, 0.6));
const DmtLaw dmt(1.0, 0.8, 10.0, 6.4e-20, 1e-19, 0.165);
const ImpactProblem dmt_problem = ImpactProblem::head_on(3e-10, 1e-11, 3e6, 2.0, dmt);
}  // namespace

static void BM_ImpactClosedForm(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(simulate_impact(linear_problem));
}
BENCHMARK(BM_ImpactClosedForm);

static void BM_ImpactIntegratorLinear(benchmark::State& state) {
  const ImpactOptions options{.method = ImpactMethod::integrator};
  for (auto _ : state) benchmark::DoNotOptimize(simulate_impact(linear_problem, options));
}
BENCHMARK(BM_ImpactIntegratorLinear);

static void BM_ImpactIntegratorDmt(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(simulate_impact(dmt_problem));
}
BENCHMARK(BM_ImpactIntegratorDmt);

static void BM_ImpactIntegratorDmtHistory400(benchmark::State& state) {
  const ImpactOptions options{.history_points = 400};
  for (auto _ : state) benchmark::DoNotOptimize(simulate_impact(dmt_problem, options));
}
BENCHMARK(BM_ImpactIntegratorDmtHistory400);

static void BM_HysteresisAreaDmt(benchmark::State& state) {
  const ForceLaw law(dmt);
  for (auto _ : state) benchmark::DoNotOptimize(hysteresis_energy_loss(law, -4.0, 2.0));
}
BENCHMARK(BM_HysteresisAreaDmt);
BENCHMARK_MAIN();
