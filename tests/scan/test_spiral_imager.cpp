// SpiralImager: every image is compared with the field the samples were taken from, evaluated by the test at the
// pixel centres (x = x_offset + (i + ½)dx, y = y_offset + (j + ½)dy), within the error bound derived in
// spiral_imager.hpp; the filled region is compared with the spiral's own geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/spiral_imager.hpp"
#include "scan_test_dir.hpp"

using afmkit::InvalidParameter;
using afmkit::scan::Grid;
using afmkit::scan::HeightMap;
using afmkit::scan::SpiralImager;

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kEps = std::numeric_limits<double>::epsilon();

using Field = std::function<double(double, double)>;
using Radius = std::function<double(double)>;

struct Pixel {
  long i, j;
  double x, y, rho, angle;  // angle in [0, 2π)
};

std::vector<Pixel> pixels(const Grid& g) {
  std::vector<Pixel> out;
  for (long j = 0; j < g.y_resolution; ++j)
    for (long i = 0; i < g.x_resolution; ++i) {
      const double x = g.x_offset + (static_cast<double>(i) + 0.5) * g.x_size / static_cast<double>(g.x_resolution);
      const double y = g.y_offset + (static_cast<double>(j) + 0.5) * g.y_size / static_cast<double>(g.y_resolution);
      double a = std::atan2(y, x);
      if (a < 0) a += kTwoPi;
      out.push_back({i, j, x, y, std::hypot(x, y), a});
    }
  return out;
}

/// Angles of an ideal scan: `per_turn` equal steps per turn from theta_first over `turns` turns.
std::vector<double> uniform_angles(double theta_first, int per_turn, double turns) {
  const auto n = static_cast<long>(std::llround(turns * per_turn));
  std::vector<double> theta(static_cast<std::size_t>(n) + 1);
  for (long k = 0; k <= n; ++k) theta[static_cast<std::size_t>(k)] = theta_first + kTwoPi * static_cast<double>(k) / per_turn;
  return theta;
}

/// Feeds the samples (θ_n, r(θ_n), field_c(r cos θ, r sin θ)) and returns the images. `tamper(n, values)` may spoil
/// a sample's values.
std::vector<HeightMap> image(const Grid& g, int m, const std::vector<double>& theta, const Radius& radius,
                             const std::vector<Field>& fields,
                             const std::function<void(std::size_t, std::vector<double>&)>& tamper = {}) {
  SpiralImager imager(g, std::vector<std::string>(fields.size(), "m"), m);
  std::vector<double> values(fields.size());
  for (std::size_t n = 0; n < theta.size(); ++n) {
    const double r = radius(theta[n]);
    for (std::size_t c = 0; c < fields.size(); ++c) values[c] = fields[c](r * std::cos(theta[n]), r * std::sin(theta[n]));
    if (tamper) tamper(n, values);
    imager.add(theta[n], r, values);
  }
  EXPECT_EQ(imager.samples(), static_cast<long>(theta.size()));
  return imager.finish();
}

/// The smooth test field z = A sin(x/L + 0.3) cos(y/L − 0.7) + a x + b y + c, with the bounds of its derivatives:
/// Hessian eigenvalues −(A/L²) sin(X ± Y), so ‖H‖ ≤ A/L²; |∇z| ≤ A/L + |(a, b)|.
struct Smooth {
  double amplitude = 20e-9, length = 1e-6, a = 3e-3, b = -2e-3, c = 4e-9;
  double operator()(double x, double y) const {
    return amplitude * std::sin(x / length + 0.3) * std::cos(y / length - 0.7) + a * x + b * y + c;
  }
  double hessian() const { return amplitude / (length * length); }
  double gradient() const { return amplitude / length + std::hypot(a, b); }
};

/// The header's bound: K = (R² + ρ'²)H + √(R² + 4ρ'²)G; |error| ≤ p²H/8 + (Δθ² + Δφ²)K/8 (strips), and in the centre
/// disc (radius r0 = max radius of turn 0) Λ(E₁ + H r0²/2) + E₁ + E₂ + H r0²/8 with Λ = 1 (the plane fit's weights
/// over a turn starting within a pitch of the centre are positive: checked offline, M = 16 … 2000, start 0 … 1 pitch).
struct Bound {
  double hessian, gradient, radius, radial_speed, step, table_step, pitch;
  double k() const {
    return (radius * radius + radial_speed * radial_speed) * hessian +
           std::sqrt(radius * radius + 4 * radial_speed * radial_speed) * gradient;
  }
  double strip() const { return pitch * pitch * hessian / 8 + (step * step + table_step * table_step) * k() / 8; }
  double centre(double r0) const {
    const double e1 = step * step * k() / 8, e2 = table_step * table_step * k() / 8;
    return (e1 + hessian * r0 * r0 / 2) + e1 + e2 + hessian * r0 * r0 / 8;
  }
};

double value(const HeightMap& m, const Pixel& p) { return m(p.i, p.j); }

// Equal, or both NaN.
bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

}  // namespace

// A smooth field on a fine ideal spiral from the centre: within the derived bound everywhere, no hole inside
// r_end − pitch, nothing at or beyond r_end. Non-square pixels, grid not centred on the axis, first angle negative,
// table size different from the samples per turn.
TEST(SpiralImager, SmoothFieldFromTheCentreWithinTheDerivedBound) {
  const Grid g{96, 80, 10e-6, 8.4e-6, -5.2e-6, -4.1e-6};
  const Smooth z;
  const double pitch = 0.04e-6, turns = 150, r_end = pitch * turns;
  const int per_turn = 1500, m = 1200;
  const double theta_first = -3.7;
  const auto theta = uniform_angles(theta_first, per_turn, turns);
  const Radius radius = [&](double t) { return pitch * (t - theta_first) / kTwoPi; };
  const auto maps = image(g, m, theta, radius, {z});
  ASSERT_EQ(maps.size(), 1u);
  const HeightMap& out = maps[0];
  EXPECT_EQ(out.z_unit(), "m");

  const Bound bound{z.hessian(), z.gradient(), r_end, pitch / kTwoPi, kTwoPi / per_turn, kTwoPi / m, pitch};
  const double rounding = 64 * kEps * (z.amplitude + z.c + std::hypot(z.a, z.b) * r_end);
  // The bound is far below the error of a nearest-turn image (~|∇z|·pitch/2): the test can fail.
  EXPECT_LT(bound.strip(), 0.02 * z.gradient() * pitch / 2);
  double worst = 0.0;
  long checked = 0;
  for (const Pixel& p : pixels(g)) {
    const double v = value(out, p);
    if (p.rho < r_end - pitch) {
      ASSERT_TRUE(std::isfinite(v)) << "hole at " << p.i << "," << p.j << " rho " << p.rho;
      ASSERT_TRUE(out.valid(p.i, p.j));
    }
    if (p.rho >= r_end) {
      EXPECT_FALSE(out.valid(p.i, p.j)) << p.i << "," << p.j;
      continue;
    }
    if (!std::isfinite(v)) continue;
    const double tolerance = (p.rho < pitch ? bound.centre(pitch) : bound.strip()) + rounding;
    EXPECT_NEAR(v, z(p.x, p.y), tolerance) << p.i << "," << p.j << " rho " << p.rho;
    worst = std::max(worst, std::abs(v - z(p.x, p.y)) / tolerance);
    ++checked;
  }
  EXPECT_GT(checked, 5000);
  RecordProperty("worst_error_over_bound", std::to_string(worst));
}

// The disc inside turn 0 (rule 3): a coarse pitch (4 pixels) so that it holds many pixels. Scans starting at the
// axis and half a pitch from it fill it within the centre bound (smooth field) and the chord bound (plane); a scan
// starting 1.2 pitches out leaves every pixel inside its first turn invalid.
TEST(SpiralImager, CentreDiscFilledWhenTheScanStartsWithinAPitch) {
  const Grid g{64, 64, 6.4e-6, 6.4e-6, -3.23e-6, -3.18e-6};
  Smooth z;
  z.length = 2e-6;
  const double ga = 0.02, gb = -0.035, gc = 1e-8;
  const Field plane = [&](double x, double y) { return ga * x + gb * y + gc; };
  const double pitch = 0.4e-6, turns = 7.6;
  const int per_turn = 2000, m = 1800;
  for (const double start : {0.0, 0.5, 1.2}) {
    const double r_start = start * pitch, r_end = r_start + pitch * turns, r0 = r_start + pitch;
    const auto theta = uniform_angles(0.3, per_turn, turns);
    const Radius radius = [&](double t) { return r_start + pitch * (t - 0.3) / kTwoPi; };
    SpiralImager imager(g, {"m", "m"}, m);
    for (double t : theta) {
      const double r = radius(t), x = r * std::cos(t), y = r * std::sin(t);
      const double v[2] = {z(x, y), plane(x, y)};
      imager.add(t, r, v);
    }
    EXPECT_EQ(imager.centre_filled(), start < 1.0) << start;
    const auto maps = imager.finish();
    const Bound smooth{z.hessian(), z.gradient(), r_end, pitch / kTwoPi, kTwoPi / per_turn, kTwoPi / m, pitch};
    const Bound flat{0.0, std::hypot(ga, gb), r_end, pitch / kTwoPi, kTwoPi / per_turn, kTwoPi / m, pitch};
    const double rounding = 64 * kEps * (z.amplitude + gc + std::hypot(ga, gb) * r_end);
    long centre = 0;
    for (const Pixel& p : pixels(g)) {
      const double v = value(maps[0], p), w = value(maps[1], p);
      if (start < 1.0 && p.rho < r_end - pitch) {
        ASSERT_TRUE(std::isfinite(v) && std::isfinite(w)) << start << " hole at " << p.i << "," << p.j;
      }
      if (start > 1.0 && p.rho < r_start) {
        EXPECT_FALSE(maps[0].valid(p.i, p.j) || maps[1].valid(p.i, p.j)) << start << " " << p.i << "," << p.j;
      }
      if (!std::isfinite(v)) continue;
      const bool in_centre = p.rho < r0;
      EXPECT_NEAR(v, z(p.x, p.y), (in_centre ? smooth.centre(r0) : smooth.strip()) + rounding) << start;
      EXPECT_NEAR(w, plane(p.x, p.y), (in_centre ? flat.centre(r0) : flat.strip()) + rounding) << start;
      const double phi = std::fmod(std::fmod(p.angle - 0.3, kTwoPi) + kTwoPi, kTwoPi);
      centre += p.rho < r_start + pitch * phi / kTwoPi;  // inside turn 0
    }
    if (start < 1.0) {
      EXPECT_GE(centre, 10) << start;
    }
  }
  // The centre bound matters: well below the error of a constant centre value (such as the first sample's), which
  // is ~|∇z|·r0 at the rim; the plane's centre bound is far smaller still.
  const double r0 = 1.5 * pitch;
  const Bound smooth{z.hessian(), z.gradient(), 3.5e-6, pitch / kTwoPi, kTwoPi / per_turn, kTwoPi / m, pitch};
  const Bound flat{0.0, std::hypot(ga, gb), 3.5e-6, pitch / kTwoPi, kTwoPi / per_turn, kTwoPi / m, pitch};
  EXPECT_LT(smooth.centre(r0), 0.25 * z.gradient() * r0);
  EXPECT_LT(flat.centre(r0), 1e-3 * std::hypot(ga, gb) * r0);
}

// A plane is not reproduced to rounding (the angular interpolation is linear in θ, a plane along a circle is a
// sinusoid): error ≤ (Δθ² + Δφ²)√(R² + 4ρ'²)|∇z|/8, and in the centre disc the plane fit adds at most E₁. Scan starting
// half a pitch from the axis: the centre is still filled (rule 3).
TEST(SpiralImager, PlaneWithinTheChordBoundCentreIncluded) {
  const Grid g{64, 64, 8e-6, 8e-6, -4e-6, -4e-6};
  const double a = 0.02, b = -0.035, c = 1e-8;
  const Field plane = [&](double x, double y) { return a * x + b * y + c; };
  const double pitch = 0.1e-6, r_start = 0.5 * pitch, turns = 40, r_end = r_start + pitch * turns;
  const int per_turn = 300, m = 256;
  const auto theta = uniform_angles(0.25, per_turn, turns);
  const Radius radius = [&](double t) { return r_start + pitch * (t - 0.25) / kTwoPi; };
  SpiralImager imager(g, {"V"}, m);
  for (double t : theta) {
    const double r = radius(t);
    const double v[1] = {plane(r * std::cos(t), r * std::sin(t))};
    imager.add(t, r, v);
  }
  EXPECT_TRUE(imager.centre_filled());  // min r_0 = p/2 <= p: rule 3 applies
  const auto maps = imager.finish();
  EXPECT_EQ(maps[0].z_unit(), "V");
  const Bound bound{0.0, std::hypot(a, b), r_end, pitch / kTwoPi, kTwoPi / per_turn, kTwoPi / m, pitch};
  const double rounding = 64 * kEps * (c + std::hypot(a, b) * r_end);
  for (const Pixel& p : pixels(g)) {
    const double v = value(maps[0], p);
    if (p.rho < r_end - pitch) {
      ASSERT_TRUE(std::isfinite(v)) << p.i << "," << p.j;
    }
    if (!std::isfinite(v)) continue;
    const double tolerance = (p.rho < r_start + pitch ? bound.centre(r_start + pitch) : bound.strip()) + rounding;
    EXPECT_NEAR(v, plane(p.x, p.y), tolerance) << p.i << "," << p.j;
  }
  EXPECT_LT(bound.strip(), 1e-2 * std::hypot(a, b) * pitch);  // far below the change of z over one pitch
}

// z = c + q·ρ is linear along every ray and the tables interpolate radius and value with the same weights, so the
// image is exact to rounding, for any spiral shape and any table size (finer or coarser than the sampling).
TEST(SpiralImager, ConeIsExactToRounding) {
  const Grid g{50, 70, 9e-6, 11e-6, -4e-6, -6.5e-6};
  const double c = -3e-9, q = 0.04;
  const Field cone = [&](double x, double y) { return c + q * std::hypot(x, y); };
  const double pitch = 0.15e-6, r_start = 1.1e-6, turns = 30.4, r_end = r_start + pitch * turns;
  struct Case { int per_turn, m; };
  for (const Case k : {Case{1500, 1200}, Case{50, 400}, Case{333, 16}}) {
    const auto theta = uniform_angles(2.0, k.per_turn, turns);
    const Radius radius = [&](double t) { return r_start + pitch * (t - 2.0) / kTwoPi; };
    const auto maps = image(g, k.m, theta, radius, {cone});
    long filled = 0;
    for (const Pixel& p : pixels(g)) {
      const double v = value(maps[0], p);
      if (p.rho < r_start || p.rho >= r_end) {
        EXPECT_FALSE(std::isfinite(v)) << p.i << "," << p.j;
      }
      if (p.rho >= r_start + pitch && p.rho < r_end - pitch) {
        EXPECT_TRUE(std::isfinite(v)) << p.i << "," << p.j;
      }
      if (!std::isfinite(v)) continue;
      EXPECT_NEAR(v, c + q * p.rho, 16 * kEps * (std::abs(c) + q * r_end)) << k.per_turn << " " << k.m;
      ++filled;
    }
    EXPECT_GT(filled, 1000);
  }
}

// The filled region is exactly the spiral's swept band: pixel (ρ, φ) is valid iff r(θ_in) ≤ ρ < r(θ_out), θ_in the
// first angle ≥ θ₀ with the pixel's direction (inner edge = turn 0) and θ_out the last angle ≤ θ_last with it
// (outer edge = the spiral up to the last sample, partial last turn included). No centre fill: starts 3 pitches out.
TEST(SpiralImager, FilledRegionIsTheSweptBandUpToTheLastSample) {
  const Grid g{90, 90, 6e-6, 6e-6, -3.1e-6, -2.95e-6};
  const double pitch = 0.21e-6, r_start = 3 * pitch;
  const double theta_first = 11.0;
  const double turns = 9.37;  // ends inside a turn
  const int per_turn = 700, m = 640;
  const auto theta = uniform_angles(theta_first, per_turn, turns);
  const double theta_last = theta.back();
  const Radius radius = [&](double t) { return r_start + pitch * (t - theta_first) / kTwoPi; };
  SpiralImager imager(g, {"m"}, m);
  const double v[1] = {1.0};
  for (double t : theta) imager.add(t, radius(t), v);
  EXPECT_EQ(imager.complete_turns(), 9);
  EXPECT_FALSE(imager.centre_filled());
  const HeightMap out = imager.finish().at(0);
  const double slack = 1e-9 * radius(theta_last);
  long inside = 0, compared = 0;
  for (const Pixel& p : pixels(g)) {
    const double phi = std::fmod(std::fmod(p.angle - theta_first, kTwoPi) + kTwoPi, kTwoPi);  // [0, 2π)
    const double theta_in = theta_first + phi;
    const double back = std::fmod(std::fmod(theta_last - theta_in, kTwoPi) + kTwoPi, kTwoPi);
    const double theta_out = theta_last - back;
    const double r_in = radius(theta_in), r_out = radius(theta_out);
    if (std::abs(p.rho - r_in) < slack || std::abs(p.rho - r_out) < slack) continue;  // on an edge: rounding decides
    if (phi < 1e-9 || phi > kTwoPi - 1e-9 || back < 1e-9 || back > kTwoPi - 1e-9) continue;  // on a seam
    const bool expected = p.rho >= r_in && p.rho < r_out;
    EXPECT_EQ(out.valid(p.i, p.j), expected) << p.i << "," << p.j << " rho " << p.rho << " in " << r_in << " out "
                                             << r_out;
    if (expected) {
      EXPECT_EQ(out(p.i, p.j), 1.0);
    }
    inside += expected;
    ++compared;
  }
  EXPECT_GT(inside, 3000);
  EXPECT_GT(compared, 8000);
}

// Non-uniform sample rate (random steps, modulated spindle speed), accelerating radial speed and an eccentric wobble
// of the radius: no hole between turn 0 and the last complete turn, nothing outside the swept radii, a cone exact to
// rounding and a smooth field within the bound computed with the largest step and the largest pitch.
TEST(SpiralImager, IrregularSamplingAndNonLinearRadiusStillFill) {
  const Grid g{72, 72, 9e-6, 9e-6, -4.5e-6, -4.5e-6};
  const double p0 = 0.06e-6, eccentricity = 0.3 * p0, r_start = 0.8e-6, turns_end = 30.0;
  const double theta_first = 0.9;
  const Radius radius = [&](double t) {
    const double tau = (t - theta_first) / kTwoPi;
    return r_start + p0 * tau * (1 + 0.5 * tau / turns_end) + eccentricity * std::sin(t + 0.4);
  };
  std::mt19937_64 random(12345);
  std::uniform_real_distribution<double> jitter(0.5, 1.5);
  const double omega_h = kTwoPi / 400;  // mean angle step: 400 samples per turn
  std::vector<double> theta;
  double time = 0.0, step_max = 0.0;
  for (;;) {
    const double t = theta_first + time + 0.4 * std::sin(0.37 * time);
    if (!theta.empty()) step_max = std::max(step_max, t - theta.back());
    theta.push_back(t);
    if (t > theta_first + kTwoPi * turns_end) break;
    time += omega_h * jitter(random);
  }
  const double theta_last = theta.back();
  const Smooth z;
  const double c = 2e-9, q = -0.01;
  const Field cone = [&](double x, double y) { return c + q * std::hypot(x, y); };
  const auto maps = image(g, 500, theta, radius, {z, cone});

  // Edges of the band that must be filled, from the spiral itself (dense evaluation).
  auto extreme = [&](double from, double to, bool want_max) {
    double e = radius(from);
    for (int k = 1; k <= 20000; ++k) {
      const double r = radius(from + (to - from) * k / 20000.0);
      e = want_max ? std::max(e, r) : std::min(e, r);
    }
    return e;
  };
  const auto complete = static_cast<long>(std::floor((theta_last - theta_first) / kTwoPi));
  const double margin = 1e-3 * p0;  // tables interpolate r between samples: Δθ²|r''|/8 ≪ this
  const double fill_from = extreme(theta_first, theta_first + kTwoPi, true) + margin;
  const double fill_to = extreme(theta_first + kTwoPi * (complete - 1), theta_first + kTwoPi * complete, false) - margin;
  const double r_min = extreme(theta_first, theta_first + kTwoPi, false) - margin;
  const double r_max = extreme(theta_first, theta_last, true) + margin;
  ASSERT_GT(fill_to, fill_from + 10 * p0);

  const double pitch_max = p0 * (2 + 0.5 / turns_end) * 1.01;  // r(θ + 2π) − r(θ) ≤ p0(1 + (2τ + 1)/(2 τ_end))
  const double radial_speed = p0 / kTwoPi * 2 + eccentricity;
  const Bound bound{z.hessian(), z.gradient(), r_max, radial_speed, step_max, kTwoPi / 500, pitch_max};
  EXPECT_LT(bound.strip(), 0.1 * z.gradient() * pitch_max / 2);  // a nearest-turn image: ~|∇z|·pitch/2
  long filled = 0;
  for (const Pixel& p : pixels(g)) {
    const bool valid0 = maps[0].valid(p.i, p.j), valid1 = maps[1].valid(p.i, p.j);
    EXPECT_EQ(valid0, valid1);
    if (p.rho >= fill_from && p.rho < fill_to) {
      EXPECT_TRUE(valid0) << "hole at " << p.i << "," << p.j;
    }
    if (p.rho < r_min || p.rho >= r_max) {
      EXPECT_FALSE(valid0) << p.i << "," << p.j;
    }
    if (!valid0) continue;
    EXPECT_NEAR(value(maps[0], p), z(p.x, p.y), bound.strip()) << p.i << "," << p.j;
    EXPECT_NEAR(value(maps[1], p), c + q * p.rho, 16 * kEps * (c + std::abs(q) * r_max));
    ++filled;
  }
  EXPECT_GT(filled, 2000);
}

// An inward spiral (radius decreasing) fills its band the same way.
TEST(SpiralImager, InwardSpiralFillsItsBand) {
  const Grid g{40, 40, 6e-6, 6e-6, -3e-6, -3e-6};
  const double pitch = 0.1e-6, r_outer = 2.9e-6, turns = 15;
  const auto theta = uniform_angles(0.0, 200, turns);
  const Radius radius = [&](double t) { return r_outer - pitch * t / kTwoPi; };
  const double c = 1e-9, q = 0.05;
  const auto maps = image(g, 180, theta, radius, {[&](double x, double y) { return c + q * std::hypot(x, y); }});
  const double r_inner = r_outer - pitch * turns;
  long filled = 0;
  for (const Pixel& p : pixels(g)) {
    const bool valid = maps[0].valid(p.i, p.j);
    if (p.rho > r_inner + pitch && p.rho < r_outer - pitch) {
      EXPECT_TRUE(valid) << p.i << "," << p.j;
    }
    if (p.rho < r_inner || p.rho > r_outer) {
      EXPECT_FALSE(valid) << p.i << "," << p.j;
    }
    if (valid) {
      EXPECT_NEAR(value(maps[0], p), c + q * p.rho, 16 * kEps * (c + q * r_outer));
    }
    filled += valid;
  }
  EXPECT_GT(filled, 300);
}

// Channels do not interact: each channel of a 3-channel run is bitwise the single-channel image of its field, also
// when one channel has bad samples.
TEST(SpiralImager, ChannelsAreIndependent) {
  const Grid g{48, 48, 6e-6, 6e-6, -3e-6, -3e-6};
  const Smooth z;
  const std::vector<Field> fields{z, [](double x, double y) { return 5 * x - y; },
                                  [](double x, double y) { return std::cos(3e6 * x) * y; }};
  const double pitch = 0.08e-6;
  const auto theta = uniform_angles(1.0, 400, 38);
  const Radius radius = [&](double t) { return pitch * (t - 1.0) / kTwoPi; };
  const auto spoil = [](std::size_t n, std::vector<double>& v) {
    if (n % 997 == 0) v[1] = kNaN;
  };
  const auto all = image(g, 350, theta, radius, fields, spoil);
  for (std::size_t c = 0; c < fields.size(); ++c) {
    const auto alone = image(g, 350, theta, radius, {fields[c]}, [&](std::size_t n, std::vector<double>& v) {
      if (c == 1 && n % 997 == 0) v[0] = kNaN;
    });
    ASSERT_EQ(alone[0].size(), all[c].size());
    for (std::size_t k = 0; k < all[c].size(); ++k) ASSERT_TRUE(same(all[c].data()[k], alone[0].data()[k])) << c << " " << k;
  }
  EXPECT_LT(all[1].valid_count(), all[0].valid_count());
  EXPECT_EQ(all[2].valid_count(), all[0].valid_count());
}

// One bad sample invalidates only pixels near it (within a pitch plus an angular step or two, the distance bound
// below) in its channel; every other pixel keeps exactly the value of the clean scan.
TEST(SpiralImager, NaNSampleInvalidatesOnlyNearbyPixels) {
  const Grid g{80, 80, 10e-6, 10e-6, -5e-6, -5e-6};
  const Smooth z;
  const double pitch = 0.25e-6;
  const int per_turn = 100, m = 90;
  const auto theta = uniform_angles(0.0, per_turn, 19.5);
  const Radius radius = [&](double t) { return pitch * t / kTwoPi; };
  const std::size_t bad = 12 * per_turn + 37;  // r ≈ 3.09 µm
  const auto clean = image(g, m, theta, radius, {z, z});
  const auto dirty = image(g, m, theta, radius, {z, z}, [&](std::size_t n, std::vector<double>& v) {
    if (n == bad) v[0] = kNaN;
  });
  const double r_bad = radius(theta[bad]);
  const double x_bad = r_bad * std::cos(theta[bad]), y_bad = r_bad * std::sin(theta[bad]);
  // Entries within Δθ of the sample; a pixel uses entries within Δφ of its angle and lies within a pitch radially.
  const double angle = kTwoPi / per_turn + kTwoPi / m;
  const double reach = pitch + pitch / kTwoPi * angle + (r_bad + 2 * pitch) * angle;
  long lost = 0;
  for (const Pixel& p : pixels(g)) {
    const double a = clean[0](p.i, p.j), b = dirty[0](p.i, p.j);
    EXPECT_TRUE(same(clean[1](p.i, p.j), dirty[1](p.i, p.j)));
    if (std::isfinite(b)) {
      EXPECT_EQ(a, b) << p.i << "," << p.j;
    } else if (std::isfinite(a)) {
      EXPECT_LE(std::hypot(p.x - x_bad, p.y - y_bad), reach) << p.i << "," << p.j;
      EXPECT_FALSE(dirty[0].valid(p.i, p.j));
      ++lost;
    }
  }
  EXPECT_GE(lost, 1);
  EXPECT_LE(lost, 40);
}

// Less than one turn gives no image; counters.
TEST(SpiralImager, LessThanOneTurnGivesNoImage) {
  const Grid g{20, 20, 2e-6, 2e-6, -1e-6, -1e-6};
  SpiralImager imager(g, {"m", "V"}, 64);
  const double v[2] = {1.0, 2.0};
  const auto theta = uniform_angles(0.0, 64, 0.95);
  for (double t : theta) imager.add(t, 1e-7 * t, v);
  EXPECT_EQ(imager.complete_turns(), 0);
  EXPECT_EQ(imager.samples(), static_cast<long>(theta.size()));
  EXPECT_EQ(imager.channels(), 2u);
  EXPECT_EQ(imager.angular_samples(), 64);
  const auto maps = imager.finish();
  ASSERT_EQ(maps.size(), 2u);
  EXPECT_EQ(maps[0].valid_count(), 0u);
  EXPECT_EQ(maps[1].z_unit(), "V");
  EXPECT_TRUE(maps[1].has_mask());
}

using scan_test::rejected;

TEST(SpiralImager, BadInputIsNamed) {
  const Grid g{8, 8, 1e-6, 1e-6, -5e-7, -5e-7};
  EXPECT_EQ(rejected([&] { SpiralImager(Grid{0, 8, 1e-6, 1e-6}, {"m"}, 64); }), "x_resolution");
  EXPECT_EQ(rejected([&] { SpiralImager(Grid{8, 0, 1e-6, 1e-6}, {"m"}, 64); }), "y_resolution");
  EXPECT_EQ(rejected([&] { SpiralImager(Grid{8, 8, -1e-6, 1e-6}, {"m"}, 64); }), "x_size");
  EXPECT_EQ(rejected([&] { SpiralImager(Grid{8, 8, 1e-6, NAN}, {"m"}, 64); }), "y_size");
  EXPECT_EQ(rejected([&] { SpiralImager(Grid{8, 8, 1e-6, 1e-6, INFINITY, 0}, {"m"}, 64); }), "x_offset");
  EXPECT_EQ(rejected([&] { SpiralImager(Grid{8, 8, 1e-6, 1e-6, 0, NAN}, {"m"}, 64); }), "y_offset");
  EXPECT_EQ(rejected([&] { SpiralImager(Grid{1L << 20, 1L << 13, 1e-6, 1e-6}, {"m"}, 64); }), "x_resolution");
  EXPECT_EQ(rejected([&] { SpiralImager(g, {}, 64); }), "channel_units");
  EXPECT_EQ(rejected([&] { SpiralImager(g, {"m", "m\n"}, 64); }), "channel_units");
  EXPECT_EQ(rejected([&] { SpiralImager(g, {" m"}, 64); }), "channel_units");
  EXPECT_EQ(rejected([&] { SpiralImager(g, {"m"}, 15); }), "angular_samples");
  EXPECT_EQ(rejected([&] { SpiralImager(g, {"m"}, (1 << 22) + 1); }), "angular_samples");
  EXPECT_EQ(rejected([&] { SpiralImager(g, {"m"}, 16); }), "(accepted)");
  EXPECT_EQ(rejected([&] { SpiralImager(g, {""}, 1 << 22); }), "(accepted)");

  SpiralImager imager(g, {"m", "m"}, 16);
  const double two[2] = {1.0, 2.0};
  const double three[3] = {1.0, 2.0, 3.0};
  EXPECT_EQ(rejected([&] { imager.add(0.0, -1e-9, two); }), "radius");
  EXPECT_EQ(rejected([&] { imager.add(0.0, NAN, two); }), "radius");
  EXPECT_EQ(rejected([&] { imager.add(0.0, INFINITY, two); }), "radius");
  EXPECT_EQ(rejected([&] { imager.add(NAN, 0.0, two); }), "angle");
  EXPECT_EQ(rejected([&] { imager.add(0.0, 0.0, three); }), "values");
  EXPECT_EQ(rejected([&] { imager.add(0.0, 0.0, std::span<const double>{}); }), "values");
  EXPECT_EQ(imager.samples(), 0);
  imager.add(0.5, 0.0, two);
  EXPECT_EQ(rejected([&] { imager.add(0.5, 1e-9, two); }), "angle");  // not increasing
  EXPECT_EQ(rejected([&] { imager.add(0.4, 1e-9, two); }), "angle");
  EXPECT_EQ(rejected([&] { imager.add(INFINITY, 1e-9, two); }), "angle");
  EXPECT_EQ(rejected([&] { imager.add(1e16, 1e-9, two); }), "angle");  // table index beyond 2^53
  EXPECT_EQ(imager.samples(), 1);
  // The rejected samples left no trace: the scan completes as if they had never come.
  for (int k = 1; k <= 3 * 16; ++k) imager.add(0.5 + kTwoPi * k / 16, 1e-8 * k, two);
  EXPECT_EQ(imager.complete_turns(), 3);
  const auto maps = imager.finish();
  EXPECT_GT(maps[0].valid_count(), 0u);
  for (double v : maps[1].data())
    if (std::isfinite(v)) {
      EXPECT_NEAR(v, 2.0, 1e-15);
    }
  EXPECT_THROW(imager.finish(), std::logic_error);
  EXPECT_THROW(imager.add(100.0, 0.0, two), std::logic_error);
}
