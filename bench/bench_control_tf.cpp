// Speed of the seed-2 controller evaluations: characteristic function Δ(s) (+Δ') for finite / infinite banks
// and the Smith predictor, pole-free C(s), state-space evaluation, and a 1000-point frequency response.
#include <benchmark/benchmark.h>

#include <numbers>

#include "afmkit/control/controller_tf.hpp"
#include "afmkit/control/frequency_response.hpp"
#include "afmkit/control/loop.hpp"
#include "afmkit/control/state_space.hpp"

using namespace afmkit::control;

namespace {
constexpr double kT = 2.0 * std::numbers::pi;
LoopSpec bank_loop(int n) {
  return LoopSpec(OscillatorBank::with_couplings(1.0, n, 0.1, -0.1, 20.0), PlantKind::FirstOrder, 20.0, 0.1 * kT);
}
}  // namespace

static void BM_CharacteristicScaledBank(benchmark::State& st) {
  const LoopSpec loop = bank_loop(static_cast<int>(st.range(0)));
  std::complex<double> s(-0.05, 0.7);
  for (auto _ : st) {
    benchmark::DoNotOptimize(characteristic_scaled(loop, s));
    s += std::complex<double>(0.0, 1e-9);
  }
}
BENCHMARK(BM_CharacteristicScaledBank)->Arg(1)->Arg(10)->Arg(160);

static void BM_CharacteristicScaledInfinite(benchmark::State& st) {
  const LoopSpec loop(InfiniteBank(1.0, 0.1, -0.1, 20.0), PlantKind::Static, 20.0, 0.1 * kT);
  std::complex<double> s(-0.05, 0.7);
  for (auto _ : st) {
    benchmark::DoNotOptimize(characteristic_scaled(loop, s));
    s += std::complex<double>(0.0, 1e-9);
  }
}
BENCHMARK(BM_CharacteristicScaledInfinite);

static void BM_CharacteristicScaledSmith(benchmark::State& st) {
  const LoopSpec loop(SmithPredictor(OscillatorBank::with_couplings(1.0, 10, 0.1, -0.1, 20.0), PlantKind::FirstOrder,
                                     18.0, 0.5 * kT),
                      PlantKind::FirstOrder, 20.0, 0.55 * kT);
  std::complex<double> s(-0.05, 0.7);
  for (auto _ : st) {
    benchmark::DoNotOptimize(characteristic_scaled(loop, s));
    s += std::complex<double>(0.0, 1e-9);
  }
}
BENCHMARK(BM_CharacteristicScaledSmith);

static void BM_ControllerResponseVsStateSpace(benchmark::State& st) {
  const auto bank = OscillatorBank::with_couplings(1.0, static_cast<int>(st.range(0)), 0.1, -0.1, 20.0);
  const bool use_ss = st.range(1) != 0;
  const StateSpace g = ss(bank);
  const Controller c = bank;
  std::complex<double> s(0.01, 0.7);
  for (auto _ : st) {
    benchmark::DoNotOptimize(use_ss ? g(s) : controller_response(c, s));
    s += std::complex<double>(0.0, 1e-9);
  }
}
BENCHMARK(BM_ControllerResponseVsStateSpace)->Args({10, 0})->Args({10, 1})->Args({40, 0})->Args({40, 1});

// Cost per frequency of every `afmkit control tf` system vs N (issue 6): O(N) — time/N is flat (BigO fit "N").
static void BM_LoopResponsePerFrequency(benchmark::State& st) {
  const LoopSpec loop = bank_loop(static_cast<int>(st.range(0)));
  std::complex<double> s(0.0, 0.7);
  for (auto _ : st) {
    benchmark::DoNotOptimize(evaluate(loop, LoopSystem::ClosedLoop, s));
    s += std::complex<double>(0.0, 1e-9);
  }
  st.SetComplexityN(st.range(0));
}
BENCHMARK(BM_LoopResponsePerFrequency)->RangeMultiplier(10)->Range(10, 100000)->Complexity(benchmark::oN);

// Δ and Δ' per evaluation vs N (the unit of the spectra's cost, docs/commands.md): O(N).
static void BM_CharacteristicPerEvaluation(benchmark::State& st) {
  const LoopSpec loop = bank_loop(static_cast<int>(st.range(0)));
  std::complex<double> s(-0.05, 0.7);
  for (auto _ : st) {
    benchmark::DoNotOptimize(characteristic_scaled(loop, s));
    s += std::complex<double>(0.0, 1e-9);
  }
  st.SetComplexityN(st.range(0));
}
BENCHMARK(BM_CharacteristicPerEvaluation)->RangeMultiplier(10)->Range(10, 100000)->Complexity(benchmark::oN);

static void BM_FrequencyResponse1000(benchmark::State& st) {
  const LoopSpec loop = bank_loop(10);
  const auto w = frequency_grid(0.01, 10.0, 1000, true);
  for (auto _ : st) benchmark::DoNotOptimize(frequency_response(loop, LoopSystem::ClosedLoop, w));
}
BENCHMARK(BM_FrequencyResponse1000);

BENCHMARK_MAIN();
