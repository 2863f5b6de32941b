#include "afmkit/tapping/continuation.hpp"

#include <chrono>
#include <cmath>
#include <optional>
#include <utility>

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

/// Shooting residual and its Jacobian in scaled unknowns z = (x(0), ẋ(0)/ω, s·p) (p: the continued parameter,
/// s = Path::scale; for the separation s = 1 and z = (x(0), ẋ(0)/ω, l)).
struct Residual {
  Eigen::Vector2d value;
  Eigen::Matrix<double, 2, 3> jacobian;
  StroboscopicMap map;
  double separation = 0.0;  // of the model at this value of the parameter
  bool memory = false;  // the memory of contact the map started with (contact-aware laws; docs/force-laws.md)
  bool memory_repeats() const { return map.end.contact == memory; }
};

/// `memory`: the start memory of a contact-aware law; when the period ends with the other, the map is evaluated
/// again from that one (as try_shoot does: a periodic orbit starts with the memory it ends with).
/// ∂P/∂p: the exact column of the variational equations for the separation; central differences of the map
/// (step Path::difference_step; one-sided where the model refuses a value beyond p) for any other parameter.
Residual residual(const detail::ParameterPath& path, const Eigen::Vector3d& z, const SimulationOptions& sim,
                  bool memory) {
  const TappingModel& base = path.base;
  const double omega = base.drive.frequency;
  // a predictor along a tangent of a singular Jacobian (a tip held in contact: no motion to follow) gives NaN
  // unknowns; that is the continuation's failure, not a value the user gave (issue 24 §2)
  if (!z.allFinite())
    throw NumericalFailure(fmt::format("branch continuation: the unknowns (x, v/omega, {}) = ({}, {}, {}) are not "
                                       "finite (the shooting Jacobian is singular: no branch to follow)",
                                       path.parameter.is_separation() ? "l" : path.parameter.name(), z.x(), z.y(),
                                       z.z() / path.scale));
  const double value = z.z() / path.scale;
  const TappingModel model = path.at(value);
  Residual r;
  r.separation = model.separation;
  r.memory = memory;
  r.map = stroboscopic_map(model, {z.x(), z.y() * omega, memory}, 1, sim);
  if (!r.memory_repeats()) {
    r.memory = r.map.end.contact;
    r.map = stroboscopic_map(model, {z.x(), z.y() * omega, r.memory}, 1, sim);
  }
  const Eigen::Matrix3d& s = r.map.sensitivity;
  Eigen::Vector2d dp(s(0, 2), s(1, 2));  // ∂(x, ẋ)(T)/∂p
  if (!path.parameter.is_separation()) dp = path.map_derivative(value, {z.x(), z.y() * omega, r.memory}, r.map.end, sim);
  r.value << r.map.end.position - z.x(), r.map.end.velocity / omega - z.y();
  r.jacobian << s(0, 0) - 1.0, omega * s(0, 1), dp.x() / path.scale,  //
      s(1, 0) / omega, s(1, 1) - 1.0, dp.y() / omega / path.scale;
  return r;
}

Eigen::Vector3d tangent(const Eigen::Matrix<double, 2, 3>& j) {
  // null vector of a 2×3 matrix: cross product of its rows
  const Eigen::Vector3d t = Eigen::Vector3d(j.row(0)).cross(Eigen::Vector3d(j.row(1)));
  return t / t.norm();
}

SweepPoint make_point(const detail::ParameterPath& path, const Eigen::Vector3d& z, const Residual& r, double omega,
                      double arclength, int iterations) {
  SweepPoint p;
  p.parameter = z.z() / path.scale;
  p.separation = r.separation;  // = z.z() when continuing in l
  p.direction = SweepDirection::continuation;
  p.arclength = arclength;
  PeriodicOrbit& o = p.orbit;
  o.separation = p.separation;
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

/// Scaled parameter at the extremum of s·p along the arclength between two points (cubic Hermite interpolation in arclength).
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
  const detail::ParameterPath& path;
  const ContinuationOptions& options;
  double l_min, l_max;  // range of the parameter
  SimulationOptions sim;
  std::chrono::steady_clock::time_point t_start;
  ContinuationResult& out;
  double s = 0.0;  // arclength so far

  /// Pseudo-arclength from the converged point z (residual r) along the unit tangent t.
  Stop trace(Eigen::Vector3d z, Residual r, Eigen::Vector3d t) {
    const double omega = path.base.drive.frequency;
    double ds = options.initial_step;
    out.points.push_back(make_point(path, z, r, omega, s, 0));
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
        try {
          rc = residual(path, zc, sim, it == 0 ? r.memory : rc.memory);
        } catch (const InvalidParameter&) {
          // the model does not exist at this value of the parameter (e.g. an adhesion beyond the other branch's):
          // beyond the range the branch has left it; inside, the failure propagates (a computed value refused)
          const double at = zc.z() / path.scale;
          if (zc.allFinite() && (at < l_min || at > l_max)) return Stop::left_range;
          throw;
        }
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
        const double at = fold_separation(s, z.z(), t.z(), s_new, zc.z(), t_new.z());  // scaled
        f.parameter = at / path.scale;
        f.separation = path.parameter.is_separation() ? f.parameter : rc.separation;
        f.separation_maximum = t.z() > 0;
        // the point nearer the fold: the one before (index size − 1) or the one about to be added (index size)
        f.point = out.points.size() - (std::abs(zc.z() - at) <= std::abs(z.z() - at) ? 0 : 1);
      }
      z = zc;
      r = rc;  // (its memory of contact starts the next corrector)
      t = t_new;
      s = s_new;
      const bool left = z.z() / path.scale < l_min || z.z() / path.scale > l_max;
      if (fold) {
        if (left) f.point = out.points.size() - 1;  // the point beyond is not kept
        out.folds.push_back(f);
      }
      if (left) return Stop::left_range;
      out.points.push_back(make_point(path, z, rc, omega, s, it));
      ds = it <= 3 ? std::min(options.max_step, 1.5 * ds) : (it >= 6 ? 0.7 * ds : ds);
    }
  }
};

/// Minimum of x + l over one period of the orbit through z (< 0: the orbit is in contact).
double orbit_min_gap(const detail::ParameterPath& path, const SweepPoint& p, const SimulationOptions& sim) {
  return analyse_orbit(path.at(p.parameter), p.orbit, sim).min_gap;
}

}  // namespace

namespace {

/// Just beyond the parameter value where the free amplitude reaches the contact edge (found by secant iterations
/// from `from`), on the free side by two difference steps; and the direction of the free side (+1: increasing p).
/// nullopt when it does not converge.
std::optional<std::pair<double, double>> grazing_value(const detail::ParameterPath& path, double from,
                                                       double contact_edge) {
  const auto g = [&](double p) {  // < 0: free
    const TappingModel model = path.at(p);
    return model.free_amplitude() + contact_edge - model.separation;
  };
  const double margin = 1e-12 * (std::abs(path.base.separation) + 1.0);
  double h = 1e-6 * std::max(std::abs(from), path.width);
  double p0 = from, p1 = from + h;
  try {
    double g0 = g(p0) + margin, g1 = g(p1) + margin;
    for (int k = 0; k < 60 && g1 != g0; ++k) {
      const double p2 = p1 - g1 * (p1 - p0) / (g1 - g0);
      p0 = p1;
      g0 = g1;
      p1 = p2;
      g1 = g(p1) + margin;
      if (std::abs(g1) <= 0.1 * margin) {  // g within [−1.1, −0.9]·margin: free, just
        const double slope = (g(p1 + h) - g(p1 - h)) / (2 * h);
        if (!(slope != 0.0) || !std::isfinite(slope)) return std::nullopt;
        // the hop lands two difference steps inside the free side, so that the central difference of the map
        // (ParameterPath::map_derivative) does not straddle the grazing corner
        const double direction = slope > 0 ? -1.0 : 1.0;
        return std::make_pair(p1 + direction * 2.0 * path.difference_step(p1), direction);
      }
    }
  } catch (const InvalidParameter&) {
    // the secant left the parameter's range: no grazing there
  }
  return std::nullopt;
}

/// continue_orbits on checked input.
ContinuationResult continue_checked(const TappingModel& base, const SweepParameter& parameter,
                                    const PeriodicOrbit& start, double p_start, double l_min, double l_max,
                                    bool increasing, const ContinuationOptions& options) {
  const detail::ParameterPath path = detail::make_path(base, parameter, l_min, l_max);
  const double omega = base.drive.frequency;
  SimulationOptions sim = options.shooting.simulation;
  sim.sensitivity = true;
  ContinuationResult out;
  Tracer tracer{path, options, l_min, l_max, sim, std::chrono::steady_clock::now(), out};

  Eigen::Vector3d z(start.initial.position, start.initial.velocity / omega, p_start * path.scale);
  Residual r = residual(path, z, sim, start.initial.contact);
  Eigen::Vector3d t = tangent(r.jacobian);
  if ((t.z() > 0) != increasing) t = -t;
  Stop stop = tracer.trace(z, r, t);

  // A contact branch that runs into grazing (contact vanishing, multipliers growing without bound) ends in a
  // corner on the free branch: hop to the grazing free orbit and follow the free branch (to larger l in a
  // separation continuation; for another parameter, to where the free amplitude clears the sample).
  if (stop == Stop::small_step && !out.points.empty()) {
    const SweepPoint& last = out.points.back();
    const TappingModel at_last = path.at(last.parameter);
    const double contact_edge = base.law.switching_gaps().empty() ? 0.0 : base.law.switching_gaps().front();
    std::optional<std::pair<double, double>> graze;  // (value, direction of the free side)
    if (parameter.is_separation()) {
      // just above grazing, so the free orbit clears the contact edge despite rounding
      graze.emplace((contact_edge + base.free_amplitude()) * (1.0 + 1e-12) + 1e-12, 1.0);
    } else {
      graze = grazing_value(path, last.parameter, contact_edge);
    }
    const double min_gap = orbit_min_gap(path, last, options.shooting.simulation) - contact_edge;
    if (graze && min_gap < 0 && min_gap > -1e-3 * at_last.free_amplitude() && graze->first >= l_min &&
        graze->first < l_max) {
      const double p_graze = graze->first;
      const TappingModel at = path.at(p_graze);
      const TipState free = free_response_state(at);
      z = Eigen::Vector3d(free.position, free.velocity / omega, p_graze * path.scale);
      r = residual(path, z, sim, false);
      if (r.value.cwiseAbs().maxCoeff() <= 1e3 * options.tolerance * std::max(1.0, z.head<2>().cwiseAbs().maxCoeff())) {
        tracer.s += (z - Eigen::Vector3d(last.orbit.initial.position, last.orbit.initial.velocity / omega,
                                         last.parameter * path.scale))
                        .norm();
        out.grazing.push_back(p_graze);
        // the free branch: along l its state does not change (tangent (0, 0, 1)); along another parameter the
        // tangent of the Jacobian, towards the free side
        Eigen::Vector3d t_free(0.0, 0.0, graze->second);
        if (!parameter.is_separation()) {
          t_free = tangent(r.jacobian);
          if ((t_free.z() > 0) != (graze->second > 0)) t_free = -t_free;
        }
        stop = tracer.trace(z, r, t_free);
      }
    }
  }
  switch (stop) {
    case Stop::left_range: out.stop_reason = "left range"; break;
    case Stop::max_points: out.stop_reason = "max points"; break;
    case Stop::time_budget: out.stop_reason = "time budget"; break;
    case Stop::small_step:
      out.stop_reason = fmt::format("step below min_step ({:.3g}) at {} {:.9g}: the branch ends or turns "
                                    "non-smoothly",
                                    options.min_step, parameter.name(),
                                    out.points.empty() ? z.z() / path.scale : out.points.back().parameter);
      break;
    case Stop::none: break;
  }
  if (options.analyse_points) {
    if (parameter.is_separation())
      detail::finish_points(base, out.points, options.shooting.simulation, options.harmonic_balance, options.parallel,
                            options.cancellation);
    else
      detail::finish_points(path, out.points, options.shooting.simulation, options.harmonic_balance, options.parallel,
                            options.cancellation);
  }
  return out;
}

/// The range [p_min, p_max] of the parameter, checked (keys named after the parameter: separation_min, …).
void check_parameter_range(const SweepParameter& parameter, double p_min, double p_max) {
  const std::string lo = parameter.name() + "_min", hi = parameter.name() + "_max";
  validate::finite(lo, p_min);
  validate::finite(hi, p_max);
  validate::require(p_min < p_max, lo, p_min, fmt::format("< {} = {}", hi, p_max));
}

}  // namespace

ContinuationResult continue_orbits(const TappingModel& base, const PeriodicOrbit& start, double l_min, double l_max,
                                   bool increasing, const ContinuationOptions& options) {
  return continue_orbits(base, SweepParameter::separation(), start, start.separation, l_min, l_max, increasing,
                         options);
}

ContinuationResult continue_orbits(const TappingModel& base, const SweepParameter& parameter,
                                   const PeriodicOrbit& start, double start_value, double p_min, double p_max,
                                   bool increasing, const ContinuationOptions& options) {
  options.validate();
  check_parameter_range(parameter, p_min, p_max);
  validate::finite(parameter.name(), start_value);
  validate::require(start.period_multiple == 1, "period_multiple", start.period_multiple,
                    "1 (continuation follows period-1 orbits)");
  // the input is checked: a value or model refused from here on was computed (core/computed.hpp), e.g. a
  // predictor step to a NaN separation, never the user's error
  return computed("branch continuation", [&] {
    return continue_checked(base, parameter, start, start_value, p_min, p_max, increasing, options);
  });
}

ContinuationResult sweep_continuation(const TappingModel& base, double l_min, double l_max,
                                      const ContinuationOptions& options) {
  return sweep_continuation(base, SweepParameter::separation(), l_min, l_max, options);
}

ContinuationResult sweep_continuation(const TappingModel& base, const SweepParameter& parameter, double p_min,
                                      double p_max, const ContinuationOptions& options) {
  check_parameter_range(parameter, p_min, p_max);
  options.validate();
  OrbitSearchOptions search;
  search.shooting = options.shooting;
  search.cancellation = options.cancellation;
  const OrbitSearchResult found = find_orbits(parameter.at(base, p_min), search);
  const FoundOrbit* best = nullptr;
  for (const FoundOrbit& f : found.orbits)
    if (f.orbit.stable && f.orbit.period_multiple == 1 && (!best || f.metrics.amplitude > best->metrics.amplitude))
      best = &f;
  if (!best)
    throw NumericalFailure(fmt::format("continuation: no stable period-1 orbit found at {}_min = {} to start from",
                                       parameter.name(), p_min));
  return continue_orbits(base, parameter, best->orbit, p_min, p_min, p_max, true, options);
}

}  // namespace afmkit::tapping
