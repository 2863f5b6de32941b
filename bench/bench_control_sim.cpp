// Speed of the seed-2 real-time filter and closed-loop simulation.
// Targets: RealtimeFilter::step ≥ 20 million samples/s at N = 10 (≤ 50 ns/sample) on one core;
//          RealtimeFilter::step_block ≥ 100 MS/s at N = 10 and ≥ 20 MS/s at N = 50 (BM_RealtimeFilterBlockVsStep
//          prints both paths and their ratio, measured in the same run);
//          100-period closed loop, 2000 steps per period, N = 10: ≤ 50 ms;
//          filter set-up at N = 1000: ≤ 0.1 s.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
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

// Median of the per-iteration times: on a shared machine an interval that lost the core to another process is an
// outlier, not a share of the average.
double median_seconds(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
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
// block_MSps, step_MSps and speedup = step time / block time (they give the same bits, test_realtime_block.cpp),
// from the medians of the per-iteration times.
void BM_RealtimeFilterBlockVsStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const double fs = std::max(2000.0, 40.0 * n) / kT;
  auto fb = RealtimeFilter::with_couplings(fs, 1.0, n, 0.1, -0.1, 20.0);
  if (state.range(1) == 1) fb.set_vectorisation(RealtimeFilter::Vectorisation::Portable);  // 16-byte vectors only
  auto fstep = fb;
  const auto in = input_signal(4096);
  std::vector<double> out(in.size()), out_step(in.size());
  using clock = std::chrono::steady_clock;
  std::vector<double> t_block, t_step;
  for (auto _ : state) {
    const auto t0 = clock::now();
    fb.step_block(in, out);
    benchmark::ClobberMemory();
    const auto t1 = clock::now();
    for (std::size_t i = 0; i < in.size(); ++i) out_step[i] = fstep.step(in[i]);
    benchmark::ClobberMemory();
    const auto t2 = clock::now();
    t_block.push_back(std::chrono::duration<double>(t1 - t0).count());
    t_step.push_back(std::chrono::duration<double>(t2 - t1).count());
    benchmark::DoNotOptimize(out.data());
    benchmark::DoNotOptimize(out_step.data());
  }
  const double samples = static_cast<double>(in.size()), tb = median_seconds(t_block), ts = median_seconds(t_step);
  state.counters["block_MSps"] = samples / tb * 1e-6;
  state.counters["step_MSps"] = samples / ts * 1e-6;
  state.counters["speedup"] = ts / tb;
  state.counters["wide"] = fb.uses_wide_vectors() ? 1 : 0;
}
BENCHMARK(BM_RealtimeFilterBlockVsStep)->ArgsProduct({{1, 10, 50, 200}, {0, 1}})->ArgNames({"N", "portable"});

// The builds of the modal block kernel against this core's arithmetic peak, all measured interleaved in the same
// iterations (same machine state): per build, MS/s and the fraction of the arithmetic limit = peak / (14N + 3)
// flops per sample (issue 28's measure; the filter does no FMA, so the peak is that of separate multiplies and adds
// (two multiply and two add pipes): peak_mul_add_GFLOPs; peak_fma_GFLOPs beside it for reference). Counters:
// <build>_MSps, <build>_of_limit (0 … 1), avx512_over_avx2, peak_* (GFLOP/s, 32-byte and 64-byte vectors), each
// from the median of the per-iteration times (a build this processor lacks is left out).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double bench_v4d __attribute__((vector_size(32)));
typedef double bench_v8d __attribute__((vector_size(64)));
// 7 independent multiply chains and 7 add chains (latency × pipes = 3 × 2 each, one more for slack; with the two
// constants all 16 AVX2 registers), `reps` rounds.
template <class W>
[[gnu::always_inline]] inline double peak_mul_add_body(long reps, double one, double zero) {
  constexpr int L = sizeof(W) / sizeof(double);
  W x[7], y[7], c, d;
  for (int l = 0; l < L; ++l) c[l] = one, d[l] = zero;
  for (int k = 0; k < 7; ++k)
    for (int l = 0; l < L; ++l) x[k][l] = 1.0 + k + l, y[k][l] = 2.0 + k - l;
#pragma GCC unroll 1  // one round per iteration: at -O3 GCC unrolled the rounds and spilled the chains
  for (long r = 0; r < reps; ++r) {
#pragma GCC unroll 7
    for (int k = 0; k < 7; ++k) x[k] = x[k] * c;
#pragma GCC unroll 7
    for (int k = 0; k < 7; ++k) y[k] = y[k] + d;
  }
  double s = 0.0;
  for (int k = 0; k < 7; ++k)
    for (int l = 0; l < L; ++l) s += x[k][l] + y[k][l];
  return s;
}
// 12 independent FMA chains (latency 4 × 2 pipes = 8 needed; 14 registers).
template <class W>
[[gnu::always_inline]] inline double peak_fma_body(long reps, double one, double zero) {
  constexpr int L = sizeof(W) / sizeof(double);
  W x[12], c, d;
  for (int l = 0; l < L; ++l) c[l] = one, d[l] = zero;
  for (int k = 0; k < 12; ++k)
    for (int l = 0; l < L; ++l) x[k][l] = 1.0 + k + l;
#pragma GCC unroll 1
  for (long r = 0; r < reps; ++r) {
#pragma GCC unroll 12
    for (int k = 0; k < 12; ++k) x[k] = x[k] * c + d;  // contracted to one FMA (fp-contract on here)
  }
  double s = 0.0;
  for (int k = 0; k < 12; ++k)
    for (int l = 0; l < L; ++l) s += x[k][l];
  return s;
}
#define AFMKIT_PEAK_FN(isa, contract) [[gnu::target(isa), gnu::noinline, gnu::optimize(contract)]] double
AFMKIT_PEAK_FN("avx2", "fp-contract=off") peak_avx2_mul_add(long r, double a, double b) {
  return peak_mul_add_body<bench_v4d>(r, a, b);
}
AFMKIT_PEAK_FN("avx512f,avx512vl", "fp-contract=off") peak_avx512_mul_add(long r, double a, double b) {
  return peak_mul_add_body<bench_v8d>(r, a, b);
}
AFMKIT_PEAK_FN("avx2,fma", "fp-contract=fast") peak_avx2_fma(long r, double a, double b) {
  return peak_fma_body<bench_v4d>(r, a, b);
}
AFMKIT_PEAK_FN("avx512f,avx512vl", "fp-contract=fast") peak_avx512_fma(long r, double a, double b) {
  return peak_fma_body<bench_v8d>(r, a, b);
}
#pragma GCC diagnostic pop
#define AFMKIT_BENCH_PEAK 1
#endif

void BM_RealtimeFilterBuilds(benchmark::State& state) {
  using V = RealtimeFilter::Vectorisation;
  using clock = std::chrono::steady_clock;
  const int n = static_cast<int>(state.range(0));
  const auto base = RealtimeFilter::with_couplings(std::max(2000.0, 40.0 * n) / kT, 1.0, n, 0.1, -0.1, 20.0);
  const V builds[3] = {V::Portable, V::Avx2, V::Avx512};
  const char* names[3] = {"portable", "avx2", "avx512"};
  std::vector<RealtimeFilter> f;
  for (V b : builds) {
    f.push_back(base);
    f.back().set_vectorisation(b);
  }
  const auto in = input_signal(4096);
  std::vector<double> out(in.size());
  std::vector<double> t[3], t_peak[4];
  double one = 1.0, zero = 0.0;
  benchmark::DoNotOptimize(one);
  benchmark::DoNotOptimize(zero);
  constexpr long kPeakReps = 20000;  // 14 vector ops per rep (7 mul + 7 add), 12 FMAs per rep
  for (auto _ : state) {
    for (int b = 0; b < 3; ++b) {
      if (f[static_cast<std::size_t>(b)].vectorisation() != builds[b]) continue;  // not on this processor
      const auto t0 = clock::now();
      f[static_cast<std::size_t>(b)].step_block(in, out);
      benchmark::ClobberMemory();
      t[b].push_back(std::chrono::duration<double>(clock::now() - t0).count());
    }
#ifdef AFMKIT_BENCH_PEAK
    double (*const peak[4])(long, double, double) = {peak_avx2_mul_add, peak_avx2_fma, peak_avx512_mul_add,
                                                     peak_avx512_fma};
    for (int k = 0; k < 4; ++k) {
      if (k >= 2 && !RealtimeFilter::vectorisation_available(V::Avx512)) continue;
      const auto t0 = clock::now();
      benchmark::DoNotOptimize(peak[k](kPeakReps, one, zero));
      t_peak[k].push_back(std::chrono::duration<double>(clock::now() - t0).count());
    }
#endif
  }
  // flops per rep: mul + add 14 ops × lanes, FMA 12 × 2 × lanes
  const double peak_flops[4] = {14.0 * 4, 24.0 * 4, 14.0 * 8, 24.0 * 8};
  const char* peak_names[4] = {"peak_mul_add_GFLOPs", "peak_fma_GFLOPs", "peak512_mul_add_GFLOPs",
                               "peak512_fma_GFLOPs"};
  double gflops[4] = {0, 0, 0, 0};
  for (int k = 0; k < 4; ++k)
    if (!t_peak[k].empty()) {
      gflops[k] = kPeakReps * peak_flops[k] / median_seconds(t_peak[k]) * 1e-9;
      state.counters[peak_names[k]] = gflops[k];
    }
  const double peak = std::max(gflops[0], gflops[2]);  // the kernel's operations: multiplies and adds
  const double limit_msps = peak > 0.0 ? peak * 1e3 / (14.0 * n + 3.0) : 0.0;
  double msps[3] = {0, 0, 0};
  for (int b = 0; b < 3; ++b)
    if (!t[b].empty()) {
      msps[b] = static_cast<double>(in.size()) / median_seconds(t[b]) * 1e-6;
      state.counters[std::string(names[b]) + "_MSps"] = msps[b];
      if (limit_msps > 0.0) state.counters[std::string(names[b]) + "_of_limit"] = msps[b] / limit_msps;
    }
  if (msps[1] > 0.0 && msps[2] > 0.0) state.counters["avx512_over_avx2"] = msps[2] / msps[1];
  state.counters["limit_MSps"] = limit_msps;
}
BENCHMARK(BM_RealtimeFilterBuilds)->Arg(1)->Arg(10)->Arg(20)->Arg(50)->Arg(200);

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
