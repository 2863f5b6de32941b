// Speed of the tapping model with the open force laws (docs/force-laws.md), in the physical case users compare
// with pyDAMPF: k = 40 N/m, f0 = 300 kHz, Q = 400, free amplitude 10 nm at resonance, R = 10 nm, E* = 1 GPa,
// A_H = 6.4e-20 J, a0 = 0.165 nm. Targets (issue 7): one converged orbit with a table law at Q = 400 ≤ 5 ms;
// a DMT + vdW approach sweep ≤ 0.5 ms per separation point at amplitude accuracy 1e-8 (counter amplitude_error:
// the largest relative amplitude error of the sweep against the same sweep at tolerance 1e-13).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <benchmark/benchmark.h>
#include <omp.h>

#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"

namespace {

using namespace afmkit;
using namespace afmkit::tapping;

const PhysicalCantilever cantilever(40.0, 300.0, 400.0, 10.0, 1.0);
const impact::DmtLaw dmt(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165);

// the DMT law as a measured curve: 200 evenly spaced samples on [−2, 20] nm (AFM exports are evenly spaced)
impact::ForceLaw table_law() {
  impact::ForceCurve c;
  for (int i = 0; i < 200; ++i) {
    const double d = -2.0 + 22.0 * i / 199.0;
    c.approach_gap.push_back(d);
    c.approach_force.push_back(dmt.approach(d));
  }
  c.retract_gap = c.approach_gap;
  c.retract_force = c.approach_force;
  return impact::make_law<impact::TableLaw>(c);
}

TappingModel model_with(const impact::ForceLaw& law, double separation) {
  return {cantilever.cantilever(), cantilever.drive(), cantilever.normalised_law(law), separation};
}

ShootingOptions accurate() {  // amplitude to ~1e-8
  ShootingOptions o;
  o.tolerance = 1e-10;
  o.simulation.relative_tolerance = 1e-10;
  o.simulation.absolute_tolerance = 1e-11;
  return o;
}

void BM_ConvergedOrbit(benchmark::State& state, bool table) {
  const TappingModel model = model_with(table ? table_law() : impact::ForceLaw(dmt), 8.0);
  // start: the orbit at a neighbouring separation (as in a sweep), i.e. Newton from a nearby state
  const PeriodicOrbit near = shoot(model.with_separation(8.05), free_response_state(model), 1, accurate());
  PeriodicOrbit orbit;
  for (auto _ : state) {
    orbit = shoot(model, near.initial, 1, accurate());
    benchmark::DoNotOptimize(orbit);
  }
  state.counters["newton_iterations"] = orbit.iterations;
  state.counters["events_per_period"] = static_cast<double>(orbit.stats.events);
}
BENCHMARK_CAPTURE(BM_ConvergedOrbit, dmt, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ConvergedOrbit, table, true)->Unit(benchmark::kMillisecond);

SweepOptions sweep_options(double tolerance) {
  SweepOptions o;
  o.parallel = false;
  o.harmonic_balance = false;
  o.shooting.tolerance = tolerance;
  o.shooting.simulation.relative_tolerance = tolerance;
  o.shooting.simulation.absolute_tolerance = 0.1 * tolerance;
  return o;
}

double max_relative_amplitude_error(const SweepResult& r, const SweepResult& reference) {
  double worst = 0.0;
  auto compare = [&](const std::vector<SweepPoint>& a, const std::vector<SweepPoint>& b) {
    if (a.size() != b.size()) worst = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
      worst = std::max(worst, std::abs(a[i].metrics.amplitude / b[i].metrics.amplitude - 1.0));
  };
  compare(r.approach, reference.approach);
  compare(r.retract, reference.retract);
  return worst;
}

// Approach and retract over l = 2…10 nm, 50 points each way; state.range(1) = −log10 of the integrator and
// Newton tolerance. The amplitude accuracy is measured against the same sweep at tolerance 1e-13.
void BM_DmtApproachSweepPerPoint(benchmark::State& state) {
  const TappingModel model = model_with(impact::ForceLaw(dmt), 10.0);
  const int points = static_cast<int>(state.range(0));
  const double tolerance = std::pow(10.0, -static_cast<double>(state.range(1)));
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const SweepResult reference = sweep_instrument(model, 2.0, 10.0, points, sweep_options(1e-13));
  const SweepOptions options = sweep_options(tolerance);
  SweepResult r;
  for (auto _ : state) {
    r = sweep_instrument(model, 2.0, 10.0, points, options);
    benchmark::DoNotOptimize(r);
  }
  omp_set_num_threads(threads);
  const double per_sweep_points = static_cast<double>(r.approach.size() + r.retract.size());
  state.counters["points"] = per_sweep_points;
  state.counters["amplitude_error"] = max_relative_amplitude_error(r, reference);
  state.counters["time_per_point"] =
      benchmark::Counter(per_sweep_points, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_DmtApproachSweepPerPoint)->Args({50, 9})->Args({50, 10})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
