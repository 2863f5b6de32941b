// Speed of the tapping-mode simulation (seed-1 eq. 8): closed-form flow vs a generic adaptive integrator
// (Dormand–Prince 5(4) with event location, the same code path for non-linear laws), periodic orbits by
// shooting, and instrument sweeps. Parameters: ω_n = 1, Q = 400, ω = ω_n, free amplitude 20 (Γ = 20/|L(iω)|),
// K_a = 10, K_b = 8 (and F_a = 0.3, F_b = 0.6 for the attractive case), l = 12.
#include <cmath>
#include <ctime>

#include <benchmark/benchmark.h>
#include <omp.h>

#include "afmkit/tapping/sweep.hpp"

namespace {

using namespace afmkit;
using namespace afmkit::tapping;

TappingModel bench_model(bool attractive, double separation = 12.0) {
  const Cantilever cantilever(1.0, 400.0);
  const double gamma = 20.0 / std::abs(cantilever.transfer({0.0, 1.0}));
  const impact::PiecewiseLinearLaw law(10.0, 8.0, attractive ? 0.3 : 0.0, attractive ? 0.6 : 0.0);
  return TappingModel(cantilever, Drive(gamma, 1.0), impact::ForceLaw(law), separation);
}

TipState hb_guess(const TappingModel& model) {
  const auto hb = harmonic_balance_solutions(model);
  const HbPoint& p = hb.back();  // largest amplitude (the contact branch at l = 12)
  return {p.offset + p.amplitude * std::cos(p.phase), p.amplitude * model.drive.frequency * std::sin(p.phase)};
}

ShootingOptions closed_form_shooting() {
  ShootingOptions o;
  o.tolerance = 1e-10;
  return o;
}

// Adaptive integrator tuned to reach the same orbit to ~1e-9 (relative amplitude).
ShootingOptions adaptive_shooting() {
  ShootingOptions o;
  o.tolerance = 1e-10;
  o.simulation.integrator = Integrator::adaptive;
  o.simulation.relative_tolerance = 1e-11;
  o.simulation.absolute_tolerance = 1e-12;
  return o;
}

void BM_OrbitShooting(benchmark::State& state, bool attractive, bool adaptive) {
  const TappingModel model = bench_model(attractive);
  const TipState guess = hb_guess(model);
  const ShootingOptions options = adaptive ? adaptive_shooting() : closed_form_shooting();
  PeriodicOrbit orbit;
  for (auto _ : state) {
    orbit = shoot(model, guess, 1, options);
    benchmark::DoNotOptimize(orbit);
  }
  state.counters["newton_iterations"] = orbit.iterations;
  state.counters["floquet_max"] = orbit.floquet_max;
}
BENCHMARK_CAPTURE(BM_OrbitShooting, repulsive_closed_form, false, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_OrbitShooting, attractive_closed_form, true, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_OrbitShooting, repulsive_adaptive, false, true)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_OrbitShooting, attractive_adaptive, true, true)->Unit(benchmark::kMicrosecond);

void BM_OnePeriod(benchmark::State& state, bool attractive, bool adaptive) {
  const TappingModel model = bench_model(attractive);
  const PeriodicOrbit orbit = shoot(model, hb_guess(model), 1, closed_form_shooting());
  const SimulationOptions options = adaptive ? adaptive_shooting().simulation : SimulationOptions{};
  SimulationResult r;
  for (auto _ : state) {
    r = simulate(model, 0.0, orbit.initial, model.period(), options);
    benchmark::DoNotOptimize(r);
  }
  state.counters["events"] = static_cast<double>(r.stats.events);
  state.counters["steps"] = static_cast<double>(r.stats.steps);
  state.counters["closure_error"] = std::hypot(r.state.position - orbit.initial.position,
                                               r.state.velocity - orbit.initial.velocity);
}
BENCHMARK_CAPTURE(BM_OnePeriod, repulsive_closed_form, false, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_OnePeriod, repulsive_adaptive, false, true)->Unit(benchmark::kMicrosecond);

double thread_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Closed form vs adaptive on the same orbits (l = 10, 11, …, 15, both laws), in this process (thread CPU time,
/// robust to machine load). The adaptive relative tolerance is the argument (10^-arg); the counters report the
/// speed-up of a converged shooting solve and the largest difference of the two orbits (relative), i.e. the
/// accuracy at which the comparison is made (the closed form is exact to rounding).
void BM_SpeedupVsAdaptive(benchmark::State& state) {
  ShootingOptions adaptive_options = adaptive_shooting();
  adaptive_options.simulation.relative_tolerance = std::pow(10.0, -static_cast<double>(state.range(0)));
  adaptive_options.simulation.absolute_tolerance = 0.1 * adaptive_options.simulation.relative_tolerance;
  double closed = 0, adaptive = 0, deviation = 0;
  for (auto _ : state) {
    closed = adaptive = deviation = 0;
    for (bool attractive : {false, true}) {
      for (double l = 10.0; l <= 15.0; l += 1.0) {
        const TappingModel model = bench_model(attractive, l);
        const TipState guess = hb_guess(model);
        const double t0 = thread_seconds();
        const PeriodicOrbit a = shoot(model, guess, 1, closed_form_shooting());
        const double t1 = thread_seconds();
        const PeriodicOrbit b = shoot(model, guess, 1, adaptive_options);
        const double t2 = thread_seconds();
        closed += t1 - t0;
        adaptive += t2 - t1;
        deviation = std::max(deviation, std::hypot(a.initial.position - b.initial.position,
                                                   a.initial.velocity - b.initial.velocity) /
                                            std::hypot(a.initial.position, a.initial.velocity));
      }
    }
  }
  state.counters["closed_form_ms_per_orbit"] = 1e3 * closed / 12;
  state.counters["adaptive_ms_per_orbit"] = 1e3 * adaptive / 12;
  state.counters["speedup"] = adaptive / closed;
  state.counters["max_relative_difference"] = deviation;
}
BENCHMARK(BM_SpeedupVsAdaptive)->Arg(9)->Arg(11)->Arg(13)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_InstrumentSweep(benchmark::State& state, bool harmonic_balance) {
  const TappingModel model = bench_model(false);
  SweepOptions options;
  options.parallel = false;  // one core
  options.harmonic_balance = harmonic_balance;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  SweepResult r;
  for (auto _ : state) {
    r = sweep_instrument(model, 5.0, 25.0, 400, options);
    benchmark::DoNotOptimize(r);
  }
  omp_set_num_threads(threads);
  state.counters["points"] = static_cast<double>(r.approach.size() + r.retract.size());
  state.counters["jumps"] = static_cast<double>(r.approach_jumps.size() + r.retract_jumps.size());
}
BENCHMARK_CAPTURE(BM_InstrumentSweep, without_hb, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_InstrumentSweep, with_hb, true)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
