// What a `tapping sweep` separation costs with its options (issue 28 §1): per separation and direction, on
// pyDAMPF's DMT + vdW approach problem (k = 40 N/m, f0 = 300 kHz, Q = 400, free amplitude 10 nm, R = 10 nm,
// E* = 1 GPa, A_H = 6.4e-20 J, a0 = 0.165 nm; l = 2 … 10 nm) at an amplitude accuracy of 1e-8 (counter
// amplitude_error: the largest relative amplitude error against the same sweep at tolerance 1e-13), on one core,
// for 50 and 1000 separations. Arguments: points, directions (1: approach only, 2: approach + retract), HB beside
// each point (0/1). The baseline, measured in the same run, is the sweep as it ran before the options (both
// directions, HB beside each point); after the benchmarks each variant's time per separation and direction is
// printed with its ratio to that baseline and to the target 0.17 ms (≈ 1000× pyDAMPF's 172 ms per point).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <tuple>

#include <benchmark/benchmark.h>
#include <omp.h>

#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"

namespace {

using namespace afmkit;
using namespace afmkit::tapping;

const PhysicalCantilever cantilever(40.0, 300.0, 400.0, 10.0, 1.0);
const impact::DmtLaw dmt(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165);
constexpr double kTargetMs = 0.17;
constexpr double kTolerance = 1e-10;  // integrator and Newton: amplitude to < 1e-8 (counter amplitude_error)

TappingModel dmt_model() { return {cantilever.cantilever(), cantilever.drive(), cantilever.normalised_law(dmt), 10.0}; }

SweepOptions options_with(double tolerance, bool retract, bool hb) {
  SweepOptions o;
  o.parallel = false;
  o.harmonic_balance = hb;
  o.retract = retract;
  o.shooting.tolerance = tolerance;
  o.shooting.simulation.relative_tolerance = tolerance;
  o.shooting.simulation.absolute_tolerance = 0.1 * tolerance;
  return o;
}

double worst_amplitude_error(const std::vector<SweepPoint>& a, const std::vector<SweepPoint>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, std::abs(a[i].metrics.amplitude / b[i].metrics.amplitude - 1.0));
  return worst;
}

// (points, directions, hb) -> ms per separation and direction
std::map<std::tuple<int, int, int>, double>& times() {
  static std::map<std::tuple<int, int, int>, double> t;
  return t;
}

const SweepResult& reference(int points) {  // both directions at 1e-13, once per grid
  static std::map<int, SweepResult> cache;
  auto it = cache.find(points);
  if (it == cache.end())
    it = cache.emplace(points, sweep_instrument(dmt_model(), 2.0, 10.0, points, options_with(1e-13, true, false))).first;
  return it->second;
}

void BM_SweepPerSeparationAndDirection(benchmark::State& state) {
  const int points = static_cast<int>(state.range(0));
  const bool retract = state.range(1) == 2;
  const bool hb = state.range(2) == 1;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const SweepResult& ref = reference(points);
  const SweepOptions options = options_with(kTolerance, retract, hb);
  SweepResult r;
  for (auto _ : state) {
    r = sweep_instrument(dmt_model(), 2.0, 10.0, points, options);
    benchmark::DoNotOptimize(r);
  }
  omp_set_num_threads(threads);
  const double orbits = static_cast<double>(r.approach.size() + r.retract.size());
  double error = worst_amplitude_error(r.approach, ref.approach);
  if (retract) error = std::max(error, worst_amplitude_error(r.retract, ref.retract));
  state.counters["orbits"] = orbits;
  state.counters["amplitude_error"] = error;
  state.counters["ms_per_point"] =
      benchmark::Counter(orbits * 1e-3, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SweepPerSeparationAndDirection)
    ->ArgNames({"points", "directions", "hb"})
    ->Args({50, 2, 1})  // the baseline: as before the options (both directions, HB beside each point)
    ->Args({50, 2, 0})
    ->Args({50, 1, 0})
    ->Args({1000, 2, 1})
    ->Args({1000, 2, 0})
    ->Args({1000, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

// Collects the time per separation and direction of each run for the table printed at the end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration || run.error_occurred) continue;
      const auto orbits = run.counters.find("orbits");
      if (orbits == run.counters.end()) continue;
      int points = 0, directions = 0, hb = 0;
      std::sscanf(run.run_name.args.c_str(), "points:%d/directions:%d/hb:%d", &points, &directions, &hb);
      // CPU time: one thread, and the machine may be shared (its wall time is then not the sweep's)
      const double seconds = run.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(run.time_unit);
      times()[{points, directions, hb}] = seconds * 1e3 / orbits->second.value;
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\nms per separation and direction (one core, CPU time), ratio to the baseline (both directions, HB beside) and "
              "to the target %.2f ms:\n",
              kTargetMs);
  for (const auto& [key, ms] : times()) {
    const auto [points, directions, hb] = key;
    const auto base = times().find({points, 2, 1});
    std::printf("  points %4d  %-8s  HB %-3s  %.3f ms   x%.2f of the baseline   x%.2f of the target\n", points,
                directions == 2 ? "both" : "approach", hb ? "on" : "off", ms,
                base != times().end() ? ms / base->second : std::nan(""), ms / kTargetMs);
  }
  benchmark::Shutdown();
  return 0;
}
