#include "afmkit/tapping/orbit.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <numbers>
#include <optional>
#include <utility>

#include <Eigen/LU>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/observer.hpp"

namespace afmkit::tapping {

const char* orbit_source_name(OrbitSource source) {
  switch (source) {
    case OrbitSource::hb_free: return "hb_free";
    case OrbitSource::hb_plus: return "hb_plus";
    case OrbitSource::hb_minus: return "hb_minus";
    case OrbitSource::transient: return "transient";
    case OrbitSource::previous: return "previous";
    case OrbitSource::continuation: return "continuation";
  }
  return "?";
}

namespace {

/// Quadrature panel: a fraction of the shortest period present (drive, stiffest contact mode).
double quadrature_panel(const TappingModel& model) {
  const double wn = model.cantilever.natural_frequency;
  double stiff = wn * wn;
  if (const auto* p = model.law.piecewise_linear()) stiff += std::max(p->approach_stiffness, p->departure_stiffness);
  const double shortest = std::min(model.period(), 2.0 * std::numbers::pi / std::sqrt(stiff));
  return shortest / 12.0;
}

}  // namespace

OrbitMetrics analyse_orbit(const TappingModel& model, const PeriodicOrbit& orbit, const SimulationOptions& options) {
  const int n = orbit.period_multiple;
  const double duration = n * model.period();
  OrbitIntegrals integrals(quadrature_panel(model) / (model.law.piecewise_linear() ? 1.0 : 4.0));
  SimulationOptions o = options;
  o.sensitivity = false;
  const TappingModel at = model.with_separation(orbit.separation);
  const SimulationResult r = simulate(at, 0.0, orbit.initial, duration, o, &integrals);
  OrbitMetrics m;
  m.offset = integrals.fourier[0].real() / duration;
  const std::complex<double> c1 = 2.0 * integrals.fourier[1] / duration;  // x ≈ A + Re(c1 e^{iωt})
  m.amplitude = std::abs(c1);
  m.phase = -std::arg(c1);  // x ≈ A + B cos(ωt − φ)
  for (int k = 2; k <= 5; ++k) m.harmonics[k - 2] = 2.0 * std::abs(integrals.fourier[k]) / duration;
  m.contact_fraction = integrals.contact_time / duration;
  m.peak_force = integrals.peak_force;
  m.min_gap = integrals.min_gap;
  m.drive_work = integrals.drive_work / n;
  m.viscous_dissipation = integrals.viscous_dissipation / n;
  m.contact_dissipation = integrals.contact_dissipation / n;
  m.impacts_per_period_multiple = r.stats.impacts;
  m.sticking_duration = r.stats.sticking_duration;
  return m;
}

namespace {

struct Task {
  OrbitSource source;
  TipState guess;
  bool transient;                // settle first, then the outcome's orbit
  std::optional<HbPoint> hb{};   // the HB solution the guess comes from
};

double distance(TipState a, TipState b, double omega) {
  return std::hypot(a.position - b.position, (a.velocity - b.velocity) / omega);
}

/// Same orbit: one of the n stroboscopic points of `a` coincides with b.initial.
bool same_orbit(const TappingModel& model, const PeriodicOrbit& a, const PeriodicOrbit& b, double tol,
                const SimulationOptions& sim) {
  if (a.period_multiple != b.period_multiple) return false;
  const double omega = model.drive.frequency;
  const double scale = std::max({1.0, std::hypot(a.initial.position, a.initial.velocity / omega)});
  TipState p = a.initial;
  for (int j = 0; j < a.period_multiple; ++j) {
    if (distance(p, b.initial, omega) <= tol * scale) return true;
    p = simulate(model, 0.0, p, model.period(), sim).state;
  }
  return false;
}

}  // namespace

namespace {

/// Newton on the impact section (the state at the instant the gap falls through the contact edge, as
/// (impact time, impact velocity)) from the HB prediction of that impact; returns the stroboscopic state of
/// the period-1 contact orbit found, for polishing by shooting. Unlike the stroboscopic map this section cannot
/// slide onto a contact-free orbit, so it finds contact orbits that graze (tiny penetration), which Newton on
/// the stroboscopic map loses to the free orbit when the HB guess misses the sample.
std::optional<TipState> impact_section_guess(const TappingModel& model, const HbPoint& hb, const SimulationOptions& sim) {
  const double omega = model.drive.frequency, period = model.period();
  const double edge = model.law.switching_gaps().empty() ? 0.0 : model.law.switching_gaps().front();
  const double x_edge = edge - model.separation;
  const double q = std::clamp(hb.q, -1.0, 1.0);
  if (!(hb.q < 1.0)) return std::nullopt;
  // x = A + B cos(ωt − φ) reaches the edge going down at ωt − φ = π − arccos q
  double ti = (hb.phase + std::numbers::pi - std::acos(q)) / omega;
  ti -= std::floor(ti / period) * period;
  double vi = -hb.amplitude * omega * std::sqrt(std::max(0.0, 1.0 - q * q));
  if (!(vi < 0)) return std::nullopt;
  SimulationOptions o = sim;
  o.sensitivity = false;
  // next impact after leaving contact: (time, velocity)
  auto next_impact = [&](double t, double v) -> std::optional<std::pair<double, double>> {
    EventRecorder events;
    simulate(model, t, {x_edge, v}, t + 1.6 * period, o, &events);
    bool left = false;
    for (const Event& e : events.events()) {
      if (e.guard.kind != GuardKind::gap) continue;
      if (e.guard.direction == CrossingDirection::rising) left = true;
      if (left && e.guard.direction == CrossingDirection::falling && e.after.region == 0)
        return std::pair<double, double>(e.time, e.state.velocity);
    }
    return std::nullopt;
  };
  const double vscale = std::max(1e-12, hb.amplitude * omega);
  for (int it = 0; it < 30; ++it) {
    const auto f0 = next_impact(ti, vi);
    if (!f0) return std::nullopt;
    const Eigen::Vector2d r((f0->first - ti - period) * omega, (f0->second - vi) / vscale);
    if (r.norm() < 1e-10) break;
    Eigen::Matrix2d j;
    const double ht = 1e-7 * period, hv = 1e-7 * std::max(std::abs(vi), 1e-3 * vscale);
    const auto ft = next_impact(ti + ht, vi);
    const auto fv = next_impact(ti, vi + hv);
    if (!ft || !fv) return std::nullopt;
    j.col(0) = (Eigen::Vector2d((ft->first - ti - ht - period) * omega, (ft->second - vi) / vscale) - r) / ht;
    j.col(1) = (Eigen::Vector2d((fv->first - ti - period) * omega, (fv->second - vi - hv) / vscale) - r) / hv;
    const Eigen::Vector2d step = -j.fullPivLu().solve(r);
    if (!step.allFinite()) return std::nullopt;
    // keep the impact velocity negative (an impact) and the step moderate
    double lambda = 1.0;
    while (vi + lambda * step.y() >= 0 && lambda > 1e-3) lambda *= 0.5;
    ti += lambda * step.x();
    vi += lambda * step.y();
    if (!(vi < 0)) return std::nullopt;
  }
  // stroboscopic state at the next multiple of the period
  const double t_strobe = std::ceil(ti / period + 1e-12) * period;
  return simulate(model, ti, {x_edge, vi}, t_strobe, o).state;
}

}  // namespace

OrbitSearchResult find_orbits(const TappingModel& model, const OrbitSearchOptions& options) {
  options.shooting.validate();
  options.transient.validate();
  OrbitSearchResult out;
  std::vector<Task> tasks;
  const double omega = model.drive.frequency;
  if (options.from_harmonic_balance && model.law.piecewise_linear()) {
    out.harmonic_balance = harmonic_balance_solutions(model);
    for (const HbPoint& p : out.harmonic_balance) {
      // x ≈ A + B cos(ωt − φ): x(0) = A + B cos φ, ẋ(0) = Bω sin φ
      const TipState guess{p.offset + p.amplitude * std::cos(p.phase), p.amplitude * omega * std::sin(p.phase)};
      const OrbitSource src = p.branch == HbBranch::Free   ? OrbitSource::hb_free
                              : p.branch == HbBranch::Plus ? OrbitSource::hb_plus
                                                           : OrbitSource::hb_minus;
      tasks.push_back({src, guess, false, p});
      // HB is accurate to ~1 %: when two orbits lie closer than that, Newton from the HB guess may pick the
      // wrong one; a transient from the same guess finds the attractor of that neighbourhood.
      if (options.from_transient && src != OrbitSource::hb_free) tasks.push_back({OrbitSource::transient, guess, true});
    }
  }
  if (options.from_transient) {
    tasks.push_back({OrbitSource::transient, free_response_state(model), true});
    tasks.push_back({OrbitSource::transient, TipState{0.0, 0.0}, true});
  }
  std::vector<std::optional<PeriodicOrbit>> found(tasks.size());
  std::vector<std::optional<TransientOutcome>> outcomes(tasks.size());
  SimulationOptions sim = options.shooting.simulation;
  sim.sensitivity = false;
#pragma omp parallel for schedule(dynamic) if (options.parallel)
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    try {
      if (tasks[i].transient) {
        outcomes[i] = settle(model, tasks[i].guess, options.transient, options.shooting);
        if (outcomes[i]->orbit) found[i] = outcomes[i]->orbit;
      } else {
        found[i] = try_shoot(model, tasks[i].guess, 1, options.shooting);
        // HB predicts contact but Newton slid onto a contact-free orbit (a grazing contact orbit missed by the
        // guess): seed again on the impact section
        if (tasks[i].hb && tasks[i].hb->q < 1.0 && (!found[i] || found[i]->stats.impacts == 0)) {
          if (auto guess = impact_section_guess(model, *tasks[i].hb, options.shooting.simulation)) {
            auto again = try_shoot(model, *guess, 1, options.shooting);
            if (again && again->stats.impacts > 0) found[i] = again;
          }
        }
      }
    } catch (const NumericalFailure&) {
      found[i].reset();  // this candidate failed; others may succeed
    }
  }
  for (auto& o : outcomes)
    if (o) out.transients.push_back(std::move(*o));
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (!found[i]) continue;
    bool duplicate = false;
    for (const FoundOrbit& f : out.orbits)
      duplicate = duplicate || same_orbit(model, f.orbit, *found[i], options.duplicate_tolerance, sim);
    if (!duplicate) out.orbits.push_back({tasks[i].source, *found[i], {}});
  }
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic) if (options.parallel)
  for (std::size_t i = 0; i < out.orbits.size(); ++i) {
    try {
      out.orbits[i].metrics = analyse_orbit(model, out.orbits[i].orbit, options.shooting.simulation);
    } catch (...) {
#pragma omp critical(afmkit_orbit_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
  std::sort(out.orbits.begin(), out.orbits.end(),
            [](const FoundOrbit& a, const FoundOrbit& b) { return a.metrics.amplitude < b.metrics.amplitude; });
  return out;
}

}  // namespace afmkit::tapping
