#include "afmkit/tapping/continuation.hpp"

#include <chrono>
#include <cmath>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "sweep_points.hpp"

namespace afmkit::tapping {

void ContinuationOptions::validate() const {
  validate::positive("initial_step", initial_step);
  validate::positive("min_step", min_step);
  validate::require(max_step >= initial_step && initial_step >= min_step, "initial_step", initial_step,
                    fmt::format("in [min_step = {}, max_step = {}]", min_step, max_step));
  validate::require(max_points >= 2, "max_points", max_points, ">= 2");
  validate::require(max_corrector_iterations >= 2, "max_corrector_iterations", max_corrector_iterations, ">= 2");
  validate::require(tolerance > 0 && tolerance < 1e-3, "tolerance", tolerance, "in (0, 1e-3)");
  validate::positive("time_budget_seconds", time_budget_seconds);
  shooting.validate();
}

namespace {

/// Shooting residual and its Jacobian in scaled unknowns z = (x(0), ẋ(0)/ω, l).
struct Residual {
  Eigen::Vector2d value;
  Eigen::Matrix<double, 2, 3> jacobian;
  StroboscopicMap map;
  bool memory = false;  // the memory of contact the map started with (contact-aware laws; docs/force-laws.md)
  bool memory_repeats() const { return map.end.contact == memory; }
};

/// `memory`: the start memory of a contact-aware law; when the period ends with the other, the map is evaluated
/// again from that one (as try_shoot does: a periodic orbit starts with the memory it ends with).
Residual residual(const TappingModel& base, const Eigen::Vector3d& z, const SimulationOptions& sim, bool memory) {
  const double omega = base.drive.frequency;
  // a predictor along a tangent of a singular Jacobian (a tip held in contact: no motion to follow) gives NaN
  // unknowns; that is the continuation's failure, not a separation the user gave (issue 24 §2)
  if (!z.allFinite())
    throw NumericalFailure(fmt::format("branch continuation: the unknowns (x, v/omega, l) = ({}, {}, {}) are not "
                                       "finite (the shooting Jacobian is singular: no branch to follow)",
                                       z.x(), z.y(), z.z()));
  const TappingModel model = base.with_separation(z.z());
  Residual r;
  r.memory = memory;
  r.map = stroboscopic_map(model, {z.x(), z.y() * omega, memory}, 1, sim);
  if (!r.memory_repeats()) {
    r.memory = r.map.end.contact;
    r.map = stroboscopic_map(model, {z.x(), z.y() * omega, r.memory}, 1, sim);
  }
  const Eigen::Matrix3d& s = r.map.sensitivity;
  r.value << r.map.end.position - z.x(), r.map.end.velocity / omega - z.y();
  r.jacobian << s(0, 0) - 1.0, omega * s(0, 1), s(0, 2),  //
      s(1, 0) / omega, s(1, 1) - 1.0, s(1, 2) / omega;
  return r;
}

Eigen::Vector3d tangent(const Eigen::Matrix<double, 2, 3>& j) {
  // null vector of a 2×3 matrix: cross product of its rows
  const Eigen::Vector3d t = Eigen::Vector3d(j.row(0)).cross(Eigen::Vector3d(j.row(1)));
  return t / t.norm();
}

SweepPoint make_point(const Eigen::Vector3d& z, const Residual& r, double omega, double arclength, int iterations) {
  SweepPoint p;
  p.separation = z.z();
  p.direction = SweepDirection::continuation;
  p.arclength = arclength;
  PeriodicOrbit& o = p.orbit;
  o.separation = z.z();
  o.period_multiple = 1;
  o.initial = {z.x(), z.y() * omega, r.memory};
  o.monodromy = r.map.sensitivity.topLeftCorner<2, 2>();
  o.separation_sensitivity = r.map.sensitivity.topRightCorner<2, 1>();
  o.residual = r.value.cwiseAbs().maxCoeff() / std::max(1.0, z.head<2>().cwiseAbs().maxCoeff());
  o.iterations = iterations;
  o.stats = r.map.stats;
  set_floquet(o);
  return p;
}

/// Separation at the extremum of l(s) between two points (cubic Hermite interpolation in arclength).
double fold_separation(double s0, double l0, double dl0, double s1, double l1, double dl1) {
  const double h = s1 - s0;
  double best = dl0 > 0 ? std::max(l0, l1) : std::min(l0, l1);
  for (int k = 1; k < 200; ++k) {
    const double u = k / 200.0;
    const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u;
    const double h01 = -2 * u * u * u + 3 * u * u, h11 = u * u * u - u * u;
    const double l = h00 * l0 + h10 * h * dl0 + h01 * l1 + h11 * h * dl1;
    best = dl0 > 0 ? std::max(best, l) : std::min(best, l);
  }
  return best;
}

}  // namespace

namespace {

enum class Stop { none, left_range, max_points, time_budget, small_step };

struct Tracer {
  const TappingModel& base;
  const ContinuationOptions& options;
  double l_min, l_max;
  SimulationOptions sim;
  std::chrono::steady_clock::time_point t_start;
  ContinuationResult& out;
  double s = 0.0;  // arclength so far

  /// Pseudo-arclength from the converged point z (residual r) along the unit tangent t.
  Stop trace(Eigen::Vector3d z, Residual r, Eigen::Vector3d t) {
    const double omega = base.drive.frequency;
    double ds = options.initial_step;
    out.points.push_back(make_point(z, r, omega, s, 0));
    for (;;) {
      options.cancellation.check();
      if (static_cast<int>(out.points.size()) >= options.max_points) return Stop::max_points;
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count() >
          options.time_budget_seconds)
        return Stop::time_budget;
      // predictor, then Newton on [G(z); t·(z − z_pred)] = 0
      const Eigen::Vector3d z_pred = z + ds * t;
      Eigen::Vector3d zc = z_pred;
      Residual rc;
      bool converged = false;
      int it = 0;
      for (; it < options.max_corrector_iterations; ++it) {
        rc = residual(base, zc, sim, it == 0 ? r.memory : rc.memory);
        const double scale = std::max(1.0, zc.head<2>().cwiseAbs().maxCoeff());
        if (it > 0 && rc.value.cwiseAbs().maxCoeff() <= options.tolerance * scale && rc.memory_repeats()) {
          converged = true;
          break;
        }
        Eigen::Matrix3d a;
        a.topRows<2>() = rc.jacobian;
        a.row(2) = t.transpose();
        Eigen::Vector3d f;
        f << rc.value, t.dot(zc - z_pred);
        const Eigen::Vector3d step = a.fullPivLu().solve(-f);
        if (!step.allFinite()) break;
        zc += step;
        if ((zc - z_pred).norm() > 0.5 * ds) break;  // the corrector wanders off: another branch, shorten
      }
      Eigen::Vector3d t_new;
      if (converged) {
        t_new = tangent(rc.jacobian);
        if (t_new.dot(t) < 0) t_new = -t_new;
        converged = t_new.dot(t) > 0.8;  // the tangent turned too much for this step length
      }
      if (!converged) {
        ds *= 0.5;
        if (ds < options.min_step) return Stop::small_step;
        continue;
      }
      const double s_new = s + (zc - z).norm();
      const bool fold = (t_new.z() > 0) != (t.z() > 0);
      ContinuationFold f;
      if (fold) {
        f.separation = fold_separation(s, z.z(), t.z(), s_new, zc.z(), t_new.z());
        f.separation_maximum = t.z() > 0;
        // the point nearer the fold: the one before (index size − 1) or the one about to be added (index size)
        f.point = out.points.size() - (std::abs(zc.z() - f.separation) <= std::abs(z.z() - f.separation) ? 0 : 1);
      }
      z = zc;
      r = rc;  // (its memory of contact starts the next corrector)
      t = t_new;
      s = s_new;
      const bool left = z.z() < l_min || z.z() > l_max;
      if (fold) {
        if (left) f.point = out.points.size() - 1;  // the point beyond is not kept
        out.folds.push_back(f);
      }
      if (left) return Stop::left_range;
      out.points.push_back(make_point(z, rc, omega, s, it));
      ds = it <= 3 ? std::min(options.max_step, 1.5 * ds) : (it >= 6 ? 0.7 * ds : ds);
    }
  }
};

/// Minimum of x + l over one period of the orbit through z (< 0: the orbit is in contact).
double orbit_min_gap(const TappingModel& base, const SweepPoint& p, const SimulationOptions& sim) {
  return analyse_orbit(base.with_separation(p.separation), p.orbit, sim).min_gap;
}

}  // namespace

namespace {

/// continue_orbits on checked input.
ContinuationResult continue_checked(const TappingModel& base, const PeriodicOrbit& start, double l_min, double l_max,
                                    bool increasing, const ContinuationOptions& options) {
  const double omega = base.drive.frequency;
  SimulationOptions sim = options.shooting.simulation;
  sim.sensitivity = true;
  ContinuationResult out;
  Tracer tracer{base, options, l_min, l_max, sim, std::chrono::steady_clock::now(), out};

  Eigen::Vector3d z(start.initial.position, start.initial.velocity / omega, start.separation);
  Residual r = residual(base, z, sim, start.initial.contact);
  Eigen::Vector3d t = tangent(r.jacobian);
  if ((t.z() > 0) != increasing) t = -t;
  Stop stop = tracer.trace(z, r, t);

  // A contact branch that runs into grazing (contact vanishing, multipliers growing without bound) ends in a
  // corner on the free branch: hop to the grazing free orbit and follow the free branch to larger l.
  if (stop == Stop::small_step && !out.points.empty()) {
    const SweepPoint& last = out.points.back();
    const double contact_edge = base.law.switching_gaps().empty() ? 0.0 : base.law.switching_gaps().front();
    // just above grazing, so the free orbit clears the contact edge despite rounding
    const double l_graze = (contact_edge + base.free_amplitude()) * (1.0 + 1e-12) + 1e-12;
    const double min_gap = orbit_min_gap(base, last, options.shooting.simulation) - contact_edge;
    if (min_gap < 0 && min_gap > -1e-3 * base.free_amplitude() && l_graze >= l_min && l_graze < l_max) {
      const TappingModel at = base.with_separation(l_graze);
      const TipState free = free_response_state(at);
      z = Eigen::Vector3d(free.position, free.velocity / omega, l_graze);
      r = residual(base, z, sim, false);
      if (r.value.cwiseAbs().maxCoeff() <= 1e3 * options.tolerance * std::max(1.0, z.head<2>().cwiseAbs().maxCoeff())) {
        tracer.s += (z - Eigen::Vector3d(last.orbit.initial.position, last.orbit.initial.velocity / omega,
                                         last.separation))
                        .norm();
        out.grazing.push_back(l_graze);
        stop = tracer.trace(z, r, Eigen::Vector3d(0.0, 0.0, 1.0));
      }
    }
  }
  switch (stop) {
    case Stop::left_range: out.stop_reason = "left range"; break;
    case Stop::max_points: out.stop_reason = "max points"; break;
    case Stop::time_budget: out.stop_reason = "time budget"; break;
    case Stop::small_step:
      out.stop_reason = fmt::format("step below min_step ({:.3g}) at separation {:.9g}: the branch ends or turns "
                                    "non-smoothly",
                                    options.min_step, out.points.empty() ? z.z() : out.points.back().separation);
      break;
    case Stop::none: break;
  }
  if (options.analyse_points)
    detail::finish_points(base, out.points, options.shooting.simulation, options.harmonic_balance, options.parallel,
                          options.cancellation);
  return out;
}

}  // namespace

ContinuationResult continue_orbits(const TappingModel& base, const PeriodicOrbit& start, double l_min, double l_max,
                                   bool increasing, const ContinuationOptions& options) {
  options.validate();
  validate::finite("separation_min", l_min);
  validate::finite("separation_max", l_max);
  validate::require(l_min < l_max, "separation_min", l_min, fmt::format("< separation_max = {}", l_max));
  validate::require(start.period_multiple == 1, "period_multiple", start.period_multiple,
                    "1 (continuation follows period-1 orbits)");
  // the input is checked: a separation or model refused from here on was computed (core/computed.hpp), e.g. a
  // predictor step to a NaN separation, never the user's error
  return computed("branch continuation",
                  [&] { return continue_checked(base, start, l_min, l_max, increasing, options); });
}

ContinuationResult sweep_continuation(const TappingModel& base, double l_min, double l_max,
                                      const ContinuationOptions& options) {
  validate::finite("separation_min", l_min);
  validate::finite("separation_max", l_max);
  validate::require(l_min < l_max, "separation_min", l_min, fmt::format("< separation_max = {}", l_max));
  options.validate();
  OrbitSearchOptions search;
  search.shooting = options.shooting;
  search.cancellation = options.cancellation;
  const OrbitSearchResult found = find_orbits(base.with_separation(l_min), search);
  const FoundOrbit* best = nullptr;
  for (const FoundOrbit& f : found.orbits)
    if (f.orbit.stable && f.orbit.period_multiple == 1 && (!best || f.metrics.amplitude > best->metrics.amplitude))
      best = &f;
  if (!best)
    throw NumericalFailure(fmt::format("continuation: no stable period-1 orbit found at separation_min = {} to start "
                                       "from",
                                       l_min));
  return continue_orbits(base, best->orbit, l_min, l_max, true, options);
}

}  // namespace afmkit::tapping
