#pragma once
// Built-in sample topographies for the virtual rotational-scanning AFM. Each is generated on a caller's Grid
// (metres; callers centre it on (0, 0) with x_offset = −x_size/2, y_offset = −y_size/2) and returned as a
// HeightMap with every pixel valid and z_unit "m".
//
// Sampling: every generator evaluates its height function at the pixel centres
//   x_i = x_offset + (i + ½)·dx,  y_j = y_offset + (j + ½)·dy
// (point sampling; no area-coverage anti-aliasing), so features narrower than about two pixels alias.
//
// Randomness (particles, rough): std::mt19937_64 seeded with `seed`, drawn through std::uniform_real_distribution /
// std::normal_distribution. A seed gives the same map on every run and machine with the same standard library;
// the sequence is libstdc++'s (another standard library's distributions may give different maps).
//
// Every spec field is validated: InvalidParameter naming it as "grating.period", "particles.count", … with the
// allowed range; the grid fields as HeightMap names them ("x_resolution", "x_size", …).
#include <array>
#include <string_view>
#include <vector>

#include "afmkit/scan/height_map.hpp"

namespace afmkit::scan {

/// The generator names as the command line spells them.
inline constexpr std::array<std::string_view, 5> sample_names{"flat", "grating", "steps", "particles", "rough"};

/// 1-D line grating: z = height where frac(u / period) < duty, else 0, with u = x cos(angle) + y sin(angle)
/// (lines perpendicular to the direction `angle`).
struct GratingSpec {
  double period = 3e-6;   ///< line pitch [m], > 0
  double height = 20e-9;  ///< line height [m], finite (negative = trenches)
  double duty = 0.5;      ///< fraction of the period that is raised, in (0, 1)
  double angle = 0.0;     ///< direction of u from +x towards +y [rad], finite
};

/// Staircase: z = height · floor(u / width), u = x cos(angle) + y sin(angle).
struct StepsSpec {
  double width = 5e-6;    ///< terrace width [m], > 0
  double height = 10e-9;  ///< step height [m], finite (negative = descending along u)
  double angle = 0.0;     ///< direction of u [rad], finite
};

/// Spheres of one radius lying on the plane z = 0, wholly inside the map rectangle, non-overlapping (centre
/// distance >= 2 r; touching allowed), placed by random sequential addition (rejection sampling).
/// z = max over spheres of r + sqrt(r² − d²) where d < r (d = in-plane distance of the pixel centre to the sphere
/// centre), else 0.
struct ParticlesSpec {
  int count = 50;          ///< number of spheres, in [0, 10^6]; placement must succeed (see place_particles)
  double radius = 200e-9;  ///< sphere radius r [m], in (0, min(x_size, y_size)/2]
  unsigned seed = 1;
};

/// Gaussian random surface with Gaussian autocorrelation C(d) = rms² exp(−d²/ξ²): white noise convolved separably
/// with the kernel exp(−2 x²/ξ²)·exp(−2 y²/ξ²) (whose self-correlation is exp(−d²/ξ²)), truncated at 3ξ, on a grid
/// padded by the kernel half-width (so no pixel sees an edge); then the mean is removed and the map scaled so its
/// RMS is exactly `rms`. Cost O(pixels · ξ/pixel); transient memory up to (1 + 6ξ/y_size)· the map.
struct RoughSpec {
  double rms = 5e-9;                   ///< RMS roughness [m], > 0
  double correlation_length = 500e-9;  ///< ξ [m], in [max(dx, dy), min(x_size, y_size)]
  unsigned seed = 1;
};

/// A sphere of the particles sample: centre (x, y) in the plane [m], radius [m] (its centre is at height radius).
struct Particle {
  double x = 0.0;
  double y = 0.0;
  double radius = 0.0;
};

HeightMap flat(const Grid& grid);  ///< all zeros
HeightMap grating(const Grid& grid, const GratingSpec& spec);
HeightMap steps(const Grid& grid, const StepsSpec& spec);
HeightMap particles(const Grid& grid, const ParticlesSpec& spec);  ///< render_particles(grid, place_particles(grid, spec))
HeightMap rough(const Grid& grid, const RoughSpec& spec);

/// The spheres of particles(grid, spec), in placement order: centres uniform in
/// [x_offset + r, x_offset + x_size − r] × [y_offset + r, y_offset + y_size − r], each candidate rejected if it
/// comes closer than 2 r to an earlier one. InvalidParameter("particles.count") if one sphere cannot be placed in
/// 10 000 consecutive tries (the plane is too crowded: random addition jams near 55 % disc area coverage).
std::vector<Particle> place_particles(const Grid& grid, const ParticlesSpec& spec);
/// Heights of the given spheres on `grid` (pixel-centre sampling; max over spheres; 0 elsewhere).
HeightMap render_particles(const Grid& grid, const std::vector<Particle>& spheres);

}  // namespace afmkit::scan
