// The forward model of `spectroscopy fit`: amplitude and phase along the measured distances from afmkit's exact
// periodic orbits, continued along the curve as an instrument sweeps it (docs/fitting.md#model).
#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/LU>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/parallel.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "afmkit/spectroscopy/fit_model.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::spectroscopy {

namespace {

using tapping::PeriodicOrbit;
using tapping::TappingModel;

/// A point reached by a transient (a branch ended): the settled orbit, or one period of a response that did not
/// settle (non-periodic).
struct Point {
  PeriodicOrbit orbit;
  bool periodic = true;
  bool jumped = false;
};

Point settle_at(const TappingModel& m, tapping::TipState start, const tapping::SweepOptions& o) {
  const tapping::TransientOutcome t = tapping::settle(m, start, o.transient, o.shooting);
  Point p;
  p.jumped = true;
  if (t.orbit) {
    p.orbit = *t.orbit;
  } else {
    p.periodic = false;
    p.orbit.initial = t.final_state;
    p.orbit.stable = false;
  }
  p.orbit.separation = m.separation;
  return p;
}

/// Where the tip lands when the followed branch ends just before m.separation. The transient from the last stable
/// orbit decides (as in the sweep), unless Newton from the harmonic-balance solutions at m.separation finds exactly
/// one stable orbit: then no other attractor of period 1 exists there and the transient would end on it (it may
/// take thousands of drive periods at a high Q; a period-n or non-periodic attractor, which HB cannot see, is
/// missed: documented in docs/fitting.md#model).
Point land(const TappingModel& m, const PeriodicOrbit& last, const tapping::SweepOptions& o, long& solves) {
  const double omega = m.drive.frequency;
  std::vector<PeriodicOrbit> found;
  try {
    for (const tapping::HbPoint& h : tapping::harmonic_balance_solutions(m)) {
      const tapping::TipState s{h.offset + h.amplitude * std::cos(h.phase), h.amplitude * omega * std::sin(h.phase)};
      ++solves;
      const std::optional<PeriodicOrbit> orbit = tapping::try_shoot(m, s, 1, o.shooting);
      if (!orbit || !orbit->stable) continue;
      const double scale = std::max(1.0, std::hypot(orbit->initial.position, orbit->initial.velocity / omega));
      const bool known = std::any_of(found.begin(), found.end(), [&](const PeriodicOrbit& f) {
        return state_distance(f.initial, orbit->initial, omega) <= 1e-6 * scale;
      });
      if (!known) found.push_back(*orbit);
    }
  } catch (const std::exception&) {
    found.clear();
  }
  if (found.size() == 1) {
    Point p;
    p.orbit = found.front();
    p.orbit.separation = m.separation;
    p.jumped = true;
    return p;
  }
  ++solves;
  return settle_at(m, last.initial, o);
}

/// One step of the instrument sweep: from `prev` to separation l_to along the stable branch; where it ends, the
/// transient from the last stable orbit just beyond (then followed on). The sweep's own step (tapping/sweep.cpp)
/// without the classification of jumps (a fit needs the orbit, not whether the branch connects back).
Point step(const TappingModel& base, const Point& prev, double l_to, const tapping::SweepOptions& o, long& solves) {
  constexpr int kMaxPasses = 64;
  Point cur = prev;
  cur.jumped = false;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    if (!cur.periodic || !cur.orbit.stable) {
      ++solves;
      return settle_at(base.with_separation(l_to), cur.orbit.initial, o);
    }
    const tapping::BranchFollow f = tapping::follow_stable_branch(base, cur.orbit, l_to, o);
    solves += f.substeps;
    if (f.reached) {
      Point p;
      p.orbit = *f.reached;
      p.jumped = cur.jumped;
      return p;
    }
    const double l_land = std::isfinite(f.failed_at) && pass + 1 < kMaxPasses ? f.failed_at : l_to;
    Point landed = land(base.with_separation(l_land), f.last, o, solves);
    if (l_land == l_to) return landed;
    cur = landed;
    cur.jumped = true;
  }
  return cur;  // not reached: the last pass lands at l_to
}

}  // namespace

double state_distance(tapping::TipState a, tapping::TipState b, double omega) {
  return std::hypot(a.position - b.position, (a.velocity - b.velocity) / omega);
}

AmForwardModel::AmForwardModel(const FitSettings& settings, const FitOptions& options, std::vector<double> distances)
    : settings_(settings), options_(options), distances_(std::move(distances)) {
  sweep_.harmonic_balance = false;
  sweep_.parallel = false;
  sweep_.shooting.simulation.relative_tolerance = options.integrator_tolerance;
  sweep_.shooting.tolerance = options.shooting_tolerance;
}

impact::ForceLaw build_law(const FitOptions& options, const ModelValues& values) {
  const impact::LawRegistry registry = impact::LawRegistry::builtin();
  impact::LawArguments args;
  args.force_curve = options.force_curve;
  args.allow_energy_gain = options.allow_energy_gain;
  for (const auto& [key, value] : values.law) {
    double f = 1.0;
    for (const auto& k : registry.keys())
      if (k.key == key) f = law_unit_to_si(k.unit);
    args.values[key] = value / f;  // registry units (nm, GPa, nN, J, ...)
  }
  return registry.build(options.law, args);
}

TappingModel AmForwardModel::model(const ModelValues& values) const {
  const double drive = settings_.drive_frequency > 0.0 ? settings_.drive_frequency : settings_.resonance_frequency;
  const tapping::PhysicalCantilever pc(settings_.spring_constant, settings_.resonance_frequency * 1e-3,
                                       settings_.quality_factor, settings_.free_amplitude * values.amplitude_scale * 1e9,
                                       drive / settings_.resonance_frequency);
  return TappingModel(pc.cantilever(), pc.drive(), pc.normalised_law(build_law(options_, values)), 0.0);
}

double AmForwardModel::separation(const ModelValues& values, std::size_t i) const {
  return (distances_[i] + values.distance_offset) * 1e9;  // nm
}

void AmForwardModel::finish(const TappingModel& m, const ModelValues&, CurveEvaluation& e) const {
  const std::size_t n = distances_.size();
  e.amplitude.assign(n, 0.0);
  e.phase.assign(n, 0.0);
  e.contact.assign(n, false);
  ExceptionCollector errors;
#pragma omp parallel for schedule(dynamic) if (options_.parallel)
  for (std::size_t i = 0; i < n; ++i) {
    errors.run([&] {
      const tapping::OrbitMetrics metrics =
          tapping::analyse_orbit(m.with_separation(e.orbits[i].separation), e.orbits[i], sweep_.shooting.simulation);
      e.amplitude[i] = metrics.amplitude * 1e-9;  // nm -> m
      e.phase[i] = metrics.phase;
      e.contact[i] = metrics.contact_fraction > 0.0;
    });
  }
  errors.rethrow();
  e.ok = true;
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(e.amplitude[i]) || !std::isfinite(e.phase[i])) e.ok = false;
  if (!e.ok) e.error = "an orbit's amplitude or phase is not finite";
}

CurveEvaluation AmForwardModel::walk(const ModelValues& values) const {
  ++curves_;
  CurveEvaluation e;
  const TappingModel m = model(values);
  const std::size_t n = distances_.size();
  // the sweep's separations: approach from the largest; a retract curve after the approach to the smallest
  std::vector<double> ls(n);
  for (std::size_t i = 0; i < n; ++i) ls[i] = separation(values, i);
  const bool retract = options_.direction == CurveDirection::retract;
  long solves = 0;
  Point p;
  {
    const double l0 = retract ? *std::max_element(ls.begin(), ls.end()) : ls.front();
    const TappingModel start = m.with_separation(l0);
    std::optional<PeriodicOrbit> o;
    try {
      o = tapping::try_shoot(start, tapping::free_response_state(start), 1, sweep_.shooting);
    } catch (const NumericalFailure&) {
      o.reset();
    }
    ++solves;
    if (o && o->stable) {
      p.orbit = *o;
      p.orbit.separation = l0;
    } else {
      p = settle_at(start, tapping::free_response_state(start), sweep_);
      p.jumped = false;
    }
  }
  if (retract) {  // approach down to the smallest distance first (the retract starts where the approach ended)
    std::vector<double> down(ls.rbegin(), ls.rend());
    for (std::size_t k = 1; k < down.size(); ++k) {
      options_.cancellation.check();
      p = step(m, p, down[k], sweep_, solves);
    }
  }
  e.orbits.resize(n);
  e.periodic.resize(n);
  e.jumped.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    options_.cancellation.check();
    if (i > 0) p = step(m, p, ls[i], sweep_, solves);
    e.orbits[i] = p.orbit;
    e.orbits[i].separation = ls[i];
    e.periodic[i] = p.periodic;
    e.jumped[i] = p.jumped;
  }
  orbits_ += solves;
  finish(m, values, e);
  return e;
}

CurveEvaluation AmForwardModel::warm(const ModelValues& values, const CurveEvaluation& from, bool chord) const {
  const std::size_t n = distances_.size();
  if (!from.ok || from.orbits.size() != n) return walk(values);
  for (std::size_t i = 0; i < n; ++i)
    if (!from.periodic[i] || !from.orbits[i].stable) return walk(values);
  ++curves_;
  const TappingModel m = model(values);
  CurveEvaluation e;
  e.orbits.resize(n);
  e.periodic.assign(n, true);
  e.jumped = from.jumped;
  tapping::ShootingOptions quick = sweep_.shooting;
  quick.max_iterations = std::min(quick.max_iterations, 8);
  tapping::SimulationOptions plain = sweep_.shooting.simulation;
  plain.sensitivity = false;
  const double omega = m.drive.frequency;
  const double amplitude = m.free_amplitude();
  const EachPointResult done = each_point(n, options_.parallel, [&](std::size_t i) {
    const PeriodicOrbit& old = from.orbits[i];
    const TappingModel at = m.with_separation(separation(values, i));
    std::optional<PeriodicOrbit> o;
    if (chord) {
      // one chord-Newton step with the monodromy of `old`: z' = z − (M − I)⁻¹ (P'(z) − z), off the perturbed
      // orbit by O(|z' − z|²), the order of the forward difference's own error (docs/fitting.md#jacobian)
      const int k = old.period_multiple;
      const tapping::SimulationResult r = tapping::simulate(at, 0.0, old.initial, k * at.period(), plain);
      const Eigen::Vector2d res(r.state.position - old.initial.position, r.state.velocity - old.initial.velocity);
      const Eigen::Vector2d dz = (old.monodromy - Eigen::Matrix2d::Identity()).fullPivLu().solve(-res);
      if (dz.allFinite() && std::hypot(dz.x(), dz.y() / omega) <= 0.01 * amplitude) {
        o = old;
        o->initial = {old.initial.position + dz.x(), old.initial.velocity + dz.y()};
      }
    }
    if (!o) {
      try {
        o = tapping::try_shoot(at, old.initial, old.period_multiple, quick);
      } catch (const NumericalFailure&) {
        o.reset();
      }
    }
    // the same branch: stable, of the same period, and near the previous orbit (a small change of the values
    // moves the orbit a little; another branch is a finite distance away)
    const bool near = o && o->stable && o->period_multiple == old.period_multiple &&
                      state_distance(o->initial, old.initial, omega) <= 0.05 * amplitude;
    if (!near) return false;
    e.orbits[i] = *o;
    e.orbits[i].separation = at.separation;
    return true;
  });
  orbits_ += done.visited;
  if (!done.all) return walk(values);
  if (!chord) {
    // where `from` jumped (its branch ended between the points i − 1 and i), the branch must still end there: the
    // orbit at i − 1 followed to l_i must not arrive (else the jump moved past a point: the whole sweep decides)
    tapping::SweepOptions check = sweep_;
    check.jump_tolerance = 1e-2;  // only whether it arrives, not where it ends
    for (std::size_t i = 1; i < n; ++i) {
      if (!from.jumped[i] || from.jumped[i - 1]) continue;
      const tapping::BranchFollow f = tapping::follow_stable_branch(m, e.orbits[i - 1], e.orbits[i].separation, check);
      orbits_ += f.substeps;
      if (f.reached) return walk(values);
    }
  }
  finish(m, values, e);
  return e;
}

}  // namespace afmkit::spectroscopy
