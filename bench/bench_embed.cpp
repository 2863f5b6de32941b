// Time per sample of the freestanding C core on the host (float32 and, through the double host build used by the
// exporter, the closed-loop verification), against the double RealtimeFilter. Reference design: 50 Hz spindle,
// f_s = 5 kHz, N harmonics (couplings eq. 20, α = 0.1 Ω, β = −0.1 Ω, K = γ = 20 Ω).
#include <cmath>
#include <numbers>
#include <vector>

#include <benchmark/benchmark.h>

#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/embed/afmkit_embed.h"  // float (afmkit links afmkit_embed_core)
#include "afmkit/embed/design.hpp"

namespace {
afmkit::embed::ExportSpec spec(int n) {
  afmkit::embed::ExportSpec s;
  s.rotation_frequency = 2.0 * std::numbers::pi * 50.0;
  s.sample_rate = 5000.0;
  s.harmonics = n;
  s.alpha = 0.1 * s.rotation_frequency;
  s.beta = -0.1 * s.rotation_frequency;
  s.gain = s.plant_rate = 20.0 * s.rotation_frequency;
  return s;
}

void BM_FloatCoreStep(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  auto s = spec(n);
  s.sample_rate = std::max(5000.0, 4.0 * n * 50.0);  // Nyquist for large N
  const afmkit::embed::ExportedDesign d(s);
  std::vector<float> pair, circle, real;
  for (double x : d.pair_coefficients()) pair.push_back(static_cast<float>(x));
  for (double x : d.circle_coefficients()) circle.push_back(static_cast<float>(x));
  for (double x : d.real_coefficients()) real.push_back(static_cast<float>(x));
  const afmkit_embed_coefficients c = {AFMKIT_EMBED_MAGIC, AFMKIT_EMBED_VERSION, AFMKIT_EMBED_PRECISION_BITS,
                                       static_cast<uint32_t>(d.pairs()), static_cast<uint32_t>(d.circles()),
                                       static_cast<uint32_t>(d.reals()), static_cast<float>(d.input_limit()),
                                       pair.empty() ? nullptr : pair.data(), circle.data(),
                                       real.empty() ? nullptr : real.data()};
  std::vector<float> state(afmkit_embed_state_size(&c));
  afmkit_embed_filter f;
  afmkit_embed_init(&f, &c, state.data(), state.size());
  float u = 0.0f, x = 0.0f;
  for (auto _ : st) {
    x = 0.7f - 0.999f * x;
    u = afmkit_embed_step(&f, x + u * 1e-4f);
    benchmark::DoNotOptimize(u);
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_FloatCoreStep)->Arg(1)->Arg(10)->Arg(40)->Arg(100);

void BM_RealtimeFilterStep(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  auto s = spec(n);
  s.sample_rate = std::max(5000.0, 4.0 * n * 50.0);
  afmkit::control::RealtimeFilter f(s.bank(), s.sample_rate);
  double u = 0.0, x = 0.0;
  for (auto _ : st) {
    x = 0.7 - 0.999 * x;
    u = f.step(x + u * 1e-4);
    benchmark::DoNotOptimize(u);
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_RealtimeFilterStep)->Arg(1)->Arg(10)->Arg(40)->Arg(100);
}  // namespace
BENCHMARK_MAIN();
