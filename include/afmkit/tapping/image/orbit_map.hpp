#pragma once
// The steady-state orbit map of a tapping cantilever: amplitude, phase, peak force, dissipated power and the
// conservative first harmonic of the tip–sample force of every stable orbit an instrument reaches, against the
// separation l, computed once from an instrument sweep (sweep.hpp: approach then retract, located jumps) and
// interpolated (docs/theory-tapping.md#quasi-static-imaging).
//
// Branches. The approach and the retract are split where the response jumps (SweepPoint::jumped); the pieces are
// joined into branches where they hold the same orbits (same amplitude and phase at common grid separations).
// A branch exists on [lower(), upper()]: its first and last orbits, extended to the located jump where the sweep
// left it (the last stable orbit before the jump is a node of the branch). Beyond an end the instrument jumps: below
// the lower end onto the branch the approach is on there, above the upper end onto the branch the retract is on.
// Branches that neither the approach nor the retract reaches are not in the map.
//
// Units: the model's (normalised; a physical run has lengths in nm, forces in nN per k, time 1/ω_n); the imaging
// engines convert with tapping::UnitScales.
#include <vector>

#include "afmkit/tapping/sweep.hpp"

namespace afmkit::tapping::image {

/// The cycle-averaged regime of an orbit, from the sign of the in-phase first harmonic of the tip–sample force
/// H_c = (2/T)∫ H cos(ωt − φ) dt = (ω_n² − ω²) B − Γ cos φ (exact first-harmonic balance of eq. 8): H_c < 0 the
/// force acts as an added stiffness (repulsive regime, phase below the free phase), H_c > 0 as a softening
/// (attractive regime), |H_c| <= 1e-9 Γ no interaction (free; `free_fraction` of Γ: a caller whose H_c carries a
/// larger numerical error says so, e.g. the time-domain engine's by-parts H_c at its integrator's tolerance).
enum class Regime { free = 0, attractive = 1, repulsive = 2 };
const char* regime_name(Regime regime);  // "free", "attractive", "repulsive"
Regime regime_of(double in_phase_force, double drive_amplitude, double free_fraction = 1e-9);

/// One steady state: the orbit's observables (model units).
struct SteadyState {
  double amplitude = 0.0;        // B, first harmonic
  double cos_phase = 0.0;        // cos φ, sin φ: φ the lag behind the drive (interpolated on the unit circle)
  double sin_phase = 1.0;
  double peak_force = 0.0;       // max H over the orbit (positive = repulsive)
  double contact_dissipation = 0.0;  // energy taken by the sample per drive period
  double in_phase_force = 0.0;   // H_c (see Regime)
  double periodic = 1.0;         // 1 on periodic orbits, 0 on a non-periodic response (one period of it)
  double phase() const;          // φ [rad] in (−π, π]
};

struct OrbitMapOptions {
  double separation_min = 0.0;  // l range of the map (model units), separation_min < separation_max
  double separation_max = 1.0;
  int points = 400;             // grid points each way (>= 8)
  SweepOptions sweep;           // of the instrument sweep (harmonic_balance is switched off)
  void validate() const;        // InvalidParameter naming map_separation_min / map_separation_max / map_points
};

class OrbitMap {
 public:
  struct Branch {
    std::vector<double> separation;  // ascending
    std::vector<SteadyState> state;  // at each separation
    double lower = 0.0, upper = 0.0; // where the branch exists (the jumps located by the sweep)
    Regime regime_at_lower = Regime::free;
  };

  /// Runs the instrument sweep of `model` over the options' range and builds the map (NumericalFailure from the
  /// sweep passes through).
  static OrbitMap build(const TappingModel& model, const OrbitMapOptions& options);
  /// The map of a sweep already computed (its approach and retract on the same grid).
  static OrbitMap from_sweep(const TappingModel& model, const SweepResult& sweep);

  const std::vector<Branch>& branches() const { return branches_; }
  double separation_min() const { return grid_.front(); }
  double separation_max() const { return grid_.back(); }
  double free_amplitude() const { return free_amplitude_; }
  double drive_amplitude() const { return drive_amplitude_; }
  double drive_period() const { return drive_period_; }
  /// Grid points that are on a non-periodic response, and jumps of the sweep.
  int non_periodic_points() const { return non_periodic_points_; }
  int jumps() const { return jumps_; }

  bool contains(int branch, double l) const {
    const Branch& b = branches_[static_cast<std::size_t>(branch)];
    return l >= b.lower && l <= b.upper;
  }
  /// The branch an approach (retract) is on at l (l clamped to the map's range).
  int approach_branch(double l) const { return track_branch(approach_track_, l); }
  int retract_branch(double l) const { return track_branch(retract_track_, l); }
  /// The branch the instrument is on at l when it was on `branch` (hysteresis): `branch` while it exists at l, else
  /// the approach's branch below its lower end, the retract's above its upper end.
  int follow(int branch, double l) const;
  /// Linear interpolation of the branch's nodes at l (clamped to its nodes); `hint`: the node index of the last call
  /// on this branch (updated), so that a slowly moving l costs O(1).
  SteadyState at(int branch, double l, std::size_t& hint) const;
  SteadyState at(int branch, double l) const {
    std::size_t hint = 0;
    return at(branch, l, hint);
  }
  /// Separations on `branch` where its amplitude equals `amplitude` (linear interpolation between nodes),
  /// ascending.
  std::vector<double> separations_at_amplitude(int branch, double amplitude) const;
  /// Where an approach from separation_max() first reaches the amplitude (the tip engaging at the set-point): the
  /// branch and separation; nullopt-like branch −1 when the approach never gets that low.
  struct Engaged {
    int branch = -1;
    double separation = 0.0;
  };
  Engaged engage(double amplitude) const;

 private:
  int track_branch(const std::vector<int>& track, double l) const;
  std::vector<double> grid_;  // the sweep's separations, ascending
  std::vector<int> approach_track_, retract_track_;  // branch at each grid separation
  std::vector<Branch> branches_;
  double free_amplitude_ = 0.0, drive_amplitude_ = 0.0, drive_period_ = 0.0;
  int non_periodic_points_ = 0, jumps_ = 0;
};

}  // namespace afmkit::tapping::image
