// Speed of the seed-2 real-time filter and closed-loop simulation.
// Targets: RealtimeFilter::step ≥ 20 million samples/s at N = 10 (≤ 50 ns/sample) on one core;
//          RealtimeFilter::step_block ≥ 100 MS/s at N = 10 and ≥ 20 MS/s at N = 50 (BM_RealtimeFilterBlockVsStep
//          prints both paths and their ratio, measured in the same run);
//          100-period closed loop, 2000 steps per period, N = 10: ≤ 50 ms;
//          filter set-up at N = 1000: ≤ 0.1 s.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <vector>

#include "afmkit/control/closed_loop_simulation.hpp"
#include "afmkit/control/realtime_filter.hpp"

using namespace afmkit::control;

namespace {
constexpr double kT = 2.0 * std::numbers::pi;

std::vector<double> input_signal(std::size_t n) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = 0.2 + std::sin(kT * i / 2000.0) + 0.05 * std::sin(kT * 3.0 * i / 2000.0);
  return v;
}

void filter_step(benchmark::State& state, SampledForm form) {
  const int n = static_cast<int>(state.range(0));
  const double fs = std::max(2000.0, 40.0 * n) / kT;
  auto f = RealtimeFilter::with_couplings(fs, 1.0, n, 0.1, -0.1, 20.0, form);
  const auto in = input_signal(4096);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.step(in[i]));
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());  // Time column = ns per sample
  state.counters["modal"] = f.uses_modal_form() ? 1 : 0;
}

void BM_RealtimeFilterStep(benchmark::State& state) { filter_step(state, SampledForm::ZeroOrderHold); }
BENCHMARK(BM_RealtimeFilterStep)->Arg(1)->Arg(10)->Arg(50);

void BM_RealtimeFilterStepBlockForm(benchmark::State& state) { filter_step(state, SampledForm::BlockZeroOrderHold); }
BENCHMARK(BM_RealtimeFilterStepBlockForm)->Arg(1)->Arg(10)->Arg(50);

void BM_RealtimeFilterStepBlock(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  auto f = RealtimeFilter::with_couplings(std::max(2000.0, 40.0 * n) / kT, 1.0, n, 0.1, -0.1, 20.0);
  const auto in = input_signal(4096);
  std::vector<double> out(in.size());
  for (auto _ : state) {
    f.step_block(in, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(in.size()));  // ns/sample = 1e9/items_per_second
}
BENCHMARK(BM_RealtimeFilterStepBlock)->Arg(1)->Arg(10)->Arg(50);

// The block path against the per-sample path, interleaved in the same iterations (same machine state): counters
// block_MSps, step_MSps and speedup = step time / block time (they give the same bits, test_realtime_block.cpp).
void BM_RealtimeFilterBlockVsStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const double fs = std::max(2000.0, 40.0 * n) / kT;
  auto fb = RealtimeFilter::with_couplings(fs, 1.0, n, 0.1, -0.1, 20.0);
  if (state.range(1) == 1) fb.set_vectorisation(RealtimeFilter::Vectorisation::Portable);  // 16-byte vectors only
  auto fstep = fb;
  const auto in = input_signal(4096);
  std::vector<double> out(in.size()), out_step(in.size());
  using clock = std::chrono::steady_clock;
  double t_block = 0.0, t_step = 0.0;
  for (auto _ : state) {
    const auto t0 = clock::now();
    fb.step_block(in, out);
    benchmark::ClobberMemory();
    const auto t1 = clock::now();
    for (std::size_t i = 0; i < in.size(); ++i) out_step[i] = fstep.step(in[i]);
    benchmark::ClobberMemory();
    const auto t2 = clock::now();
    t_block += std::chrono::duration<double>(t1 - t0).count();
    t_step += std::chrono::duration<double>(t2 - t1).count();
    benchmark::DoNotOptimize(out.data());
    benchmark::DoNotOptimize(out_step.data());
  }
  const double samples = static_cast<double>(state.iterations()) * static_cast<double>(in.size());
  state.counters["block_MSps"] = samples / t_block * 1e-6;
  state.counters["step_MSps"] = samples / t_step * 1e-6;
  state.counters["speedup"] = t_step / t_block;
  state.counters["wide"] = fb.uses_wide_vectors() ? 1 : 0;
}
BENCHMARK(BM_RealtimeFilterBlockVsStep)->ArgsProduct({{1, 10, 50, 200}, {0, 1}})->ArgNames({"N", "portable"});

// Set-up of the zero-order-hold filter (what afmkit_filter_create does): O(N²) time, O(N) memory, modal form.
// Target (issue 12): N = 1000 in under 0.1 s.
void BM_RealtimeFilterCreate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  bool modal = false;
  for (auto _ : state) {
    auto f = RealtimeFilter::with_couplings(40.0 * n / kT, 1.0, n, 0.1, -0.1, 20.0);
    modal = f.uses_modal_form();
    benchmark::DoNotOptimize(f.last_output());
  }
  state.counters["modal"] = modal ? 1 : 0;
}
BENCHMARK(BM_RealtimeFilterCreate)->Arg(10)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

void closed_loop(benchmark::State& state, PlantKind kind, ControllerStepping stepping, int record_every) {
  const Plant plant(kind, 20.0, 1.0, 0.1 * kT, Disturbance::paper_example());
  const auto bank = OscillatorBank::with_couplings(1.0, 10, 0.1, -0.1, 20.0);
  SimulationOptions o;
  o.periods = 100;
  o.steps_per_period = 2000;
  o.stepping = stepping;
  o.record_every = record_every;
  for (auto _ : state) {
    auto r = simulate_closed_loop(plant, bank, o);
    benchmark::DoNotOptimize(r.report.residual_first_harmonic);
  }
}

void BM_ClosedLoop100PeriodsAb3Static(benchmark::State& s) {
  closed_loop(s, PlantKind::Static, ControllerStepping::AdamsBashforth3, 0);
}
void BM_ClosedLoop100PeriodsAb3FirstOrder(benchmark::State& s) {
  closed_loop(s, PlantKind::FirstOrder, ControllerStepping::AdamsBashforth3, 0);
}
void BM_ClosedLoop100PeriodsAb3FirstOrderRecorded(benchmark::State& s) {
  closed_loop(s, PlantKind::FirstOrder, ControllerStepping::AdamsBashforth3, 1);
}
void BM_ClosedLoop100PeriodsZohFirstOrder(benchmark::State& s) {
  closed_loop(s, PlantKind::FirstOrder, ControllerStepping::ZeroOrderHold, 0);
}
void BM_ClosedLoop100PeriodsNeutralStatic(benchmark::State& state) {
  const Plant plant(PlantKind::Static, 20.0, 1.0, 0.1 * kT, Disturbance::paper_example());
  SimulationOptions o;
  o.periods = 100;
  o.steps_per_period = 2000;
  o.record_every = 0;
  for (auto _ : state) {
    auto r = simulate_closed_loop(plant, InfiniteBank(1.0, 0.1, -0.1, 20.0), o);
    benchmark::DoNotOptimize(r.report.residual_first_harmonic);
  }
}
BENCHMARK(BM_ClosedLoop100PeriodsAb3Static)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosedLoop100PeriodsAb3FirstOrder)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosedLoop100PeriodsAb3FirstOrderRecorded)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosedLoop100PeriodsZohFirstOrder)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosedLoop100PeriodsNeutralStatic)->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();
