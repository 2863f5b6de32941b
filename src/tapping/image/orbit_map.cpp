// The steady-state orbit map (orbit_map.hpp).
#include "afmkit/tapping/image/orbit_map.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::tapping::image {

const char* regime_name(Regime regime) {
  switch (regime) {
    case Regime::attractive: return "attractive";
    case Regime::repulsive: return "repulsive";
    default: return "free";
  }
}

double SteadyState::phase() const { return std::atan2(sin_phase, cos_phase); }

Regime regime_of(double in_phase_force, double drive_amplitude, double free_fraction) {
  if (!(std::abs(in_phase_force) > free_fraction * drive_amplitude)) return Regime::free;
  return in_phase_force > 0.0 ? Regime::attractive : Regime::repulsive;
}

void OrbitMapOptions::validate() const {
  if (!(std::isfinite(separation_min) && std::isfinite(separation_max)))
    throw InvalidParameter("map_separation_min", "the separations of the orbit map must be finite");
  if (!(separation_min < separation_max))
    throw InvalidParameter("map_separation_max",
                           fmt::format("map_separation_max = {} must be > map_separation_min = {} (model units)",
                                       separation_max, separation_min));
  if (points < 8)
    throw InvalidParameter("map_points", fmt::format("map_points = {} is out of range: must be >= 8", points));
  sweep.validate();
}

namespace {

// H_c = (ω_n² − ω²) B − Γ cos φ: the in-phase first harmonic of the tip–sample force (exact for a periodic orbit:
// eq. 8 projected on cos(ωt − φ) over a period).
SteadyState steady_state(const TappingModel& m, const OrbitMetrics& o, bool periodic) {
  const double wn = m.cantilever.natural_frequency, w = m.drive.frequency;
  SteadyState s;
  s.amplitude = o.amplitude;
  s.cos_phase = std::cos(o.phase);
  s.sin_phase = std::sin(o.phase);
  s.peak_force = o.peak_force;
  s.contact_dissipation = o.contact_dissipation;  // per drive period (orbit.hpp)
  s.in_phase_force = (wn * wn - w * w) * o.amplitude - m.drive.amplitude * std::cos(o.phase);
  s.periodic = periodic ? 1.0 : 0.0;
  return s;
}

// A run of consecutive sweep points between two jumps (one direction).
struct Piece {
  std::vector<std::size_t> grid_index;  // of each point (into the ascending grid)
  std::vector<char> on_grid;            // 1: a grid point (a sweep point), 0: a jump's node
  std::vector<double> l;
  std::vector<SteadyState> state;
  double lower = 0.0, upper = 0.0;      // where it exists
  bool approach = true;
};

std::size_t grid_index_of(const std::vector<double>& grid, double l) {
  const auto it = std::lower_bound(grid.begin(), grid.end(), l - 1e-12 * (1.0 + std::abs(l)));
  return static_cast<std::size_t>(std::min<std::ptrdiff_t>(it - grid.begin(), static_cast<std::ptrdiff_t>(grid.size()) - 1));
}

std::vector<Piece> pieces_of(const TappingModel& model, const std::vector<SweepPoint>& points,
                             const std::vector<SweepJump>& jumps, SweepDirection direction,
                             const std::vector<double>& grid) {
  std::vector<Piece> out;
  const bool approach = direction == SweepDirection::approach;
  for (const SweepPoint& p : points) {
    if (out.empty() || p.jumped) {
      out.push_back({});
      out.back().approach = approach;
    }
    Piece& piece = out.back();
    piece.grid_index.push_back(grid_index_of(grid, p.separation));
    piece.on_grid.push_back(1);
    piece.l.push_back(p.separation);
    piece.state.push_back(steady_state(model, p.metrics, p.periodic));
  }
  // The located jumps: the last stable orbit before each becomes the end node of the piece it left (the first jump
  // between two grid points; further jumps there leave pieces too short to hold a grid point).
  std::size_t next = 0;
  for (std::size_t k = 0; k + 1 < out.size(); ++k) {
    const double end = out[k].l.back(), start_next = out[k + 1].l.front();
    while (next < jumps.size()) {
      const SweepJump& j = jumps[next];
      if (j.direction != direction) {
        ++next;
        continue;
      }
      // sweep order: a jump before this boundary (a further jump of an earlier interval) is passed over, one after
      // it belongs to a later boundary
      const bool before = approach ? j.separation > end : j.separation < end;
      const bool after = approach ? j.separation < start_next : j.separation > start_next;
      if (before) {
        ++next;
        continue;
      }
      if (after) break;
      const double lf = j.from.separation;
      if (approach ? (lf < end) : (lf > end)) {
        out[k].grid_index.push_back(out[k].grid_index.back());
        out[k].on_grid.push_back(0);
        out[k].l.push_back(lf);
        out[k].state.push_back(steady_state(model, j.from_metrics, true));
      }
      out[k].l.push_back(j.separation);  // the branch ends here (marked by a node with the end's values)
      out[k].state.push_back(out[k].state.back());
      out[k].grid_index.push_back(out[k].grid_index.back());
      out[k].on_grid.push_back(0);
      ++next;
      break;
    }
  }
  for (Piece& piece : out) {
    piece.lower = *std::min_element(piece.l.begin(), piece.l.end());
    piece.upper = *std::max_element(piece.l.begin(), piece.l.end());
  }
  return out;
}

// Two pieces hold the same orbits where they share grid points with equal amplitude and phase.
bool same_branch(const Piece& a, const Piece& b, double scale) {
  int common = 0;
  for (std::size_t i = 0; i < a.l.size(); ++i) {
    if (!a.on_grid[i]) continue;
    for (std::size_t j = 0; j < b.l.size(); ++j) {
      if (!b.on_grid[j] || a.grid_index[i] != b.grid_index[j]) continue;
      ++common;
      if (std::abs(a.state[i].amplitude - b.state[j].amplitude) > 1e-4 * scale) return false;
      if (std::abs(std::remainder(a.state[i].phase() - b.state[j].phase(), 2.0 * std::numbers::pi)) > 1e-3)
        return false;
    }
  }
  return common > 0;
}

}  // namespace

OrbitMap OrbitMap::build(const TappingModel& model, const OrbitMapOptions& options) {
  options.validate();
  SweepOptions sweep = options.sweep;
  sweep.harmonic_balance = false;
  return from_sweep(model, sweep_instrument(model, options.separation_min, options.separation_max, options.points,
                                            sweep));
}

OrbitMap OrbitMap::from_sweep(const TappingModel& model, const SweepResult& sweep) {
  if (sweep.approach.size() < 2 || sweep.retract.size() < 2)
    throw NumericalFailure("orbit map: the instrument sweep returned fewer than 2 points in a direction");
  OrbitMap map;
  map.free_amplitude_ = model.free_amplitude();
  map.drive_amplitude_ = model.drive.amplitude;
  map.drive_period_ = model.period();
  for (const SweepPoint& p : sweep.retract) map.grid_.push_back(p.separation);
  std::sort(map.grid_.begin(), map.grid_.end());
  map.grid_.erase(std::unique(map.grid_.begin(), map.grid_.end()), map.grid_.end());
  for (const SweepPoint& p : sweep.approach) map.non_periodic_points_ += p.periodic ? 0 : 1;
  for (const SweepPoint& p : sweep.retract) map.non_periodic_points_ += p.periodic ? 0 : 1;
  map.jumps_ = static_cast<int>(sweep.jumps.size());

  std::vector<Piece> pieces = pieces_of(model, sweep.approach, sweep.jumps, SweepDirection::approach, map.grid_);
  const std::size_t approach_pieces = pieces.size();
  for (Piece& p : pieces_of(model, sweep.retract, sweep.jumps, SweepDirection::retract, map.grid_))
    pieces.push_back(std::move(p));

  // union–find over the pieces
  std::vector<std::size_t> parent(pieces.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const double scale = std::max(map.free_amplitude_, 1e-300);
  for (std::size_t i = 0; i < pieces.size(); ++i)
    for (std::size_t j = i + 1; j < pieces.size(); ++j)
      if (root(i) != root(j) && same_branch(pieces[i], pieces[j], scale)) parent[root(j)] = root(i);

  std::vector<int> branch_of_root(pieces.size(), -1);
  std::vector<int> branch_of_piece(pieces.size());
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const std::size_t r = root(i);
    if (branch_of_root[r] < 0) {
      branch_of_root[r] = static_cast<int>(map.branches_.size());
      map.branches_.push_back({});
      map.branches_.back().lower = pieces[i].lower;
      map.branches_.back().upper = pieces[i].upper;
    }
    const int b = branch_of_root[r];
    branch_of_piece[i] = b;
    Branch& branch = map.branches_[static_cast<std::size_t>(b)];
    branch.lower = std::min(branch.lower, pieces[i].lower);
    branch.upper = std::max(branch.upper, pieces[i].upper);
    for (std::size_t k = 0; k < pieces[i].l.size(); ++k) {
      branch.separation.push_back(pieces[i].l[k]);
      branch.state.push_back(pieces[i].state[k]);
    }
  }
  for (Branch& b : map.branches_) {  // sort the nodes, one per separation
    std::vector<std::size_t> order(b.separation.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t i, std::size_t j) { return b.separation[i] < b.separation[j]; });
    std::vector<double> l;
    std::vector<SteadyState> s;
    for (std::size_t i : order) {
      if (!l.empty() && b.separation[i] - l.back() <= 1e-12 * (1.0 + std::abs(l.back()))) continue;
      l.push_back(b.separation[i]);
      s.push_back(b.state[i]);
    }
    b.separation = std::move(l);
    b.state = std::move(s);
    b.regime_at_lower = regime_of(b.state.front().in_phase_force, map.drive_amplitude_);
  }
  // the tracks: the branch each direction is on at each grid point
  map.approach_track_.assign(map.grid_.size(), 0);
  map.retract_track_.assign(map.grid_.size(), 0);
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    std::vector<int>& track = i < approach_pieces ? map.approach_track_ : map.retract_track_;
    for (std::size_t k = 0; k < pieces[i].l.size(); ++k) {
      const std::size_t g = pieces[i].grid_index[k];
      if (pieces[i].on_grid[k]) track[g] = branch_of_piece[i];
    }
  }
  return map;
}

int OrbitMap::track_branch(const std::vector<int>& track, double l) const {
  const std::size_t n = grid_.size();
  const auto it = std::lower_bound(grid_.begin(), grid_.end(), l);
  const std::size_t above = static_cast<std::size_t>(std::min<std::ptrdiff_t>(it - grid_.begin(), n - 1));
  const std::size_t below = above == 0 ? 0 : above - 1;
  // the nearer grid point whose branch holds l, else the nearer one
  const bool above_nearer = std::abs(grid_[above] - l) <= std::abs(l - grid_[below]);
  const int first = track[above_nearer ? above : below], second = track[above_nearer ? below : above];
  if (contains(first, l)) return first;
  if (contains(second, l)) return second;
  return first;
}

int OrbitMap::follow(int branch, double l) const {
  const Branch& b = branches_[static_cast<std::size_t>(branch)];
  if (l < b.lower) return approach_branch(l);
  if (l > b.upper) return retract_branch(l);
  return branch;
}

SteadyState OrbitMap::at(int branch, double l, std::size_t& hint) const {
  const Branch& b = branches_[static_cast<std::size_t>(branch)];
  const std::vector<double>& x = b.separation;
  const std::size_t n = x.size();
  if (n == 1 || l <= x.front()) return b.state.front();
  if (l >= x.back()) return b.state.back();
  std::size_t i = std::min(hint, n - 2);
  if (!(x[i] <= l && l <= x[i + 1])) {
    // a few steps from the hint, else bisection
    if (l > x[i + 1] && i + 2 < n && l <= x[i + 2]) ++i;
    else if (l < x[i] && i > 0 && l >= x[i - 1]) --i;
    else i = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), l) - x.begin()) - 1;
    i = std::min(i, n - 2);
  }
  hint = i;
  const double t = (l - x[i]) / (x[i + 1] - x[i]);
  const SteadyState& a = b.state[i];
  const SteadyState& c = b.state[i + 1];
  const auto mix = [t](double u, double v) { return u + t * (v - u); };
  SteadyState s;
  s.amplitude = mix(a.amplitude, c.amplitude);
  const double co = mix(a.cos_phase, c.cos_phase), si = mix(a.sin_phase, c.sin_phase);
  const double norm = std::sqrt(co * co + si * si);
  s.cos_phase = norm > 0.0 ? co / norm : a.cos_phase;
  s.sin_phase = norm > 0.0 ? si / norm : a.sin_phase;
  s.peak_force = mix(a.peak_force, c.peak_force);
  s.contact_dissipation = mix(a.contact_dissipation, c.contact_dissipation);
  s.in_phase_force = mix(a.in_phase_force, c.in_phase_force);
  s.periodic = std::min(a.periodic, c.periodic);
  return s;
}

std::vector<double> OrbitMap::separations_at_amplitude(int branch, double amplitude) const {
  const Branch& b = branches_[static_cast<std::size_t>(branch)];
  std::vector<double> out;
  for (std::size_t i = 0; i + 1 < b.separation.size(); ++i) {
    const double a0 = b.state[i].amplitude - amplitude, a1 = b.state[i + 1].amplitude - amplitude;
    if (a0 == 0.0) out.push_back(b.separation[i]);
    else if ((a0 < 0.0) != (a1 < 0.0) && a1 != 0.0)
      out.push_back(b.separation[i] + (b.separation[i + 1] - b.separation[i]) * a0 / (a0 - a1));
  }
  if (!b.separation.empty() && b.state.back().amplitude == amplitude) out.push_back(b.separation.back());
  return out;
}

OrbitMap::Engaged OrbitMap::engage(double amplitude) const {
  // walk the approach from the top: the first grid interval where the amplitude of the branch the approach is on
  // falls to the set-point; across a jump, the crossing nearest below the jump on the branch landed on
  int previous = approach_track_.back();
  for (std::size_t k = grid_.size() - 1; k-- > 0;) {
    const int b = approach_track_[k];
    if (b == previous) {
      const double hi = grid_[k + 1], lo = grid_[k];
      std::vector<double> cross = separations_at_amplitude(b, amplitude);
      for (auto it = cross.rbegin(); it != cross.rend(); ++it)
        if (*it <= hi && *it >= lo) return {b, *it};
    } else {
      // jumped between grid_[k + 1] and grid_[k]: the tip lands on b at the jump. Below the set-point there, the
      // loop retracts it along b to the first crossing above the jump; above it, the approach goes on down b.
      const double at_jump = branches_[static_cast<std::size_t>(previous)].lower;
      {  // the set-point may be reached on the branch left, between the last grid point and its end
        std::vector<double> cross = separations_at_amplitude(previous, amplitude);
        for (auto it = cross.rbegin(); it != cross.rend(); ++it)
          if (*it <= grid_[k + 1] && *it >= at_jump) return {previous, *it};
      }
      if (at(b, at_jump).amplitude <= amplitude) {
        for (double c : separations_at_amplitude(b, amplitude))
          if (c >= at_jump && c <= branches_[static_cast<std::size_t>(b)].upper) return {b, c};
      }
      const double hi = std::min(at_jump, grid_[k + 1]), lo = grid_[k];
      std::vector<double> cross = separations_at_amplitude(b, amplitude);
      for (auto it = cross.rbegin(); it != cross.rend(); ++it)
        if (*it <= hi && *it >= lo) return {b, *it};
    }
    previous = b;
  }
  return {};
}

}  // namespace afmkit::tapping::image
