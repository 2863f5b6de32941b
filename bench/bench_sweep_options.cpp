// What a `tapping sweep` separation costs with its options (issue 28 §1): per separation and direction, on
// pyDAMPF's DMT + vdW approach problem (k = 40 N/m, f0 = 300 kHz, Q = 400, free amplitude 10 nm, R = 10 nm,
// E* = 1 GPa, A_H = 6.4e-20 J, a0 = 0.165 nm; l = 2 … 10 nm) at an amplitude accuracy of 1e-8 (counter
// amplitude_error: the largest relative amplitude error against the same sweep at tolerance 1e-13), on one core,
// for 50 and 1000 separations. Arguments: points, directions (1: approach only, 2: approach + retract), HB beside
// each point (0/1), lazy sensitivities (0: every Newton iteration integrates the variational equations, the path
// before; 1: Newton iterates on the map without them and integrates them once per orbit, SweepOptions::
// lazy_sensitivities). The baseline, measured in the same run, is the sweep as it ran before the options (both
// directions, HB beside each point, eager sensitivities); after the benchmarks each variant's time per separation
// and direction is printed with its ratio to that baseline, to the eager path of the same options and to the
// target 0.17 ms (≈ 1000× pyDAMPF's 172 ms per point), and the agreement of the lazy and eager sweeps (largest
// relative amplitude difference, largest difference of the largest Floquet multiplier, the same jumps).
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

SweepOptions options_with(double tolerance, bool retract, bool hb, bool lazy = true) {
  SweepOptions o;
  o.parallel = false;
  o.lazy_sensitivities = lazy;
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

// (points, directions, hb, lazy) -> ms per separation and direction
std::map<std::tuple<int, int, int, int>, double>& times() {
  static std::map<std::tuple<int, int, int, int>, double> t;
  return t;
}

// (points, directions, hb, lazy) -> the last sweep (for the agreement of the lazy and eager paths)
std::map<std::tuple<int, int, int, int>, SweepResult>& sweeps() {
  static std::map<std::tuple<int, int, int, int>, SweepResult> r;
  return r;
}

double worst_floquet_difference(const std::vector<SweepPoint>& a, const std::vector<SweepPoint>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, std::abs(a[i].orbit.floquet_max - b[i].orbit.floquet_max));
  return worst;
}

bool same_jumps(const SweepResult& a, const SweepResult& b) {
  auto close = [](const std::vector<double>& x, const std::vector<double>& y) {
    if (x.size() != y.size()) return false;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (std::abs(x[i] - y[i]) > 1e-4) return false;  // within the jump tolerance (1e-5 of A_free = 1e-4 nm)
    return true;
  };
  return close(a.approach_jumps, b.approach_jumps) && close(a.retract_jumps, b.retract_jumps);
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
  const bool lazy = state.range(3) == 1;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const SweepResult& ref = reference(points);
  const SweepOptions options = options_with(kTolerance, retract, hb, lazy);
  SweepResult r;
  for (auto _ : state) {
    r = sweep_instrument(dmt_model(), 2.0, 10.0, points, options);
    benchmark::DoNotOptimize(r);
  }
  omp_set_num_threads(threads);
  const double orbits = static_cast<double>(r.approach.size() + r.retract.size());
  double error = worst_amplitude_error(r.approach, ref.approach);
  if (retract) error = std::max(error, worst_amplitude_error(r.retract, ref.retract));
  sweeps()[{points, retract ? 2 : 1, hb ? 1 : 0, lazy ? 1 : 0}] = r;
  state.counters["orbits"] = orbits;
  state.counters["amplitude_error"] = error;
  state.counters["ms_per_point"] =
      benchmark::Counter(orbits * 1e-3, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SweepPerSeparationAndDirection)
    ->ArgNames({"points", "directions", "hb", "lazy"})
    ->Args({50, 2, 1, 0})  // the baseline: as before the options (both directions, HB beside each point)
    ->Args({50, 2, 0, 0})
    ->Args({50, 2, 0, 1})
    ->Args({50, 1, 0, 0})
    ->Args({50, 1, 0, 1})
    ->Args({1000, 2, 1, 0})
    ->Args({1000, 2, 0, 0})
    ->Args({1000, 2, 0, 1})
    ->Args({1000, 1, 0, 0})
    ->Args({1000, 1, 0, 1})
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
      int points = 0, directions = 0, hb = 0, lazy = 0;
      std::sscanf(run.run_name.args.c_str(), "points:%d/directions:%d/hb:%d/lazy:%d", &points, &directions, &hb,
                  &lazy);
      // CPU time: one thread, and the machine may be shared (its wall time is then not the sweep's)
      const double seconds = run.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(run.time_unit);
      times()[{points, directions, hb, lazy}] = seconds * 1e3 / orbits->second.value;
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\nms per separation and direction (one core, CPU time), ratio to the baseline (both directions, HB beside, "
              "eager sensitivities), to the eager path of the same options and to the target %.2f ms:\n",
              kTargetMs);
  for (const auto& [key, ms] : times()) {
    const auto [points, directions, hb, lazy] = key;
    const auto base = times().find({points, 2, 1, 0});
    const auto eager = times().find({points, directions, hb, 0});
    std::printf("  points %4d  %-8s  HB %-3s  %-5s  %.3f ms   x%.2f of the baseline   x%.2f of eager   x%.2f of the "
                "target\n",
                points, directions == 2 ? "both" : "approach", hb ? "on" : "off", lazy ? "lazy" : "eager", ms,
                base != times().end() ? ms / base->second : std::nan(""),
                eager != times().end() ? ms / eager->second : std::nan(""), ms / kTargetMs);
  }
  std::printf("\nagreement of the lazy and the eager sweeps (same options):\n");
  for (const auto& [key, r] : sweeps()) {
    const auto [points, directions, hb, lazy] = key;
    if (!lazy) continue;
    const auto eager = sweeps().find({points, directions, hb, 0});
    if (eager == sweeps().end()) continue;
    const SweepResult& e = eager->second;
    const double da = std::max(worst_amplitude_error(r.approach, e.approach), worst_amplitude_error(r.retract, e.retract));
    const double df = std::max(worst_floquet_difference(r.approach, e.approach),
                               worst_floquet_difference(r.retract, e.retract));
    std::printf("  points %4d  %-8s  HB %-3s  amplitude %.2e (relative)  floquet_max %.2e  jumps %s (%zu + %zu)\n",
                points, directions == 2 ? "both" : "approach", hb ? "on" : "off", da, df,
                same_jumps(r, e) ? "same" : "DIFFER", r.approach_jumps.size(), r.retract_jumps.size());
  }
  benchmark::Shutdown();
  return 0;
}
