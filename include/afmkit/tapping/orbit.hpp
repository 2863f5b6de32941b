#pragma once
// Observables of a periodic orbit (first harmonic, offset, phase, higher harmonics, contact, forces, energy)
// and the search for every periodic orbit at one separation.
//
// Phase convention: x(t) ≈ A + B cos(ωt − φ) for the drive Γ cos ωt (φ = π/2 for the free response at
// resonance). Harmonics are Fourier coefficients at kω over the whole orbit (n drive periods for a period-n
// orbit), computed by Gauss–Legendre quadrature on every smooth segment between events (exact to rounding).
// Energy per drive period (per unit mass): drive work W = ∫ Γ cos(ωt) ẋ dt, viscous loss ∫ 2ξω_n ẋ² dt,
// contact loss ∫ h(x, ẋ) ẋ dt (energy taken by the sample); for a periodic orbit W = viscous + contact.
#include <array>
#include <string>
#include <vector>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/transient.hpp"

namespace afmkit::tapping {

struct OrbitMetrics {
  double amplitude = 0.0;  // B: first harmonic
  double offset = 0.0;     // A: mean of x
  double phase = 0.0;      // φ [rad] in (−π, π]
  std::array<double, 4> harmonics{};  // amplitudes of harmonics 2, 3, 4, 5 (|c_k|, same normalisation as B)
  double contact_fraction = 0.0;  // fraction of time with x + l below the law's contact gap (ForceLaw::contact_gap)
  double peak_force = 0.0;        // max over the orbit of H (tip–sample force, positive = repulsive)
  double min_gap = 0.0;           // min over the orbit of x + l
  double drive_work = 0.0;            // per drive period
  double viscous_dissipation = 0.0;   // per drive period
  double contact_dissipation = 0.0;   // per drive period
  double energy_dissipated() const { return viscous_dissipation + contact_dissipation; }
  long impacts_per_period_multiple = 0;  // contacts during one orbit (n drive periods)
  double sticking_duration = 0.0;        // time spent sticking during one orbit
  double duration = 0.0;                 // of the orbit: period_multiple drive periods (0: not analysed)
};

/// Whether the tip is trapped on this orbit: it never taps — it sticks to the sample for the whole orbit (at rest
/// where the force lies between the approach and retract branches, e.g. held by an adhesion far above the drive
/// force k A0 / Q) or stays below the law's contact gap over the whole orbit (each up to a fraction 1e-6 of the
/// orbit's duration; docs/conventions.md#statuses). Its amplitude is the motion in contact (often ~1e-16 nm), not
/// a tapping amplitude.
bool tip_trapped(const OrbitMetrics& metrics);

/// Evaluate the observables of `orbit` by simulating it once (period_multiple drive periods).
OrbitMetrics analyse_orbit(const TappingModel& model, const PeriodicOrbit& orbit,
                           const SimulationOptions& options = {});

/// Where an orbit came from (the kind of the first seed that converged to it).
enum class OrbitSource { hb_free, hb_plus, hb_minus, transient, previous, continuation, grid, contact };
const char* orbit_source_name(OrbitSource source);

/// Kinds of starting point of the orbit search.
enum class SeedKind {
  harmonic_balance,  // Newton from an HB solution (any law: closed forms or numerical describing functions)
  transient,         // full transient (settle): from each HB contact solution, the free response and rest
  grid,              // phase × amplitude grid: Newton from the state, and after short transients
  contact,           // states in contact (at the contact edge, penetrating, moving in or out or at rest)
  continuation       // a point at l of a branch continued in l from an orbit already found
};
inline constexpr int seed_kind_count = 5;
const char* seed_kind_name(SeedKind kind);

/// One starting point of the search and what it converged to.
struct SearchSeed {
  SeedKind kind = SeedKind::grid;
  TipState start;  // state at t = 0 (continuation: the state interpolated between the two branch points)
  double grid_phase = 0.0;      // grid seeds: x(t) ≈ a cos(ωt − θ) at t = 0: θ [rad] and a
  double grid_amplitude = 0.0;
  std::vector<int> orbits;      // indices into OrbitSearchResult::orbits this seed converged to (may be several)
  bool converged() const { return !orbits.empty(); }
};

/// How the search went: counts per seed kind, the continuation bracket, the wall time.
struct OrbitSearchReport {
  std::vector<SearchSeed> seeds;
  std::array<int, seed_kind_count> seeds_by_kind{};      // indexed by SeedKind
  std::array<int, seed_kind_count> converged_by_kind{};  // seeds of that kind that converged to an orbit
  int continuation_runs = 0;           // branch continuations started (period-1 orbits × 2 directions)
  double bracket_min = 0.0, bracket_max = 0.0;  // separations the continuations covered
  double seconds = 0.0;
};

struct FoundOrbit {
  OrbitSource source;
  PeriodicOrbit orbit;
  OrbitMetrics metrics;
  std::vector<int> seeds;  // indices into OrbitSearchReport::seeds that converged to this orbit
};

struct OrbitSearchOptions {
  ShootingOptions shooting;
  TransientOptions transient;
  bool from_harmonic_balance = true;  // shoot from each HB solution
  bool from_transient = true;         // full transients from each HB contact solution, the free response, rest
  bool from_grid = true;              // grid and contact seeds
  bool from_continuation = true;      // continue every period-1 orbit found through the bracket around l
  /// Grid: initial states x = a cos θ, ẋ = aω sin θ (x(t) ≈ a cos(ωt − θ)) for grid_phases phases θ in [0, 2π)
  /// and a = f·max(A_free, |l|) for each factor f; from each Newton shoots at 0 and after each number of drive
  /// periods in grid_transient_periods (cumulative).
  int grid_phases = 8;
  std::vector<double> grid_amplitudes{0.25, 0.6, 0.9, 1.05, 1.25};
  std::vector<int> grid_transient_periods{24};
  /// Continuation bracket: l ± bracket_fraction · A_free.
  double bracket_fraction = 0.15;
  int continuation_max_points = 300;  // per continuation run
  bool parallel = true;               // OpenMP over the candidates
  /// Two converged orbits are the same when their initial states differ by less than this (relative).
  double duplicate_tolerance = 1e-6;
  Cancellation cancellation;  // checked once per candidate and per continuation point (core/cancellation.hpp)
  void validate() const;
};

struct OrbitSearchResult {
  std::vector<HbPoint> harmonic_balance;  // every HB solution at the separation
  std::vector<FoundOrbit> orbits;         // distinct orbits, by increasing amplitude
  std::vector<TransientOutcome> transients;  // what each full transient settled to (incl. non-periodic)
  OrbitSearchReport report;               // how the search went
};

/// Periodic orbits at model.separation, by Newton shooting from several kinds of seed (SeedKind): every HB
/// solution; full transients from the HB contact solutions, the free response and rest; a phase × amplitude
/// grid of states from rest to beyond the free amplitude and states in contact, each shot directly and after
/// short transients; and the points at l of the branches through every period-1 orbit found, continued in l
/// (pseudo-arclength, through folds) over l ± bracket_fraction·A_free. Duplicates are merged.
///
/// Guarantees: every orbit reported is a converged periodic orbit (shooting residual within tolerance) with
/// its Floquet multipliers; each stable period-1 orbit whose basin contains a seed (or a short transient of it)
/// is found, and so is every period-1 orbit (stable or not) on a branch through a found period-1 orbit that
/// crosses l within the bracket without leaving it. Not guaranteed: orbits of period n > 1 unless a full
/// transient settles on them (stable, n ≤ transient.max_period_multiple); unstable orbits on branches not
/// connected within the bracket to an orbit found (e.g. isolas); stable orbits with basins missed by every seed.
OrbitSearchResult find_orbits(const TappingModel& model, const OrbitSearchOptions& options = {});

}  // namespace afmkit::tapping
