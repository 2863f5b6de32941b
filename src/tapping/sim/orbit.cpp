#include "afmkit/tapping/orbit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <numbers>
#include <optional>
#include <utility>

#include <Eigen/LU>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/parallel.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/continuation.hpp"
#include "afmkit/tapping/observer.hpp"
#include "phase_space.hpp"

namespace afmkit::tapping {

const char* orbit_source_name(OrbitSource source) {
  switch (source) {
    case OrbitSource::hb_free: return "hb_free";
    case OrbitSource::hb_plus: return "hb_plus";
    case OrbitSource::hb_minus: return "hb_minus";
    case OrbitSource::transient: return "transient";
    case OrbitSource::previous: return "previous";
    case OrbitSource::continuation: return "continuation";
    case OrbitSource::grid: return "grid";
    case OrbitSource::contact: return "contact";
  }
  return "?";
}

const char* seed_kind_name(SeedKind kind) {
  switch (kind) {
    case SeedKind::harmonic_balance: return "harmonic_balance";
    case SeedKind::transient: return "transient";
    case SeedKind::grid: return "grid";
    case SeedKind::contact: return "contact";
    case SeedKind::continuation: return "continuation";
  }
  return "?";
}

void OrbitSearchOptions::validate() const {
  shooting.validate();
  transient.validate();
  validate::require(grid_phases >= 1 && grid_phases <= 360, "grid_phases", grid_phases, "in [1, 360]");
  for (double f : grid_amplitudes)
    validate::require(std::isfinite(f) && f >= 0.0 && f <= 100.0, "grid_amplitudes", f, "in [0, 100] (factors of max(A_free, |l|))");
  for (std::size_t k = 0; k < grid_transient_periods.size(); ++k)
    validate::require(grid_transient_periods[k] >= 1 && grid_transient_periods[k] <= 1000000 &&
                          (k == 0 || grid_transient_periods[k] > grid_transient_periods[k - 1]),
                      "grid_transient_periods", grid_transient_periods[k], "increasing, in [1, 1000000]");
  validate::require(std::isfinite(bracket_fraction) && bracket_fraction >= 0.0 && bracket_fraction <= 10.0,
                    "bracket_fraction", bracket_fraction, "in [0, 10]");
  validate::require(continuation_max_points >= 2, "continuation_max_points", continuation_max_points, ">= 2");
  validate::require(duplicate_tolerance > 0.0 && duplicate_tolerance <= 1e-2, "duplicate_tolerance",
                    duplicate_tolerance, "in (0, 1e-2]");
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

bool tip_trapped(const OrbitMetrics& metrics) {
  const double tolerance = 1e-6;
  const bool stuck = metrics.duration > 0.0 && metrics.sticking_duration >= (1.0 - tolerance) * metrics.duration;
  return stuck || metrics.contact_fraction >= 1.0 - tolerance;
}

OrbitMetrics analyse_orbit(const TappingModel& model, const PeriodicOrbit& orbit, const SimulationOptions& options) {
  const int n = orbit.period_multiple;
  const double duration = n * model.period();
  // panels of 1/12 of the shortest period: for the closed form (segments from event to event); the adaptive
  // integrator's segments are its steps (at most 1/24 of it, each a polynomial of degree ≤ 7 in its dense output),
  // so one panel of 20 Gauss nodes (exact to degree 39) per step integrates x e^{−ikωt} (k ≤ 5) to rounding
  OrbitIntegrals integrals(quadrature_panel(model));
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
  m.duration = duration;
  return m;
}

namespace {


/// Same orbit: one of the n stroboscopic points of `a` coincides with b.initial.
bool same_orbit(const TappingModel& model, const PeriodicOrbit& a, const PeriodicOrbit& b, double tol,
                const SimulationOptions& sim) {
  if (a.period_multiple != b.period_multiple) return false;
  const double omega = model.drive.frequency;
  const double scale = std::max({1.0, std::hypot(a.initial.position, a.initial.velocity / omega)});
  TipState p = a.initial;
  for (int j = 0; j < a.period_multiple; ++j) {
    if (detail::phase_distance(p, b.initial, omega) <= tol * scale) return true;
    if (j + 1 < a.period_multiple) p = simulate(model, 0.0, p, model.period(), sim).state;
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

namespace {

/// One seed of the search (SearchSeed plus what to do with it).
struct Task {
  SeedKind kind;
  OrbitSource source;
  TipState start;
  std::optional<HbPoint> hb{};  // harmonic_balance seeds: the HB solution the guess comes from
  double phase = 0.0, amplitude = 0.0;
};

/// Newton from an HB solution; when HB predicts contact but Newton slid onto a contact-free orbit (a grazing
/// contact orbit missed by the guess), seed again on the impact section.
std::optional<PeriodicOrbit> shoot_from_hb(const TappingModel& model, const Task& task, const ShootingOptions& shooting) {
  auto found = try_shoot(model, task.start, 1, shooting);
  if (task.hb && task.hb->q < 1.0 && (!found || found->stats.impacts == 0)) {
    if (auto guess = impact_section_guess(model, *task.hb, shooting.simulation)) {
      auto again = try_shoot(model, *guess, 1, shooting);
      if (again && again->stats.impacts > 0) found = again;
    }
  }
  return found;
}

/// Grid / contact seed: Newton from the state, then after each cumulative number of drive periods of transient.
std::vector<PeriodicOrbit> shoot_with_short_transients(const TappingModel& model, TipState y,
                                                       const std::vector<int>& periods, const ShootingOptions& quick,
                                                       const SimulationOptions& sim) {
  std::vector<PeriodicOrbit> found;
  auto attempt = [&](TipState s) {
    try {
      if (auto o = try_shoot(model, s, 1, quick)) found.push_back(*o);
    } catch (const NumericalFailure&) {
    }
  };
  attempt(y);
  int done = 0;
  for (int k : periods) {
    // every period restarts at t = 0: the drive is T-periodic, so the phase stays exact
    for (; done < k; ++done) y = simulate(model, 0.0, y, model.period(), sim).state;
    attempt(y);
  }
  return found;
}

double elapsed_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

namespace {
OrbitSearchResult search_orbits(const TappingModel& model, const OrbitSearchOptions& options) {
  const auto t_start = std::chrono::steady_clock::now();
  OrbitSearchResult out;
  std::vector<Task> tasks;
  const double omega = model.drive.frequency, l = model.separation;
  const double free_amplitude = model.free_amplitude();
  if (options.from_harmonic_balance) {  // any law (closed form for piecewise-linear ones)
    out.harmonic_balance = HarmonicBalance(model, options.cancellation).solutions(model.separation);
    for (const HbPoint& p : out.harmonic_balance) {
      // x ≈ A + B cos(ωt − φ): x(0) = A + B cos φ, ẋ(0) = Bω sin φ
      const TipState guess{p.offset + p.amplitude * std::cos(p.phase), p.amplitude * omega * std::sin(p.phase)};
      const OrbitSource src = p.branch == HbBranch::Free   ? OrbitSource::hb_free
                              : p.branch == HbBranch::Plus ? OrbitSource::hb_plus
                                                           : OrbitSource::hb_minus;
      tasks.push_back({SeedKind::harmonic_balance, src, guess, p});
      // HB is accurate to ~1 %: when two orbits lie closer than that, Newton from the HB guess may pick the
      // wrong one; a transient from the same guess finds the attractor of that neighbourhood.
      if (options.from_transient && src != OrbitSource::hb_free)
        tasks.push_back({SeedKind::transient, OrbitSource::transient, guess});
    }
  }
  if (options.from_transient) {
    tasks.push_back({SeedKind::transient, OrbitSource::transient, free_response_state(model)});
    tasks.push_back({SeedKind::transient, OrbitSource::transient, TipState{0.0, 0.0}});
  }
  if (options.from_grid) {
    // phase × energy of the motion: x(t) ≈ a cos(ωt − θ), from near rest to beyond the free amplitude and the
    // separation (amplitudes above l reach the sample)
    const double a_ref = std::max(free_amplitude, std::abs(l));
    for (double f : options.grid_amplitudes) {
      const int phases = f == 0.0 ? 1 : options.grid_phases;
      for (int j = 0; j < phases; ++j) {
        const double theta = 2.0 * std::numbers::pi * j / phases, a = f * a_ref;
        tasks.push_back({SeedKind::grid, OrbitSource::grid, {a * std::cos(theta), a * omega * std::sin(theta)},
                         std::nullopt, theta, a});
      }
    }
    // in contact: just below the contact edge (2 % of a_ref deep), moving in, at rest, moving out
    const double edge = model.law.switching_gaps().empty() ? 0.0 : model.law.switching_gaps().front();
    const double x_in = edge - l - 0.02 * a_ref;
    for (double v : {-1.0, -0.3, 0.0, 0.3, 1.0})
      tasks.push_back({SeedKind::contact, OrbitSource::contact, {x_in, v * omega * a_ref}});
  }

  SimulationOptions sim = options.shooting.simulation;
  sim.sensitivity = false;
  ShootingOptions quick = options.shooting;
  quick.max_iterations = std::min(quick.max_iterations, 10);
  TransientOptions transient = options.transient;
  transient.cancellation = options.cancellation;  // a long transient stops within a chunk on request
  std::vector<std::vector<PeriodicOrbit>> found(tasks.size());
  std::vector<std::optional<TransientOutcome>> outcomes(tasks.size());
  ExceptionCollector errors;  // a candidate that fails numerically is dropped; anything else is an error
#pragma omp parallel for schedule(dynamic) if (options.parallel)
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    errors.run([&] {
    options.cancellation.check();
    try {
      switch (tasks[i].kind) {
        case SeedKind::transient:
          outcomes[i] = settle(model, tasks[i].start, transient, options.shooting);
          if (outcomes[i]->orbit) found[i].push_back(*outcomes[i]->orbit);
          break;
        case SeedKind::harmonic_balance:
          if (auto o = shoot_from_hb(model, tasks[i], options.shooting)) found[i].push_back(*o);
          break;
        default: found[i] = shoot_with_short_transients(model, tasks[i].start, options.grid_transient_periods, quick, sim);
      }
    } catch (const NumericalFailure&) {
      // this candidate failed (time or event budget, divergence); others may succeed
    }
    });
  }
  errors.rethrow();
  for (auto& o : outcomes)
    if (o) out.transients.push_back(std::move(*o));

  OrbitSearchReport& report = out.report;
  auto add_seed = [&](const Task& t) {
    SearchSeed s;
    s.kind = t.kind;
    s.start = t.start;
    s.grid_phase = t.phase;
    s.grid_amplitude = t.amplitude;
    report.seeds.push_back(s);
  };
  // merge: each converged orbit is either one already listed (record the seed) or a new one
  auto merge = [&](int seed, OrbitSource source, const PeriodicOrbit& orbit) {
    int index = -1;
    for (std::size_t k = 0; k < out.orbits.size() && index < 0; ++k)
      if (same_orbit(model, out.orbits[k].orbit, orbit, options.duplicate_tolerance, sim)) index = static_cast<int>(k);
    if (index < 0) {
      index = static_cast<int>(out.orbits.size());
      out.orbits.push_back({source, orbit, {}, {}});
    }
    auto& orbit_seeds = out.orbits[index].seeds;
    if (orbit_seeds.empty() || orbit_seeds.back() != seed) orbit_seeds.push_back(seed);
    auto& seed_orbits = report.seeds[seed].orbits;
    if (std::find(seed_orbits.begin(), seed_orbits.end(), index) == seed_orbits.end()) seed_orbits.push_back(index);
  };
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    add_seed(tasks[i]);
    for (const PeriodicOrbit& o : found[i]) merge(static_cast<int>(i), tasks[i].source, o);
  }

  // Continuation: follow the branch of every period-1 orbit found through l ± w in both directions (through
  // folds, so the unstable orbit between two stable ones is reached from either of them); each point where a
  // branch crosses l again seeds Newton at l.
  if (options.from_continuation && options.bracket_fraction > 0.0) {
    const double w = options.bracket_fraction * free_amplitude;
    report.bracket_min = l - w;
    report.bracket_max = l + w;
    ContinuationOptions copt;
    copt.shooting = options.shooting;
    copt.harmonic_balance = false;
    copt.analyse_points = false;
    copt.parallel = false;
    copt.max_points = options.continuation_max_points;
    copt.max_step = std::max(copt.max_step, 0.02 * free_amplitude);
    copt.min_step = 1e-6 * std::max(1.0, free_amplitude);
    copt.initial_step = std::clamp(0.1 * w, copt.min_step, copt.max_step);
    copt.time_budget_seconds = options.shooting.time_budget_seconds;
    copt.cancellation = options.cancellation;
    std::vector<std::pair<PeriodicOrbit, bool>> runs;
    for (const FoundOrbit& f : out.orbits)
      if (f.orbit.period_multiple == 1)
        for (bool up : {true, false}) runs.push_back({f.orbit, up});
    report.continuation_runs = static_cast<int>(runs.size());
    std::vector<std::vector<TipState>> crossings(runs.size());
#pragma omp parallel for schedule(dynamic) if (options.parallel)
    for (std::size_t r = 0; r < runs.size(); ++r) {
      errors.run([&] {
      try {
        const ContinuationResult c = continue_orbits(model, runs[r].first, l - w, l + w, runs[r].second, copt);
        for (std::size_t k = 1; k < c.points.size(); ++k) {
          const SweepPoint &a = c.points[k - 1], &b = c.points[k];
          const double da = a.separation - l, db = b.separation - l;
          if (db == 0.0) {
            crossings[r].push_back(b.orbit.initial);
          } else if (da != 0.0 && (da < 0) != (db < 0)) {
            const double u = da / (da - db);
            crossings[r].push_back({a.orbit.initial.position + u * (b.orbit.initial.position - a.orbit.initial.position),
                                    a.orbit.initial.velocity + u * (b.orbit.initial.velocity - a.orbit.initial.velocity),
                                    a.orbit.initial.contact});
          }
        }
      } catch (const NumericalFailure&) {
        // a continuation that cannot start or proceed contributes no seeds
      }
      });
    }
    errors.rethrow();
    std::vector<Task> more;
    for (const auto& list : crossings)
      for (const TipState& s : list) more.push_back({SeedKind::continuation, OrbitSource::continuation, s});
    std::vector<std::optional<PeriodicOrbit>> shot(more.size());
#pragma omp parallel for schedule(dynamic) if (options.parallel)
    for (std::size_t i = 0; i < more.size(); ++i) {
      errors.run([&] {
        options.cancellation.check();
        try {
          shot[i] = try_shoot(model, more[i].start, 1, options.shooting);
        } catch (const NumericalFailure&) {
          shot[i].reset();
        }
      });
    }
    errors.rethrow();
    for (std::size_t i = 0; i < more.size(); ++i) {
      const int seed = static_cast<int>(report.seeds.size());
      add_seed(more[i]);
      if (shot[i]) merge(seed, OrbitSource::continuation, *shot[i]);
    }
  }

#pragma omp parallel for schedule(dynamic) if (options.parallel)
  for (std::size_t i = 0; i < out.orbits.size(); ++i)
    errors.run([&] { options.cancellation.check(); out.orbits[i].metrics = analyse_orbit(model, out.orbits[i].orbit, options.shooting.simulation); });
  errors.rethrow();
  // by increasing amplitude; renumber the seeds' orbit indices
  std::vector<int> order(out.orbits.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return out.orbits[a].metrics.amplitude < out.orbits[b].metrics.amplitude;
  });
  std::vector<int> rank(order.size());
  std::vector<FoundOrbit> sorted;
  sorted.reserve(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    rank[order[k]] = static_cast<int>(k);
    sorted.push_back(std::move(out.orbits[order[k]]));
  }
  out.orbits = std::move(sorted);
  for (SearchSeed& s : report.seeds) {
    for (int& index : s.orbits) index = rank[index];
    const auto kind = static_cast<std::size_t>(s.kind);
    ++report.seeds_by_kind[kind];
    if (s.converged()) ++report.converged_by_kind[kind];
  }
  report.seconds = elapsed_since(t_start);
  return out;
}
}  // namespace

OrbitSearchResult find_orbits(const TappingModel& model, const OrbitSearchOptions& options) {
  options.validate();
  // the model and the options are checked: what is refused from here on was computed (core/computed.hpp)
  return computed("orbit search", [&] { return search_orbits(model, options); });
}

}  // namespace afmkit::tapping
