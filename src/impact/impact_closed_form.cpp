// Closed-form impact for piecewise-linear hysteresis laws (seed-1 eqs. 10, 11, 26) and constant external
// forces. The relative motion obeys, piece by piece,
//   d̈ = a − ω² d,   contact (d < 0): ω² = K/μ, a = g − F/μ;   free (d ≥ 0): ω² = 0, a = g,
// with (K, F) = (K_a, F_a) while approaching and (K_b, F_b) while departing, g = F2/m2 − F1/m1 and
// μ the reduced mass. Each piece is a harmonic (or parabolic) arc; the events — crossing of the contact
// edge d = 0, the turning point ḋ = 0, the return to d(t_s) — have exact closed-form times.
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/numbers.hpp"
#include "impact_detail.hpp"

namespace afmkit::impact::detail {

namespace {

using afmkit::numbers::nan;

/// One analytic arc d(τ) on [t0, t1] of d̈ = accel − w2·d.
struct Arc {
  double t0, t1;
  double d0, v0;     // gap and gap rate at t0
  double accel;      // a
  double w2;         // ω²
  bool contact;      // d < 0 region (the law acts) or free flight
  bool departure;    // branch H_b (else H_a)
  double adhesion;   // F of the branch (contact arcs)
  double stiffness;  // K of the branch (contact arcs)

  void state(double t, double& d, double& v) const {
    const double tau = t - t0;
    if (w2 > 0) {
      const double w = std::sqrt(w2), c = accel / w2;
      const double cs = std::cos(w * tau), sn = std::sin(w * tau);
      d = c + (d0 - c) * cs + v0 / w * sn;
      v = -(d0 - c) * w * sn + v0 * cs;
    } else {
      d = d0 + v0 * tau + 0.5 * accel * tau * tau;
      v = v0 + accel * tau;
    }
  }
  /// Interaction force H on this arc (linear in d, so its extremes over the arc are at the ends).
  double force(double d) const { return contact ? -(adhesion + stiffness * d) : 0.0; }
};

/// Counter-clockwise angle in [0, π] swept from u to w in the phase plane (d − c, −ḋ/ω): the phase
/// ψ = ωt + θ grows with time and one monotone stretch of motion lasts at most half a period.
double swept_angle(double ux, double uy, double wx, double wy) {
  double angle = std::atan2(ux * wy - uy * wx, ux * wx + uy * wy);
  if (angle < -0.5 * std::numbers::pi) angle += 2.0 * std::numbers::pi;  // −π (rounding of +π)
  else if (angle < 0) angle = 0.0;                                          // rounding below 0
  return angle;
}

}  // namespace

ImpactResult closed_form_impact(const ImpactProblem& problem, const ImpactOptions& options) {
  const PiecewiseLinearLaw& law = *problem.law().piecewise_linear();
  const double m1 = problem.body1().mass, m2 = problem.body2().mass, total = m1 + m2;
  const double mu = problem.reduced_mass();
  const double f1 = problem.external().on_body1, f2 = problem.external().on_body2;
  const double g = f2 / m2 - f1 / m1;  // relative acceleration due to the external forces
  const double d_ref = problem.initial_gap();

  ImpactResult r;
  r.method = "closed_form";
  std::vector<Arc> arcs;
  double t = 0.0, d = d_ref, v = problem.initial_gap_rate();
  bool departure = false, finished = false;
  bool ended_at_turn = false;  // the approach arc ends at t̄ (history: two rows there)

  auto make_arc = [&](bool contact) {
    Arc a{t, t, d, v, g, 0.0, contact, departure, 0.0, 0.0};
    if (contact) {
      a.stiffness = departure ? law.departure_stiffness : law.approach_stiffness;
      a.adhesion = departure ? law.departure_adhesion : law.approach_adhesion;
      a.w2 = a.stiffness / mu;
      a.accel = g - a.adhesion / mu;
    }
    return a;
  };

  for (int guard = 0; guard < 16 && !finished; ++guard) {
    // Region of the next arc: at the edge d = 0 the direction of motion decides.
    const bool contact = d < 0 || (d == 0 && !departure);
    Arc arc = make_arc(contact);
    const double w = std::sqrt(arc.w2), c = arc.w2 > 0 ? arc.accel / arc.w2 : 0.0;

    // Nearest event gap ahead in the direction of motion: the contact edge 0 and (departing) d(t_s).
    double target = nan;
    bool target_is_end = false;
    if (!departure) {
      if (!contact) target = 0.0;
    } else {
      if (contact) target = 0.0;
      if (d_ref > d && !(target < d_ref)) {
        target = d_ref;
        target_is_end = true;
      }
    }
    // Work–energy along the arc: ḋ² = v² + (d_t − d)(2a − ω²(d_t + d)); reachable iff positive.
    const double v_sq = std::isnan(target) ? -1.0 : v * v + (target - d) * (2.0 * arc.accel - arc.w2 * (target + d));
    if (v_sq > 0) {
      const double v_t = departure ? std::sqrt(v_sq) : -std::sqrt(v_sq);
      const double dt = arc.w2 > 0 ? swept_angle(d - c, -v / w, target - c, -v_t / w) / w
                                   : 2.0 * (target - d) / (v + v_t);
      t += dt;
      d = target;
      v = v_t;
      arc.t1 = t;
      arcs.push_back(arc);
      if (target_is_end) finished = true;
      continue;
    }
    // No event gap reached: the arc ends at the turning point ḋ = 0.
    double dt = 0, d_turn = 0;
    if (arc.w2 > 0) {
      const double radius = std::hypot(d - c, v / w);
      d_turn = departure ? c + radius : c - radius;
      dt = swept_angle(d - c, -v / w, d_turn - c, 0.0) / w;
    } else if ((!departure && arc.accel > 0) || (departure && arc.accel < 0)) {
      dt = -v / arc.accel;
      d_turn = d - v * v / (2.0 * arc.accel);
    } else {
      throw NumericalFailure(fmt::format(
          "the approach never stops: at gap {} the approach branch (K_a = {}, F_a = {}) does not repel the bodies "
          "against the external forces; no minimum gap exists",
          d, arc.stiffness, arc.adhesion));
    }
    t += dt;
    d = d_turn;
    v = 0.0;
    arc.t1 = t;
    arcs.push_back(arc);
    if (!departure) {
      r.minimum_time = t;
      r.minimum_gap = d;
      ended_at_turn = true;
      departure = true;
      // Filippov check at ḋ = 0: if the departure branch does not push the bodies apart, they stick.
      const Arc next = make_arc(d < 0);
      const double departure_accel = next.accel - next.w2 * d;
      if (departure_accel <= 0) {
        r.outcome = ImpactOutcome::captured;
        r.capture_reason = fmt::format(
            "stuck at the minimum gap {}: the departure branch does not pull the bodies apart (relative "
            "acceleration {} <= 0)",
            d, departure_accel);
        finished = true;
      }
    } else {
      r.outcome = ImpactOutcome::captured;
      r.capture_reason =
          fmt::format("the bodies turn back at gap {} < d(t_s) = {} without separating", d, d_ref);
      finished = true;
    }
  }
  if (!finished) throw NumericalFailure("closed-form impact: too many arcs (internal error)");
  for (const Arc& a : arcs)
    if (!std::isfinite(a.w2) || !std::isfinite(a.accel))
      throw InvalidParameter("approach_stiffness",
                             fmt::format("stiffness / reduced mass = {} and (adhesion, external force) / mass = {} "
                                         "must be finite (reduced mass {}): rescale the units",
                                         a.w2, a.accel, mu));

  // Departure speed from the energy balance (exact for this flow): each arc conserves ½ μ ḋ² + U(d) − μ g d
  // (U' = −H), and the switch H_a -> H_b at t̄ removes the area between the branches, so
  // ½ μ ḋ(t_f)² = ½ μ ḋ(t_s)² − ∫_{d(t̄)}^{d(t_s)} (H_a − H_b) dξ (seed-1 eqs. 3, 6). Writing ḋ(t_f) this way,
  // with the area in closed form, keeps 1 − e and the loss relatively accurate as e → 1 (the arc-by-arc value
  // carries an absolute rounding error ~ε|ḋ(t_s)|, i.e. a relative error ε/(1 − e) of the loss).
  double relative_loss = nan;
  if (r.outcome == ImpactOutcome::separated) {
    const double v_s = problem.initial_gap_rate();
    relative_loss = hysteresis_energy_loss(problem.law(), r.minimum_gap, d_ref);
    r.energy_balance_residual = 0.5 * mu * (v_s - v) * (v_s + v) - relative_loss;  // arcs vs eq. (6)
    const double x = relative_loss / (0.5 * mu * v_s * v_s);  // 1 − e²
    if (x < 1) v = -v_s * std::sqrt(1.0 - x);
  } else {
    r.energy_balance_residual = nan;
  }

  // Centre-of-mass motion (exact for constant forces) and body states.
  const double com_x0 = (m1 * problem.body1().position + m2 * problem.body2().position) / total;
  const double com_v0 = (m1 * problem.body1().velocity + m2 * problem.body2().velocity) / total;
  const double com_a = (f1 + f2) / total;
  auto bodies = [&](double time, double gap, double rate, Body& b1, Body& b2) {
    const double x = com_x0 + com_v0 * time + 0.5 * com_a * time * time, vc = com_v0 + com_a * time;
    b1 = {m1, x - m2 / total * gap, vc - m2 / total * rate};
    b2 = {m2, x + m1 / total * gap, vc + m1 / total * rate};
  };

  r.end_time = t;
  r.steps = static_cast<long>(arcs.size());
  bodies(t, d, v, r.body1_after, r.body2_after);
  r.peak_force = -std::numeric_limits<double>::infinity();
  r.min_force = std::numeric_limits<double>::infinity();
  std::vector<double> events;
  for (const Arc& a : arcs) {
    events.push_back(a.t0);
    double d_end = 0, v_end = 0;
    a.state(a.t1, d_end, v_end);
    for (double f : {a.force(a.d0), a.force(a.contact && a.t1 > a.t0 ? d_end : a.d0)}) {
      r.peak_force = std::max(r.peak_force, f);
      r.min_force = std::min(r.min_force, f);
    }
    if (a.contact && !r.contact) {
      r.contact = true;
      r.contact_start = a.t0;
    }
  }
  events.push_back(t);
  // contact end: the start of the first free arc after a contact arc (or t_f if d(t_s) < 0)
  r.contact_end = nan;
  for (std::size_t i = 1; i < arcs.size(); ++i)
    if (arcs[i - 1].contact && !arcs[i].contact) r.contact_end = arcs[i].t0;
  if (r.contact && std::isnan(r.contact_end) && r.outcome == ImpactOutcome::separated) r.contact_end = t;
  if (r.contact && r.outcome == ImpactOutcome::captured) r.contact_end = nan;

  // History: uniform grid plus the arc boundaries; at t̄ one row per branch. Streamed to the sink one sample
  // at a time.
  SampleClock clock(t, options.history_points, events);
  const HistorySink emit(options, r.history);
  for (std::size_t i = 0; i < arcs.size(); ++i) {
    const Arc& a = arcs[i];
    const bool last = i + 1 == arcs.size();
    const bool turn = ended_at_turn && a.t1 == r.minimum_time && !a.departure;
    for (; !clock.done() && (clock.peek() < a.t1 || (last && clock.peek() <= a.t1)); clock.pop()) {
      if (clock.peek() < a.t0) continue;
      ImpactSample s{};
      s.time = clock.peek();
      a.state(s.time, s.gap, s.gap_rate);
      s.force = a.departure ? problem.law().departure(s.gap) : problem.law().approach(s.gap);
      Body b1{}, b2{};
      bodies(s.time, s.gap, s.gap_rate, b1, b2);
      s.position1 = b1.position, s.velocity1 = b1.velocity, s.position2 = b2.position, s.velocity2 = b2.velocity;
      emit(s);
    }
    if (turn && options.history_points > 0) {
      // t̄: one row on the approach branch, one on the departure branch (the next arc's first row, or
      // added here when the impact ends at t̄ by sticking)
      ImpactSample s{};
      s.time = a.t1;
      s.gap = r.minimum_gap;
      s.gap_rate = 0.0;
      Body b1{}, b2{};
      bodies(s.time, s.gap, 0.0, b1, b2);
      s.position1 = b1.position, s.velocity1 = b1.velocity, s.position2 = b2.position, s.velocity2 = b2.velocity;
      s.force = last ? problem.law().departure(s.gap) : problem.law().approach(s.gap);
      emit(s);
    }
  }
  complete_result(problem, r, relative_loss);
  return r;
}

}  // namespace afmkit::impact::detail
