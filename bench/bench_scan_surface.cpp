// Surface::operator() (bilinear topography + tilt) per call, and the generation of the rough sample.
//   Spiral:    consecutive samples half a pixel apart along an Archimedean spiral, as a rotational scan visits the
//              map (neighbouring samples share cache lines).
//   Scattered: uniformly random points over the inscribed disc (every call a cache miss on large maps; worst case).
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/scan/surface.hpp"

using namespace afmkit::scan;

namespace {
constexpr double side = 20e-6;
constexpr int points = 1 << 16;

Surface rough_surface(long pixels) {
  return Surface(rough(Grid{pixels, pixels, side, side, -side / 2, -side / 2}, RoughSpec{5e-9, 500e-9, 1}),
                 Tilt(0.01, 0.3));
}

void run(benchmark::State& state, const Surface& surface, const std::vector<double>& xs, const std::vector<double>& ys) {
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(surface(xs[k], ys[k]));
    k = (k + 1) & (points - 1);
  }
  state.SetItemsProcessed(state.iterations());
}
}  // namespace

static void BM_SurfaceCallSpiral(benchmark::State& state) {
  const long pixels = state.range(0);
  const Surface surface = rough_surface(pixels);
  // Spiral r = pitch · θ / 2π from mid-radius, arc step half a pixel, pitch 2 pixels (precomputed).
  const double pixel = side / static_cast<double>(pixels), pitch = 2 * pixel;
  std::vector<double> xs, ys;
  double theta = 2 * std::numbers::pi * (0.5 * surface.inscribed_radius() / pitch);
  for (int k = 0; k < points; ++k) {
    const double r = pitch * theta / (2 * std::numbers::pi);
    xs.push_back(r * std::cos(theta));
    ys.push_back(r * std::sin(theta));
    theta += 0.5 * pixel / r;
  }
  run(state, surface, xs, ys);
}
BENCHMARK(BM_SurfaceCallSpiral)->Arg(512)->Arg(4096);

static void BM_SurfaceCallScattered(benchmark::State& state) {
  const long pixels = state.range(0);
  const Surface surface = rough_surface(pixels);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> xs, ys;
  for (int k = 0; k < points; ++k) {
    const double r = surface.inscribed_radius() * std::sqrt(unit(rng)), phi = 2 * std::numbers::pi * unit(rng);
    xs.push_back(r * std::cos(phi));
    ys.push_back(r * std::sin(phi));
  }
  run(state, surface, xs, ys);
}
BENCHMARK(BM_SurfaceCallScattered)->Arg(512)->Arg(4096);

static void BM_RoughGenerate512(benchmark::State& state) {
  const Grid grid{512, 512, side, side, -side / 2, -side / 2};
  for (auto _ : state) benchmark::DoNotOptimize(rough(grid, RoughSpec{5e-9, 500e-9, 1}));
}
BENCHMARK(BM_RoughGenerate512)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
