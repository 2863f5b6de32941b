#include "afmkit/scan/sample_generators.hpp"

#include <algorithm>
#include <future>
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "gaussian_rows.hpp"

namespace afmkit::scan {
namespace {

// The grid's values, all zero, after HeightMap has validated the grid (the resolutions are checked first so that the
// pixel count cannot overflow).
std::vector<double> zeros_on(const Grid& grid) {
  validate::require(grid.x_resolution >= 1, "x_resolution", static_cast<double>(grid.x_resolution), "an integer >= 1");
  validate::require(grid.y_resolution >= 1, "y_resolution", static_cast<double>(grid.y_resolution), "an integer >= 1");
  const long max_pixels = 1L << 40;  // far beyond memory; only guards the product
  validate::require(grid.x_resolution <= max_pixels / grid.y_resolution, "x_resolution",
                    static_cast<double>(grid.x_resolution), "an integer with x_resolution · y_resolution <= 2^40");
  const auto pixels = static_cast<std::size_t>(grid.x_resolution * grid.y_resolution);
  return HeightMap(grid, std::vector<double>(pixels, 0.0)).data();  // validates x_size, y_size, offsets
}

// Fills data[j·nx + i] = height(x_i, y_j) at the pixel centres.
template <class Height>
HeightMap sample_at_centres(const Grid& grid, Height&& height) {
  std::vector<double> data = zeros_on(grid);
  const double dx = grid.x_size / static_cast<double>(grid.x_resolution);
  const double dy = grid.y_size / static_cast<double>(grid.y_resolution);
  for (long j = 0; j < grid.y_resolution; ++j) {
    const double y = grid.y_offset + (static_cast<double>(j) + 0.5) * dy;
    double* row = data.data() + j * grid.x_resolution;
    for (long i = 0; i < grid.x_resolution; ++i) row[i] = height(grid.x_offset + (static_cast<double>(i) + 0.5) * dx, y);
  }
  return HeightMap(grid, std::move(data));
}

constexpr int max_particle_count = 1'000'000;
constexpr int max_placement_tries = 10'000;

}  // namespace

HeightMap flat(const Grid& grid) { return HeightMap(grid, zeros_on(grid)); }

HeightMap grating(const Grid& grid, const GratingSpec& spec) {
  validate::positive("grating.period", spec.period);
  validate::finite("grating.height", spec.height);
  validate::require(std::isfinite(spec.duty) && spec.duty > 0.0 && spec.duty < 1.0, "grating.duty", spec.duty,
                    "in (0, 1)");
  validate::finite("grating.angle", spec.angle);
  const double cos_angle = std::cos(spec.angle);
  const double sin_angle = std::sin(spec.angle);
  return sample_at_centres(grid, [&](double x, double y) {
    const double phase = (x * cos_angle + y * sin_angle) / spec.period;
    return phase - std::floor(phase) < spec.duty ? spec.height : 0.0;
  });
}

HeightMap steps(const Grid& grid, const StepsSpec& spec) {
  validate::positive("steps.width", spec.width);
  validate::finite("steps.height", spec.height);
  validate::finite("steps.angle", spec.angle);
  const double cos_angle = std::cos(spec.angle);
  const double sin_angle = std::sin(spec.angle);
  return sample_at_centres(grid, [&](double x, double y) {
    return spec.height * std::floor((x * cos_angle + y * sin_angle) / spec.width);
  });
}

std::vector<Particle> place_particles(const Grid& grid, const ParticlesSpec& spec) {
  (void)zeros_on(grid);  // validate the grid first, so its fields are named before the spec's
  validate::require(spec.count >= 0 && spec.count <= max_particle_count, "particles.count", spec.count,
                    fmt::format("an integer in [0, {}]", max_particle_count));
  const double r = spec.radius;
  const double max_radius = 0.5 * std::min(grid.x_size, grid.y_size);
  validate::require(std::isfinite(r) && r > 0.0 && r <= max_radius, "particles.radius", r,
                    fmt::format("in (0, {:g}] m (half the smaller side of the map)", max_radius));
  // Centres live in [x_lo, x_lo + width] × [y_lo, y_lo + height].
  const double x_lo = grid.x_offset + r;
  const double y_lo = grid.y_offset + r;
  const double width = grid.x_size - 2 * r;
  const double height = grid.y_size - 2 * r;
  // Cell list: cells of side >= 2r, so a sphere closer than 2r to a candidate is in the candidate's cell or one of
  // its 8 neighbours; the side grows with the area per sphere so that there are about `count` cells.
  const double side = std::max(2 * r, std::sqrt(width * height / std::max(spec.count, 1)));
  const long cells_x = std::max(1L, static_cast<long>(std::ceil(width / side)));
  const long cells_y = std::max(1L, static_cast<long>(std::ceil(height / side)));
  std::vector<std::vector<int>> cells(static_cast<std::size_t>(cells_x * cells_y));
  const auto cell_of = [&](double coordinate, double lo, long cells_n) {
    return std::clamp(static_cast<long>(std::floor((coordinate - lo) / side)), 0L, cells_n - 1);
  };

  std::mt19937_64 generator(spec.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Particle> spheres;
  spheres.reserve(static_cast<std::size_t>(spec.count));
  const double min_distance_squared = 4 * r * r;
  while (static_cast<int>(spheres.size()) < spec.count) {
    bool placed = false;
    for (int attempt = 0; attempt < max_placement_tries && !placed; ++attempt) {
      const double x = x_lo + width * unit(generator);
      const double y = y_lo + height * unit(generator);
      const long cx = cell_of(x, x_lo, cells_x);
      const long cy = cell_of(y, y_lo, cells_y);
      bool clear = true;
      for (long ny = std::max(cy - 1, 0L); clear && ny <= std::min(cy + 1, cells_y - 1); ++ny)
        for (long nx = std::max(cx - 1, 0L); clear && nx <= std::min(cx + 1, cells_x - 1); ++nx)
          for (const int k : cells[static_cast<std::size_t>(ny * cells_x + nx)]) {
            const Particle& other = spheres[static_cast<std::size_t>(k)];
            if ((x - other.x) * (x - other.x) + (y - other.y) * (y - other.y) < min_distance_squared) {
              clear = false;
              break;
            }
          }
      if (clear) {
        cells[static_cast<std::size_t>(cy * cells_x + cx)].push_back(static_cast<int>(spheres.size()));
        spheres.push_back({x, y, r});
        placed = true;
      }
    }
    if (!placed) {
      const double coverage = static_cast<double>(spec.count) * std::numbers::pi * r * r / (grid.x_size * grid.y_size);
      throw InvalidParameter(
          "particles.count",
          fmt::format("particles.count = {} is out of range: only {} non-overlapping spheres of radius {:g} m could be "
                      "placed on the {:g} m × {:g} m map ({} tries for the next failed); the requested discs would "
                      "cover {:.0f} % of it: must be at most {} here (random placement jams near 55 % coverage)",
                      spec.count, spheres.size(), r, grid.x_size, grid.y_size, max_placement_tries, 100 * coverage,
                      spheres.size()));
    }
  }
  return spheres;
}

HeightMap render_particles(const Grid& grid, const std::vector<Particle>& spheres) {
  std::vector<double> data = zeros_on(grid);
  for (const Particle& p : spheres) {
    validate::finite("spheres.x", p.x);
    validate::finite("spheres.y", p.y);
    validate::positive("spheres.radius", p.radius);
  }
  const long columns = grid.x_resolution;
  const long rows = grid.y_resolution;
  const double dx = grid.x_size / static_cast<double>(columns);
  const double dy = grid.y_size / static_cast<double>(rows);
  // Index range of the pixel centres within [lo, hi] along one axis (first > last when none).
  const auto centre_range = [](double lo, double hi, double offset, double step, long n) {
    const double first = std::ceil((lo - offset) / step - 0.5);
    const double last = std::floor((hi - offset) / step - 0.5);
    return std::pair<long, long>{static_cast<long>(std::max(first, 0.0)),
                                 static_cast<long>(std::min(last, static_cast<double>(n - 1)))};
  };
  for (const Particle& p : spheres) {
    const double r = p.radius;
    const auto [i_first, i_last] = centre_range(p.x - r, p.x + r, grid.x_offset, dx, columns);
    const auto [j_first, j_last] = centre_range(p.y - r, p.y + r, grid.y_offset, dy, rows);
    for (long j = j_first; j <= j_last; ++j) {
      const double ey = grid.y_offset + (static_cast<double>(j) + 0.5) * dy - p.y;
      for (long i = i_first; i <= i_last; ++i) {
        const double ex = grid.x_offset + (static_cast<double>(i) + 0.5) * dx - p.x;
        const double d_squared = ex * ex + ey * ey;
        if (d_squared < r * r) {
          double& z = data[static_cast<std::size_t>(j * columns + i)];
          z = std::max(z, r + std::sqrt(r * r - d_squared));
        }
      }
    }
  }
  return HeightMap(grid, std::move(data));
}

HeightMap particles(const Grid& grid, const ParticlesSpec& spec) {
  return render_particles(grid, place_particles(grid, spec));
}

HeightMap rough(const Grid& grid, const RoughSpec& spec) {
  std::vector<double> out = zeros_on(grid);
  validate::positive("rough.rms", spec.rms);
  const long columns = grid.x_resolution;
  const long rows = grid.y_resolution;
  const double dx = grid.x_size / static_cast<double>(columns);
  const double dy = grid.y_size / static_cast<double>(rows);
  const double xi = spec.correlation_length;
  const double xi_min = std::max(dx, dy);
  const double xi_max = std::min(grid.x_size, grid.y_size);
  validate::require(std::isfinite(xi) && xi >= xi_min && xi <= xi_max, "rough.correlation_length", xi,
                    fmt::format("in [{:g}, {:g}] m (from the larger pixel side to the smaller map side)", xi_min,
                                xi_max));
  if (out.size() < 2)
    throw InvalidParameter("rough", "a rough surface needs at least 2 pixels (its RMS about the mean is 0 otherwise)");

  // Kernel exp(−2 (m·step)²/ξ²), m = −half … half, half = ceil(3ξ / step): its self-correlation is exp(−d²/ξ²).
  const auto kernel = [xi](double step) {
    const long half = static_cast<long>(std::ceil(3.0 * xi / step));
    std::vector<double> k(static_cast<std::size_t>(2 * half + 1));
    for (long m = -half; m <= half; ++m) {
      const double d = static_cast<double>(m) * step / xi;
      k[static_cast<std::size_t>(m + half)] = std::exp(-2.0 * d * d);
    }
    return k;
  };
  const std::vector<double> kernel_x = kernel(dx);
  const std::vector<double> kernel_y = kernel(dy);
  const long half_x = static_cast<long>(kernel_x.size() / 2);
  const long half_y = static_cast<long>(kernel_y.size() / 2);

  // Pass 1: row by row of the padded noise field ((columns + 2 half_x) × (rows + 2 half_y), drawn in row-major
  // order), convolve along x into the smoothed rows (columns each, rows + 2 half_y of them). Pass 2, as the smoothed
  // rows arrive: out[j][i] = Σ_m k[m] · smoothed[j + m][i]. The smoothed rows live in windows of the 2 half_y rows
  // the next output row needs plus a block of `block` more: when one is full, its block of output rows is computed
  // on another thread while the next window (starting with its last 2 half_y rows) fills here. The same sums as over
  // all the smoothed rows at once, without holding them: two windows of 2 half_y + block rows instead of
  // rows + 2 half_y.
  std::mt19937_64 generator(spec.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const long padded_rows = rows + 2 * half_y;
  const long padded_columns = columns + 2 * half_x;
  constexpr long block = 64;
  const long overlap = 2 * half_y;
  std::vector<double> noise_row(static_cast<std::size_t>(padded_columns));
  std::vector<double> windows[2];
  for (auto& w : windows) w.resize(static_cast<std::size_t>((overlap + block) * columns));
  std::future<void> columns_pass;  // the previous window's block (waits in its destructor if a draw throws)
  int current = 0;
  long filled = 0;     // smoothed rows in the current window
  long first_out = 0;  // output row of its first row
  for (long j = 0; j < padded_rows; ++j) {
    std::vector<double>& window = windows[current];
    for (double& w : noise_row) w = normal(generator);
    // target[i] = Σ_m k[m] · noise at column i − half_x + m
    detail::convolve_along_row(noise_row.data(), kernel_x.data(), kernel_x.size(), window.data() + filled * columns,
                               columns);
    ++filled;
    if (filled == overlap + block || j + 1 == padded_rows) {
      const long ready = filled - overlap;  // output rows whose taps are all in the window
      if (columns_pass.valid()) columns_pass.get();  // the other window is free again
      std::vector<double>& next = windows[1 - current];
      std::copy(window.begin() + ready * columns, window.begin() + filled * columns, next.begin());
      double* target = out.data() + first_out * columns;
      columns_pass = std::async(std::launch::async, [&window, columns, ready, &kernel_y, target] {
        detail::convolve_down_columns(window.data(), columns, ready, kernel_y.data(), kernel_y.size(), target);
      });
      first_out += ready;
      filled = overlap;
      current = 1 - current;
    }
  }
  if (columns_pass.valid()) columns_pass.get();
  // Remove the mean, scale to the RMS (two passes for accuracy).
  double mean = 0.0;
  for (const double z : out) mean += z;
  mean /= static_cast<double>(out.size());
  double sum_squares = 0.0;
  for (double& z : out) {
    z -= mean;
    sum_squares += z * z;
  }
  const double scale = spec.rms / std::sqrt(sum_squares / static_cast<double>(out.size()));
  for (double& z : out) z *= scale;
  return HeightMap(grid, std::move(out));
}

}  // namespace afmkit::scan
