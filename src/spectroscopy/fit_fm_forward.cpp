// The forward model of the FM fit: frequency shift and dissipation along the measured distances from the exact FM
// orbits of `tapping fm` (tapping/fm.hpp), continued along the curve as the instrument sweeps it
// (docs/fitting.md#fm-afm).
#include <algorithm>
#include <atomic>
#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/spectroscopy/fit_model.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::spectroscopy {

FmForwardModel::FmForwardModel(const FmFitSettings& settings, const FitOptions& options,
                               std::vector<double> distances)
    : settings_(settings), options_(options), distances_(std::move(distances)) {
  fm_.shooting.simulation.relative_tolerance = options.integrator_tolerance;
  fm_.shooting.tolerance = options.shooting_tolerance;
}

tapping::FmSetting FmForwardModel::setting(const ModelValues& values) const {
  // the cantilever in afmkit's physical units (ω_n = 1, lengths in nm, forces / k); the free amplitude of a
  // driven cantilever does not enter an FM orbit (its drive is an unknown): A is passed for the validation only
  const tapping::PhysicalCantilever pc(settings_.spring_constant, settings_.resonance_frequency * 1e-3,
                                       settings_.quality_factor, settings_.amplitude * 1e9, 1.0);
  return tapping::FmSetting(pc.cantilever(), pc.normalised_law(build_law(options_, values)), settings_.amplitude * 1e9);
}

double FmForwardModel::separation(const ModelValues& values, std::size_t i) const {
  return (distances_[i] + values.distance_offset) * 1e9;  // nm
}

void FmForwardModel::finish(FmCurveEvaluation& e) const {
  const std::size_t n = distances_.size();
  e.frequency_shift.assign(n, 0.0);
  e.dissipation.assign(n, 0.0);
  e.contact.assign(n, false);
  e.ok = true;
  for (std::size_t i = 0; i < n; ++i) {
    const tapping::FmOrbit& o = e.orbits[i];
    // ω_n = 1: Δω/ω_n = Δf/f0; energies: k · (1 nm)² = 1e-18 J per model unit and N/m
    e.frequency_shift[i] = o.frequency_shift() / o.natural_frequency * settings_.resonance_frequency;
    e.dissipation[i] = o.tip_dissipation() * settings_.spring_constant * 1e-18;
    e.contact[i] = o.metrics.contact_fraction > 0.0;
    if (!std::isfinite(e.frequency_shift[i]) || !std::isfinite(e.dissipation[i])) e.ok = false;
  }
  if (!e.ok) e.error = "an FM orbit's frequency shift or dissipation is not finite";
}

FmCurveEvaluation FmForwardModel::walk(const ModelValues& values) const {
  ++curves_;
  const tapping::FmSetting s = setting(values);
  const std::size_t n = distances_.size();
  std::vector<double> ls(n);
  for (std::size_t i = 0; i < n; ++i) ls[i] = separation(values, i);
  // the targets of the sweep: the points (approach); a retract curve after the approach down to its smallest
  std::vector<double> targets;
  const bool retract = options_.direction == CurveDirection::retract;
  if (retract) targets.assign(ls.rbegin(), ls.rend() - 1);
  targets.insert(targets.end(), ls.begin(), ls.end());
  tapping::FmSweepOptions o;
  o.fm = fm_;
  o.cancellation = options_.cancellation;
  const tapping::FmSweepResult r = tapping::sweep_fm(s, targets, o);
  orbits_ += static_cast<long>(targets.size()) + r.failed_attempts;
  FmCurveEvaluation e;
  e.orbits.resize(n);
  e.jacobians.resize(n);
  e.jumped.assign(n, false);
  const std::size_t first = targets.size() - n;
  for (std::size_t i = 0; i < n; ++i) {
    const tapping::FmPoint& pt = r.points[first + i];
    if (!pt.orbit) {
      e.ok = false;
      e.error = fmt::format("no FM orbit at model separation {:.6g} nm (distance {:.6g} nm + distance_offset {:.6g} nm)",
                            ls[i], distances_[i] * 1e9, values.distance_offset * 1e9);
      return e;
    }
    e.orbits[i] = *pt.orbit;
    e.jumped[i] = pt.jumped;
  }
  finish(e);
  return e;
}

FmCurveEvaluation FmForwardModel::warm(const ModelValues& values, const FmCurveEvaluation& from, bool) const {
  const std::size_t n = distances_.size();
  if (!from.ok || from.orbits.size() != n) return walk(values);
  // a curve that jumped through a fold: whether the jump stays between the same points is the sweep's to decide
  if (std::any_of(from.jumped.begin(), from.jumped.end(), [](bool b) { return b; })) return walk(values);
  ++curves_;
  const tapping::FmSetting s = setting(values);
  tapping::FmOptions quick = fm_;
  quick.shooting.max_iterations = std::min(quick.shooting.max_iterations, 8);
  FmCurveEvaluation e;
  e.orbits.resize(n);
  e.jacobians = from.jacobians;
  e.jumped.assign(n, false);
  const double a = s.amplitude;
  const EachPointResult done = each_point(n, options_.parallel, [&](std::size_t i) {
    const tapping::FmOrbit& old = from.orbits[i];
    std::optional<tapping::FmOrbit> o;
    try {
      o = tapping::try_solve_fm(s, separation(values, i), old.state, quick, &e.jacobians[i]);
    } catch (const NumericalFailure&) {
      o.reset();
    }
    // the same branch: near the previous orbit in state and frequency (a small change of the values moves the
    // orbit a little; another branch is a finite distance away)
    const bool near = o && state_distance(o->state.initial, old.state.initial, old.state.frequency) <= 0.05 * a &&
                      std::abs(o->state.frequency - old.state.frequency) <= 0.05 * old.state.frequency;
    if (!near) return false;
    e.orbits[i] = *o;
    return true;
  });
  orbits_ += done.visited;
  if (!done.all) return walk(values);
  finish(e);
  return e;
}

}  // namespace afmkit::spectroscopy
