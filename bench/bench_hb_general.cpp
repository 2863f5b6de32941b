// Harmonic balance for any force law (issue 7.2): the numerical-describing-function HB curve of the DMT + vdW case
// (k = 40 N/m, f0 = 300 kHz, Q = 400, A_free = 10 nm, R = 10 nm, E* = 1 GPa, A_H = 6.4e-20 J, a0 = 0.165 nm;
// target: 10³ q samples in ≤ 50 ms), its parts (curve tracing, solutions at one separation, one describing-function
// evaluation), and the closed-form curve of a piecewise-linear law for comparison with bench_hb (unchanged path).
#include <benchmark/benchmark.h>

#include <numbers>

#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/numerical_describing_functions.hpp"
#include "afmkit/tapping/units.hpp"

namespace {

using namespace afmkit;
using namespace afmkit::tapping;

TappingModel dmt_model(double l = 8.0) {
  const PhysicalCantilever pc(40.0, 300.0, 400.0, 10.0, 1.0);
  const impact::ForceLaw law = impact::ForceLaw(impact::DmtLaw(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165))
                                   .scaled(1.0 / pc.spring_constant, 2.0 * std::numbers::pi * pc.resonance_frequency * 1e3);
  return TappingModel(pc.cantilever(), pc.drive(), law, l);
}

// The default curve options (q ∈ [−2, 2], half the samples log-spaced towards grazing), 10³ samples.
void BM_DmtCurve(benchmark::State& state) {
  const TappingModel model = dmt_model();
  HbCurveOptions o;
  o.points = static_cast<std::size_t>(state.range(0));
  o.spacing = state.range(1) != 0 ? HbCurveSpacing::RefinedGrazing : HbCurveSpacing::Uniform;
  std::vector<HbPoint> out;
  for (auto _ : state) {
    harmonic_balance_curve(model, o, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["points_out"] = static_cast<double>(out.size());
}
BENCHMARK(BM_DmtCurve)->Args({1000, 1})->Args({1000, 0})->Unit(benchmark::kMillisecond);

// Tracing the whole first-harmonic curve (construction of HarmonicBalance for a non-linear law).
void BM_DmtScan(benchmark::State& state) {
  const TappingModel model = dmt_model();
  for (auto _ : state) benchmark::DoNotOptimize(HarmonicBalance(model));
}
BENCHMARK(BM_DmtScan)->Unit(benchmark::kMillisecond);

void BM_DmtSolutionsAtSeparation(benchmark::State& state) {
  const HarmonicBalance hb(dmt_model());
  for (auto _ : state) benchmark::DoNotOptimize(hb.solutions(8.0));  // three solutions (S-shaped curve)
}
BENCHMARK(BM_DmtSolutionsAtSeparation)->Unit(benchmark::kMicrosecond);

// One numerical describing-function evaluation: an intermittent-contact orbit (contact arc + van der Waals side)
// and a permanent-contact one.
void BM_DmtDescribingFunctions(benchmark::State& state) {
  const TappingModel model = dmt_model();
  const DescribingFunctionQuadrature df(model.law, model.drive.frequency);
  const double g = state.range(0) != 0 ? 5.0 : -0.5, b = state.range(0) != 0 ? 5.2 : 0.2;
  for (auto _ : state) benchmark::DoNotOptimize(df.at_gap(g, b));
}
BENCHMARK(BM_DmtDescribingFunctions)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

// The closed-form curve (piecewise-linear law): the fast path, as in bench_hb's BM_CurvePoints.
void BM_ClosedFormCurve(benchmark::State& state) {
  const TappingModel model(Cantilever(1.0, 100.0), Drive(0.2, 0.995),
                           impact::PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6), 14.5);
  HbCurveOptions o;
  o.q_min = -2.0;
  o.q_max = 1.5;
  o.points = static_cast<std::size_t>(state.range(0));
  std::vector<HbPoint> out;
  out.reserve(2 * o.points);
  for (auto _ : state) {
    harmonic_balance_curve(model, o, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["points_out"] = static_cast<double>(out.size());
}
BENCHMARK(BM_ClosedFormCurve)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
