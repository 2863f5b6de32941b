// A fit of a 500-point AM-AFM amplitude/phase curve with 4 parameters (A_H, E*, distance offset, phase offset of
// DMT + vdW) on one core (issue 25: ≤ 10 s), and of an FM-AFM frequency-shift curve with 3 parameters (A_H, E*,
// distance offset). Counters: orbit evaluations (AM: Newton shooting solves; FM: FM orbit solves), curve evaluations
// (forward-model runs, the Jacobian's columns included), iterations. docs/fitting.md#speed.
#include <random>

#include <benchmark/benchmark.h>

#include "afmkit/spectroscopy/fit.hpp"

using namespace afmkit::spectroscopy;

namespace {

FitSettings settings() {
  FitSettings s;
  s.spring_constant = 40.0;
  s.resonance_frequency = 300e3;
  s.quality_factor = 400.0;
  s.free_amplitude = 20e-9;
  return s;
}

FitCurve synthetic(int n) {
  FitOptions truth;
  truth.law_values = {{"effective_modulus", 1e9}, {"tip_radius", 10e-9}, {"hamaker", 1e-19}};
  truth.initial = {{"distance_offset", 0.7e-9}, {"phase_offset", 0.1}};
  FitCurve c;
  for (int i = 0; i < n; ++i) c.distance.push_back(21e-9 - 17e-9 * i / (n - 1));
  const AmPrediction p = predict_am_curve(c.distance, settings(), truth);
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    c.amplitude.push_back(p.amplitude[i] + 0.003 * 20e-9 * g(rng));
    c.phase.push_back(p.phase[i] + 0.005 * g(rng));
  }
  return c;
}

void BM_FitAmCurve(benchmark::State& state) {
  const FitCurve data = synthetic(static_cast<int>(state.range(0)));
  FitOptions o;
  o.law_values = {{"tip_radius", 10e-9}, {"effective_modulus", 0.7e9}, {"hamaker", 1.3e-19}};
  o.parameters = {"hamaker", "effective_modulus", "distance_offset", "phase_offset"};
  o.initial = {{"distance_offset", 0.4e-9}};
  o.parallel = false;  // one core
  FitResult r;
  for (auto _ : state) {
    r = fit_am_curve(data, settings(), o);
    benchmark::DoNotOptimize(r.estimates.data());
  }
  state.counters["orbit_evaluations"] = static_cast<double>(r.orbit_evaluations);
  state.counters["curve_evaluations"] = static_cast<double>(r.curve_evaluations);
  state.counters["iterations"] = r.iterations;
  state.counters["converged"] = r.status == FitStatus::ok ? 1 : 0;
}
BENCHMARK(BM_FitAmCurve)->Arg(100)->Arg(500)->Unit(benchmark::kSecond)->Iterations(1);

/// A 3-parameter FM fit: Δf of DMT + vdW (A = 5 nm, from 5.5 nm above the surface into contact) with 1 Hz of noise,
/// from values 30 % off.
void BM_FitFmCurve(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const FmFitSettings s{40.0, 300e3, 400.0, 5e-9};
  FitOptions truth;
  truth.law_values = {{"effective_modulus", 1e9}, {"tip_radius", 10e-9}, {"hamaker", 1e-19}};
  truth.initial = {{"distance_offset", 0.5e-9}};
  FmFitCurve data;
  for (int i = 0; i < n; ++i) data.distance.push_back(10e-9 - 6.5e-9 * i / (n - 1));
  const FmPrediction p = predict_fm_curve(data.distance, s, truth);
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int i = 0; i < n; ++i) data.frequency_shift.push_back(p.frequency_shift[i] + g(rng));
  FitOptions o;
  o.law_values = {{"tip_radius", 10e-9}, {"effective_modulus", 0.7e9}, {"hamaker", 1.3e-19}};
  o.parameters = {"hamaker", "effective_modulus", "distance_offset"};
  o.initial = {{"distance_offset", 0.3e-9}};
  o.parallel = false;  // one core
  FitResult r;
  for (auto _ : state) {
    r = fit_fm_curve(data, s, o);
    benchmark::DoNotOptimize(r.estimates.data());
  }
  state.counters["orbit_evaluations"] = static_cast<double>(r.orbit_evaluations);
  state.counters["curve_evaluations"] = static_cast<double>(r.curve_evaluations);
  state.counters["iterations"] = r.iterations;
  state.counters["converged"] = r.status == FitStatus::ok ? 1 : 0;
}
BENCHMARK(BM_FitFmCurve)->Arg(100)->Arg(500)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
