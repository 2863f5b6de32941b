// Built-in samples, checked against integer-arithmetic predictions (grating, steps), a brute-force renderer and the
// sphere-cap volume (particles), and direct autocorrelation sums (rough).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <cstring>
#include <numbers>
#include <random>
#include <tuple>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/levelling.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "scan_test_dir.hpp"

using afmkit::InvalidParameter;
using namespace afmkit::scan;

namespace {

using scan_test::rejected;

// Centred grid of nx × ny square pixels of side `pixel`.
Grid centred(long nx, long ny, double pixel) {
  return Grid{nx, ny, nx * pixel, ny * pixel, -0.5 * nx * pixel, -0.5 * ny * pixel};
}

// Floor division for integers.
long floor_div(long a, long b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0)) ? 1 : 0); }

}  // namespace

TEST(SampleNames, AreTheCommandLineSpellings) {
  EXPECT_EQ(sample_names.size(), 5u);
  EXPECT_NE(std::find(sample_names.begin(), sample_names.end(), "particles"), sample_names.end());
  EXPECT_EQ(sample_names.front(), "flat");
}

TEST(Flat, IsZeroEverywhereWithEveryPixelValid) {
  const HeightMap m = flat(centred(7, 5, 1e-7));
  EXPECT_EQ(m.x_resolution(), 7);
  EXPECT_EQ(m.z_unit(), "m");
  EXPECT_EQ(m.valid_count(), 35u);
  for (const double z : m.data()) EXPECT_EQ(z, 0.0);
}

TEST(SampleGenerators, BadGridsAreNamedLikeHeightMapNamesThem) {
  for (const auto& make : std::vector<std::function<void(const Grid&)>>{
           [](const Grid& g) { flat(g); }, [](const Grid& g) { grating(g, {}); }, [](const Grid& g) { steps(g, {}); },
           [](const Grid& g) { particles(g, {0, 1e-9, 1}); }, [](const Grid& g) { rough(g, {}); }}) {
    EXPECT_EQ(rejected([&] { make(Grid{0, 4, 1e-5, 1e-5}); }), "x_resolution");
    EXPECT_EQ(rejected([&] { make(Grid{4, -3, 1e-5, 1e-5}); }), "y_resolution");
    EXPECT_EQ(rejected([&] { make(Grid{1L << 30, 1L << 30, 1e-5, 1e-5}); }), "x_resolution");  // no overflow
    EXPECT_EQ(rejected([&] { make(Grid{4, 4, NAN, 1e-5}); }), "x_size");
    EXPECT_EQ(rejected([&] { make(Grid{4, 4, 1e-5, 1e-5, 0.0, INFINITY}); }), "y_offset");
  }
}

TEST(Grating, HighColumnsFollowIntegerArithmeticAndTheDuty) {
  // Period = 10 pixels, centred 200 × 30 grid: column i has centre x = (i − 100 + ½)·dx, so its phase in periods is
  // ((i − 100) mod 10 + ½)/10 and it is high exactly when (i − 100) mod 10 < 10·duty − ½, i.e. residues 0, 1, 2
  // for duty 0.3: a fraction 0.3 of the columns.
  const double dx = 50e-9;
  const GratingSpec spec{10 * dx, 15e-9, 0.3, 0.0};
  const HeightMap m = grating(centred(200, 30, dx), spec);
  long high = 0;
  for (long j = 0; j < 30; ++j)
    for (long i = 0; i < 200; ++i) {
      const long residue = (i - 100) - 10 * floor_div(i - 100, 10);
      EXPECT_EQ(m(i, j), residue < 3 ? 15e-9 : 0.0) << i << ", " << j;
      high += m(i, j) != 0.0;
    }
  EXPECT_EQ(high, 3 * 20 * 30);
  // Lines along x for angle π/2: on a square grid the transpose of the angle-0 map.
  const HeightMap a = grating(centred(60, 60, dx), spec);
  const HeightMap b = grating(centred(60, 60, dx), GratingSpec{10 * dx, 15e-9, 0.3, std::numbers::pi / 2});
  for (long j = 0; j < 60; ++j)
    for (long i = 0; i < 60; ++i) ASSERT_EQ(b(i, j), a(j, i)) << i << ", " << j;
}

TEST(Grating, AnObliqueGratingCoversTheDutyFractionOfTheMap) {
  // 1000 × 1000 pixels, period 12.5 pixels (80 periods across): whole periods cover exactly `duty`; the partial
  // periods at the edges change the fraction by at most about one period over the map side (1/80), and each
  // pixel row / column by at most one pixel per period (1/12.5 of a period) — so 1.5 % is a safe band.
  const double dx = 10e-9;
  const GratingSpec spec{12.5 * dx, 5e-9, 0.4, 0.7};
  const HeightMap m = grating(centred(1000, 1000, dx), spec);
  const double fraction = static_cast<double>(std::count(m.data().begin(), m.data().end(), 5e-9)) / 1e6;
  EXPECT_EQ(std::count(m.data().begin(), m.data().end(), 0.0) + std::count(m.data().begin(), m.data().end(), 5e-9),
            1000000);
  EXPECT_NEAR(fraction, 0.4, 0.015);
}

TEST(Grating, EachBadFieldIsNamed) {
  const Grid g = centred(8, 8, 1e-7);
  EXPECT_EQ(rejected([&] { grating(g, {0.0, 1e-9, 0.5, 0}); }), "grating.period");
  EXPECT_EQ(rejected([&] { grating(g, {-1e-6, 1e-9, 0.5, 0}); }), "grating.period");
  EXPECT_EQ(rejected([&] { grating(g, {INFINITY, 1e-9, 0.5, 0}); }), "grating.period");
  EXPECT_EQ(rejected([&] { grating(g, {1e-6, NAN, 0.5, 0}); }), "grating.height");
  EXPECT_EQ(rejected([&] { grating(g, {1e-6, 1e-9, 0.0, 0}); }), "grating.duty");
  EXPECT_EQ(rejected([&] { grating(g, {1e-6, 1e-9, 1.0, 0}); }), "grating.duty");
  EXPECT_EQ(rejected([&] { grating(g, {1e-6, 1e-9, NAN, 0}); }), "grating.duty");
  EXPECT_EQ(rejected([&] { grating(g, {1e-6, 1e-9, 0.5, NAN}); }), "grating.angle");
  EXPECT_EQ(rejected([&] { grating(g, {1e-6, -1e-9, 0.99, -4.0}); }), "(accepted)");
}

TEST(Steps, TerracesFollowIntegerArithmeticAndAverageToTheStairSlope) {
  // Width = 8 pixels on a centred 480 × 20 grid: column i is on terrace floor((i − 240)/8), since the centre's
  // extra half pixel never crosses a terrace edge.
  const double dx = 25e-9;
  const StepsSpec spec{8 * dx, 2e-9, 0.0};
  const HeightMap m = steps(centred(480, 20, dx), spec);
  for (long j = 0; j < 20; ++j)
    for (long i = 0; i < 480; ++i)
      ASSERT_EQ(m(i, j), 2e-9 * static_cast<double>(floor_div(i - 240, 8))) << i << ", " << j;
  // Averaged, a staircase is a ramp of slope height/width: the least-squares slope is that, up to the saw-tooth
  // remainder (amplitude height over a row of 60 terraces: relative slope error ~ 1/60 at most).
  const Plane p = fit_plane(m);
  EXPECT_NEAR(p.b, 2e-9 / (8 * dx), 0.02 * 2e-9 / (8 * dx));
  EXPECT_NEAR(p.c, 0.0, 1e-12);
  // Angle π descends along x: z(x) = height · floor(−x / width), the mirror image of the angle-0 map on the
  // symmetric grid (column i has x = −(x of column 479 − i)).
  const HeightMap down = steps(centred(480, 20, dx), StepsSpec{8 * dx, 2e-9, std::numbers::pi});
  for (long i = 0; i < 480; ++i) ASSERT_EQ(down(i, 3), m(479 - i, 3)) << i;
}

TEST(Steps, EachBadFieldIsNamed) {
  const Grid g = centred(8, 8, 1e-7);
  EXPECT_EQ(rejected([&] { steps(g, {0.0, 1e-9, 0}); }), "steps.width");
  EXPECT_EQ(rejected([&] { steps(g, {NAN, 1e-9, 0}); }), "steps.width");
  EXPECT_EQ(rejected([&] { steps(g, {1e-6, INFINITY, 0}); }), "steps.height");
  EXPECT_EQ(rejected([&] { steps(g, {1e-6, 1e-9, -INFINITY}); }), "steps.angle");
}

TEST(Particles, SpheresAreInsideNonOverlappingAndRenderedAsCaps) {
  const double dx = 20e-9, r = 200e-9;
  const Grid g = centred(300, 250, dx);
  const ParticlesSpec spec{40, r, 5};
  const std::vector<Particle> spheres = place_particles(g, spec);
  ASSERT_EQ(spheres.size(), 40u);
  for (std::size_t a = 0; a < spheres.size(); ++a) {
    EXPECT_EQ(spheres[a].radius, r);
    EXPECT_GE(spheres[a].x, g.x_offset + r);
    EXPECT_LE(spheres[a].x, g.x_offset + g.x_size - r);
    EXPECT_GE(spheres[a].y, g.y_offset + r);
    EXPECT_LE(spheres[a].y, g.y_offset + g.y_size - r);
    for (std::size_t b = 0; b < a; ++b)
      EXPECT_GE(std::hypot(spheres[a].x - spheres[b].x, spheres[a].y - spheres[b].y), 2 * r) << a << ", " << b;
  }
  const HeightMap m = particles(g, spec);
  // Brute force: every pixel against every sphere.
  for (long j = 0; j < 250; ++j)
    for (long i = 0; i < 300; ++i) {
      const double x = g.x_offset + (i + 0.5) * dx, y = g.y_offset + (j + 0.5) * dx;
      double z = 0.0;
      for (const Particle& p : spheres) {
        const double d2 = (x - p.x) * (x - p.x) + (y - p.y) * (y - p.y);
        if (d2 < r * r) z = std::max(z, r + std::sqrt(r * r - d2));
      }
      ASSERT_NEAR(m(i, j), z, 1e-15 * r) << i << ", " << j;
    }
  // Top of each sphere: 2r at its centre; the nearest pixel centre is within half a pixel diagonal δ, where the cap
  // is lower by r − sqrt(r² − δ²) < δ²/r.
  const double delta = dx / std::sqrt(2.0);
  for (const Particle& p : spheres) {
    const long i = static_cast<long>(std::floor((p.x - g.x_offset) / dx));
    const long j = static_cast<long>(std::floor((p.y - g.y_offset) / dx));
    EXPECT_LE(m(i, j), 2 * r);
    EXPECT_GE(m(i, j), 2 * r - delta * delta / r);
  }
  EXPECT_LE(*std::max_element(m.data().begin(), m.data().end()), 2 * r);
  // Volume under the surface: each sphere on the plane contributes a cylinder of height r under its equator plus a
  // hemisphere, π r³ + (2/3) π r³. Midpoint sums at r/dx = 10 pixels per radius: the cylinder's edge is a step, so
  // each disc's pixel count is off by ~1 % (lattice points in a circle of radius 10), with random sign from disc
  // to disc: ~0.1 % over 40 discs (other seeds give 0.01–0.03 %); 0.3 % band.
  double volume = 0.0;
  for (const double z : m.data()) volume += z * dx * dx;
  EXPECT_NEAR(volume, 40 * (5.0 / 3.0) * std::numbers::pi * r * r * r, 0.003 * volume);
}

TEST(Particles, SeedsAreReproducibleAndDistinct) {
  const Grid g = centred(64, 64, 50e-9);
  const ParticlesSpec spec{12, 150e-9, 9};
  EXPECT_EQ(particles(g, spec).data(), particles(g, spec).data());
  EXPECT_NE(particles(g, spec).data(), particles(g, ParticlesSpec{12, 150e-9, 10}).data());
  for (const double z : particles(g, ParticlesSpec{0, 150e-9, 9}).data()) EXPECT_EQ(z, 0.0);
}

TEST(Particles, EachBadFieldIsNamed) {
  const Grid g = centred(50, 40, 100e-9);  // 5 µm × 4 µm
  EXPECT_EQ(rejected([&] { particles(g, {-1, 1e-7, 1}); }), "particles.count");
  EXPECT_EQ(rejected([&] { particles(g, {1'000'001, 1e-9, 1}); }), "particles.count");
  EXPECT_EQ(rejected([&] { particles(g, {5, 0.0, 1}); }), "particles.radius");
  EXPECT_EQ(rejected([&] { particles(g, {5, NAN, 1}); }), "particles.radius");
  EXPECT_EQ(rejected([&] { particles(g, {1, 2.01e-6, 1}); }), "particles.radius");  // larger than half of 4 µm
  EXPECT_EQ(rejected([&] { particles(g, {1, 2e-6, 1}); }), "(accepted)");
  // 200 discs of radius 0.1 µm would cover 31 % of the map: placeable. 600 would cover 94 %: more than any
  // packing by random addition reaches, so placement gives up.
  EXPECT_EQ(rejected([&] { particles(g, {200, 1e-7, 1}); }), "(accepted)");
  EXPECT_EQ(rejected([&] { particles(g, {600, 1e-7, 1}); }), "particles.count");
  EXPECT_EQ(rejected([&] { render_particles(g, {Particle{0.0, NAN, 1e-7}}); }), "spheres.y");
  EXPECT_EQ(rejected([&] { render_particles(g, {Particle{0.0, 0.0, -1e-7}}); }), "spheres.radius");
}

TEST(Rough, HasExactRmsZeroMeanAndGaussianAutocorrelation) {
  // 1024 × 512 pixels with dx = ξ/8, dy = ξ/4 (a square map 128 ξ wide, non-square pixels to exercise both kernels).
  const double xi = 400e-9, rms = 3e-9;
  const Grid g{1024, 512, 128 * xi, 128 * xi, -64 * xi, -64 * xi};
  const HeightMap m = rough(g, RoughSpec{rms, xi, 42});
  double sum = 0, sum_squares = 0;
  for (const double z : m.data()) {
    sum += z;
    sum_squares += z * z;
  }
  const double n = static_cast<double>(m.size());
  EXPECT_NEAR(sum / n, 0.0, 1e-14 * rms);
  EXPECT_NEAR(std::sqrt(sum_squares / n), rms, 1e-12 * rms);
  // Autocorrelation at lag ξ (8 columns, 4 rows) and 2ξ, by direct sums over all pixel pairs at that lag:
  // expected rms² e^{−1} = 0.368 rms² and rms² e^{−4} = 0.018 rms².
  const auto correlation = [&](long di, long dj) {
    double s = 0, count = 0;
    for (long j = 0; j + dj < 512; ++j)
      for (long i = 0; i + di < 1024; ++i) {
        s += m(i, j) * m(i + di, j + dj);
        count += 1;
      }
    return s / count / (rms * rms);
  };
  // Statistical tolerance: Bartlett's formula for the variance of a sample autocorrelation ρ̂(h) of a Gaussian
  // field with ρ(d) = exp(−d²/ξ²) over N pixels of area dA gives var ≈ (π ξ² / (2 N dA)) (1 + 3e^{−2} − 4e^{−3/2})
  // = 0.51 · 50.3 / 524288, a standard error 0.007 at h = ξ; the 10 % band (0.037) is over 5 standard errors. The
  // biases (mean removal ~ 1/(map area / ξ²) ~ 1e-4, kernel truncation at 3ξ ~ e^{−18}, sampling of the kernel
  // at ξ/8 and ξ/4 ~ e^{−2π²·4}) are far smaller.
  const double e1 = std::exp(-1.0);
  EXPECT_NEAR(correlation(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(correlation(8, 0), e1, 0.1 * e1);
  EXPECT_NEAR(correlation(0, 4), e1, 0.1 * e1);
  EXPECT_NEAR(correlation(16, 0), std::exp(-4.0), 0.04);  // standard error ~0.006 here too
  EXPECT_NEAR(correlation(0, 8), std::exp(-4.0), 0.04);
  EXPECT_NEAR(correlation(8, 4), std::exp(-2.0), 0.04);   // diagonal: d² = 2ξ²
}

TEST(Rough, SeedsAreReproducibleAndDistinct) {
  const Grid g = centred(64, 48, 50e-9);
  const RoughSpec spec{2e-9, 300e-9, 11};
  EXPECT_EQ(rough(g, spec).data(), rough(g, spec).data());
  const std::vector<double> other = rough(g, RoughSpec{2e-9, 300e-9, 12}).data();
  const std::vector<double> first = rough(g, spec).data();
  long differing = 0;
  for (std::size_t k = 0; k < first.size(); ++k) differing += first[k] != other[k];
  EXPECT_EQ(differing, static_cast<long>(first.size()));
}

TEST(Rough, EachBadFieldIsNamed) {
  const Grid g = centred(40, 20, 100e-9);  // 4 µm × 2 µm, 0.1 µm pixels
  EXPECT_EQ(rejected([&] { rough(g, {0.0, 500e-9, 1}); }), "rough.rms");
  EXPECT_EQ(rejected([&] { rough(g, {-1e-9, 500e-9, 1}); }), "rough.rms");
  EXPECT_EQ(rejected([&] { rough(g, {NAN, 500e-9, 1}); }), "rough.rms");
  EXPECT_EQ(rejected([&] { rough(g, {1e-9, 99e-9, 1}); }), "rough.correlation_length");   // below a pixel
  EXPECT_EQ(rejected([&] { rough(g, {1e-9, 2.01e-6, 1}); }), "rough.correlation_length");  // above the map
  EXPECT_EQ(rejected([&] { rough(g, {1e-9, INFINITY, 1}); }), "rough.correlation_length");
  EXPECT_EQ(rejected([&] { rough(g, {1e-9, 100e-9, 1}); }), "(accepted)");
  EXPECT_EQ(rejected([&] { rough(g, {1e-9, 2e-6, 1}); }), "(accepted)");
  EXPECT_EQ(rejected([&] { rough(Grid{1, 1, 1e-6, 1e-6}, {1e-9, 1e-6, 1}); }), "rough");  // one pixel
}

namespace {
// The rough generator's definition written as plain loops (the pre-blocking code): noise rows drawn in row-major
// order over the padded field, each output summed from 0 in ascending kernel tap, along x then along y; mean
// removed and scaled to the RMS. The register-blocked passes must give these doubles bit for bit.
std::vector<double> rough_by_plain_loops(const Grid& g, const RoughSpec& spec) {
  const long nx = g.x_resolution, ny = g.y_resolution;
  const double dx = g.x_size / static_cast<double>(nx), dy = g.y_size / static_cast<double>(ny);
  const auto kernel = [&](double step) {
    const long half = static_cast<long>(std::ceil(3.0 * spec.correlation_length / step));
    std::vector<double> k;
    for (long m = -half; m <= half; ++m) {
      const double d = static_cast<double>(m) * step / spec.correlation_length;
      k.push_back(std::exp(-2.0 * d * d));
    }
    return k;
  };
  const std::vector<double> kx = kernel(dx), ky = kernel(dy);
  const long px = nx + static_cast<long>(kx.size()) - 1, py = ny + static_cast<long>(ky.size()) - 1;
  std::mt19937_64 generator(spec.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> noise(static_cast<std::size_t>(px)), along_x(static_cast<std::size_t>(py * nx), 0.0),
      out(static_cast<std::size_t>(nx * ny), 0.0);
  for (long j = 0; j < py; ++j) {
    for (double& w : noise) w = normal(generator);
    for (std::size_t m = 0; m < kx.size(); ++m)
      for (long i = 0; i < nx; ++i) along_x[static_cast<std::size_t>(j * nx + i)] += kx[m] * noise[i + m];
  }
  for (long j = 0; j < ny; ++j)
    for (std::size_t m = 0; m < ky.size(); ++m)
      for (long i = 0; i < nx; ++i)
        out[static_cast<std::size_t>(j * nx + i)] += ky[m] * along_x[static_cast<std::size_t>((j + m) * nx + i)];
  double mean = 0.0;
  for (double z : out) mean += z;
  mean /= static_cast<double>(out.size());
  double squares = 0.0;
  for (double& z : out) {
    z -= mean;
    squares += z * z;
  }
  const double scale = spec.rms / std::sqrt(squares / static_cast<double>(out.size()));
  for (double& z : out) z *= scale;
  return out;
}
}  // namespace

TEST(Rough, BlockedFilterGivesThePlainLoopsDoublesBitForBit) {
  // sizes that leave partial blocks (16 along a row, 8 × 4 down the columns) and a kernel longer than the map side;
  // the column pass runs over a window of 64 output rows at a time: 70, 128 and 200 rows take 2, 2 and 4 windows
  // (the last one partial or full)
  for (const auto& [nx, ny, pixel, xi] : {std::tuple{37L, 23L, 50e-9, 300e-9}, std::tuple{64L, 8L, 20e-9, 150e-9},
                                          std::tuple{5L, 70L, 100e-9, 200e-9}, std::tuple{19L, 128L, 50e-9, 150e-9},
                                          std::tuple{23L, 200L, 50e-9, 600e-9}}) {
    const Grid g = centred(nx, ny, pixel);
    const RoughSpec spec{2e-9, xi, 7};
    const std::vector<double> fast = rough(g, spec).data(), plain = rough_by_plain_loops(g, spec);
    ASSERT_EQ(fast.size(), plain.size());
    long differing = 0;
    for (std::size_t k = 0; k < fast.size(); ++k) differing += std::memcmp(&fast[k], &plain[k], sizeof(double)) != 0;
    EXPECT_EQ(differing, 0) << nx << " x " << ny;
  }
}
