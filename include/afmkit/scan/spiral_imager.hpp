#pragma once
// Resampling of a rotational (spiral) scan stream onto a Cartesian image, while the samples arrive.
//
// In the sample's frame the tip follows a spiral: sample n is at polar (r_n, θ_n), θ unwrapped and strictly
// increasing, x = r cos θ, y = r sin θ (metres, the frame of Grid: pixel (i, j) has its centre at
// x = x_offset + (i + ½)·dx, y = y_offset + (j + ½)·dy). Memory is bounded by the image, not by the sample count.
//
// Algorithm
//  1. Turns. θ₀ = the first sample's angle. Turn k is the arc of unwrapped angle [θ₀ + 2πk, θ₀ + 2π(k + 1)].
//     Each turn is resampled, as the samples stream in, into a table of M + 1 points at the angles
//     φ_j = 2πj/M (j = 0 … M, relative to θ₀): the table coordinate of a sample is s = (θ − θ₀)·M/(2π) and entry
//     g = kM + j gets, for the two consecutive samples with s_a < g ≤ s_b, the radius and every channel linearly
//     interpolated in θ: w = (g − s_a)/(s_b − s_a), v = v_a + w (v_b − v_a). Entry M of turn k is entry 0 of turn
//     k + 1, so the curves join end to end: C_k(φ) over the closed [0, 2π] is the spiral itself, not a closed loop.
//     Between table points the curve is linear in φ (radius and values): a point (r_k(φ), φ) of C_k is on the
//     polar-linear path between two table points, and carries the interpolated values there.
//  2. Strips. When turn k + 1's table is complete (a sample reaches θ₀ + 2π(k + 2)), every pixel whose centre
//     (ρ, φ) (φ = polar angle − θ₀, wrapped to [0, 2π)) satisfies min(r_k(φ), r_{k+1}(φ)) ≤ ρ <
//     max(r_k(φ), r_{k+1}(φ)) gets value = the linear interpolation in ρ between C_k(φ) and C_{k+1}(φ). The strips
//     of consecutive turn pairs share their boundary curve (evaluated by the same arithmetic on the same table), so
//     for a spiral whose radius grows with θ (r_{k+1}(φ) ≥ r_k(φ)) they tile the scanned annulus exactly: no pixel
//     is missed between two turns and none is written twice. (Outward or inward spirals both work; where the
//     radius folds back, r_{k+1}(φ) < r_k(φ) on an outward scan, the last strip written wins.)
//     Candidates: the pixel centres are sorted by ρ once (construction), each strip tests only the pixels with ρ
//     in [min over both tables of r, max of r) (binary search), so filling costs O(pixels · strips covering them).
//     Only two turn tables exist at a time.
//  3. Centre. When turn 0 completes, if its pitch p₀ = r_0(2π) − r_0(0) is > 0 and min_φ r_0(φ) ≤ p₀ (the spiral
//     starts within one pitch of the centre, e.g. at r = 0), the pixels with ρ < r_0(φ) are filled by linear
//     interpolation in ρ between the centre value v_c at ρ = 0 and C_0(φ). v_c, per channel, is the value at the
//     origin of the least-squares plane c + a x + b y through the finite points of turn 0's table (exact for a
//     plane; for points spread over a full turn around the origin it is a weighted mean of the curve's values
//     with the linear part removed). Fewer than 3 finite points (or collinear ones): v_c = NaN, the centre stays
//     invalid. Otherwise (the scan starts further out) the disc inside turn 0 stays invalid.
//  4. End. finish() fills the strip between the last complete turn K and the partial turn K + 1 over the angles
//     the partial turn covers: its table entries written so far plus the last sample itself as a final point (at
//     its own, non-integer, table coordinate), so the filled region ends exactly at the last sample's angle.
//     Samples before one full turn is complete give no image.
//  Bad values: a non-finite value makes the table entries interpolated from it NaN in that channel, hence the
//  pixels interpolated from those entries (within about a pitch and one or two angular steps of the sample) are
//  invalid; the other channels and the geometry are unaffected. finish() marks a pixel valid exactly when its value
//  is finite.
//
// Interpolation error (z smooth, H = max ‖Hessian of z‖₂, G = max |∇z| over the scanned disc of radius R, radial
// speed ρ' = dr/dθ, Δθ = largest angle step between raw samples, Δφ = 2π/M, p = largest radial gap between two
// consecutive turns at a fixed angle, the pitch): along a polar-linear path g(θ) = z(ρ(θ) cos θ, ρ(θ) sin θ) has
// |g''| ≤ (R² + ρ'²) H + √(R² + 4ρ'²) G =: K, so a table value is within E₁ = Δθ²K/8 of z at its table point, a
// curve value within E₁ + E₂, E₂ = Δφ²K/8, and a pixel within
//     |error| ≤ p² H / 8 + (Δθ² + Δφ²) K / 8.
// A plane (H = 0) is not reproduced to rounding: the angular interpolation is linear in θ, a plane restricted to a
// circle is a sinusoid in θ (the chord-versus-arc error, ≤ (Δθ² + Δφ²)·√(R² + 4ρ'²)·G/8). The radial step is exact
// for a plane (linear along a ray), and a cone z = c + q·ρ is reproduced to rounding for any spiral (radius and
// value are interpolated with the same weights everywhere).
// In the centre disc (rule 3), r₀ = max radius of turn 0: |v_c − z(0)| ≤ Λ (E₁ + H r₀²/2), Λ = Σ|weights| of the
// fit's constant term, and a pixel is within Λ (E₁ + H r₀²/2) + E₁ + E₂ + H r₀²/8. Λ = 1 when the turn starts
// within a pitch of the centre (the weights are then all positive; checked numerically for M = 16 … 2000 and
// starts at 0 … 1 pitch).
// (All of this assumes each sample holds z exactly at its own position.)
//
// Cost: construction sorts the pixel centres by ρ (buckets of ~32 pixels, then each bucket); add() is O(1 + channels·M/(samples per
// turn)) (the table entries the sample completes) plus, once per turn, the strip fill (O(pixels in the strip)); no
// allocation after construction. 10^7 samples into 1024 × 1024 pixels: ≈ 0.2 s on one core (bench_scan_imager).
// Memory: pixels·(8·channels + 20) bytes (images; sorted pixel radii, angles, indices) + 2·(M + 1)·(1 + channels)·8
// bytes (tables); transient: 16 bytes/pixel while constructing, 1 byte/pixel/channel (masks) in finish().
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "afmkit/scan/height_map.hpp"

namespace afmkit::scan {

class SpiralImager {
 public:
  /// grid: the output images' grid (metres). channel_units: one z_unit per channel (e.g. {"m","m"}); ≥ 1 channel.
  /// angular_samples M (≥ 16, ≤ 2^22): resolution of the per-turn table (the caller passes ≈ samples per turn).
  /// InvalidParameter naming the Grid field (as HeightMap does; x_resolution also when x_resolution·y_resolution
  /// exceeds 2^32 − 1 pixels), "channel_units" (empty, or a unit HeightMap would refuse), "angular_samples".
  SpiralImager(const Grid& grid, std::vector<std::string> channel_units, int angular_samples);

  /// One sample, in time order: unwrapped angle θ [rad] strictly increasing, radius r ≥ 0 [m], values[k] for each
  /// channel (NaN = bad sample: pixels interpolated from it become invalid). Amortised O(1), no allocation.
  /// InvalidParameter("angle") if θ is not finite, does not increase, or is so far from the first angle that the
  /// table index (θ − θ₀)·M/(2π) reaches 2^53; ("radius") if r < 0 or non-finite; ("values") if values.size() is
  /// not the channel count. A rejected sample leaves the imager unchanged. std::logic_error after finish().
  void add(double angle, double radius, std::span<const double> values);

  /// After the last sample: one HeightMap per channel on `grid` (with its unit and a mask); pixels inside the
  /// scanned region filled, others invalid (NaN + mask 0). Call once (std::logic_error otherwise); releases the
  /// imager's pixel and turn tables.
  std::vector<HeightMap> finish();

  long samples() const { return samples_; }
  /// Turns whose whole angle range has been passed: floor((θ_last − θ₀)/(2π)).
  long complete_turns() const { return turn_; }
  /// Whether the disc inside turn 0 was filled (rule 3; false until turn 0 is complete).
  bool centre_filled() const { return centre_filled_; }
  int angular_samples() const { return table_size_; }
  std::size_t channels() const { return units_.size(); }
  const Grid& grid() const { return grid_; }

 private:
  void complete_turn();
  void fill_centre();
  void fill_strip(const std::vector<double>& lower, const std::vector<double>& upper, long upper_uniform_end,
                  double upper_end);
  double* row(std::vector<double>& table, std::size_t channel_plus_one) {
    return table.data() + channel_plus_one * static_cast<std::size_t>(table_size_ + 1);
  }

  Grid grid_;
  std::vector<std::string> units_;
  int table_size_;  // M

  // Pixel centres sorted by ρ (radius, polar angle in [0, 2π), row-major pixel index).
  std::vector<double> pixel_radius_;
  std::vector<double> pixel_angle_;
  std::vector<std::uint32_t> pixel_index_;
  std::vector<std::vector<double>> images_;  // per channel, row-major, NaN = not filled

  // Turn tables, (1 + channels) rows of M + 1: row 0 radius, row 1 + c channel c. lower_ = turn turn_ − 1,
  // upper_ = turn turn_ (being written).
  std::vector<double> lower_;
  std::vector<double> upper_;

  long samples_ = 0;
  long turn_ = 0;            // complete turns = index of the turn upper_ holds
  long next_entry_ = 0;      // global table index g of the next entry to write
  long next_column_ = 0;     // its column in upper_: g − turn_·M
  double first_angle_ = 0;   // θ₀
  double first_phase_ = 0;   // θ₀ wrapped to [0, 2π)
  double per_radian_ = 0;    // M/(2π)
  double last_angle_ = 0;
  double last_position_ = 0;  // s of the last sample
  double last_radius_ = 0;
  std::vector<double> last_values_;
  bool centre_filled_ = false;
  bool finished_ = false;
};

}  // namespace afmkit::scan
