// Numerical impact: eq. (1) for both bodies, integrated with Dormand–Prince 5(4) (Boost.Odeint, dense
// output) and event location on the dense-output interpolant (TOMS 748). Within one phase (approach or
// departure) the branch is fixed, so the right-hand side is smooth except at the law's switching gaps,
// which are events too (the stepper restarts there). Events: switching-gap crossings, the turning point
// ḋ = 0 (approach -> departure, or a capture if departing), and the return of the gap to d(t_s).
//
// Scaling: lengths by L = max(|d(t_s)|, |switching gaps|) (1 if zero), velocities by V = |ḋ(t_s)|, time by
// L/V; positions and velocities are taken relative to the initial centre-of-mass motion (Galilean shift),
// so the gap keeps its relative precision.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include <boost/math/tools/toms748_solve.hpp>
#include <boost/numeric/odeint.hpp>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/numbers.hpp"
#include "impact_detail.hpp"

namespace afmkit::impact::detail {

namespace {

namespace odeint = boost::numeric::odeint;
using State = std::array<double, 4>;  // scaled x1, v1, x2, v2 in the initial centre-of-mass frame
using afmkit::numbers::nan;

enum class Event { none, level, turning, end };

class ImpactIntegrator {
 public:
  ImpactIntegrator(const ImpactProblem& problem, const ImpactOptions& options)
      : problem_(problem), options_(options), law_(problem.law()), ext_(problem.external()) {
    m1_ = problem.body1().mass;
    m2_ = problem.body2().mass;
    const double total = m1_ + m2_;
    com_x0_ = (m1_ * problem.body1().position + m2_ * problem.body2().position) / total;
    com_v0_ = (m1_ * problem.body1().velocity + m2_ * problem.body2().velocity) / total;
    d_ref_ = problem.initial_gap();
    length_ = std::abs(d_ref_);
    for (double g : law_.switching_gaps()) length_ = std::max(length_, std::abs(g));
    if (std::isfinite(law_.contact_gap())) length_ = std::max(length_, std::abs(law_.contact_gap()));
    if (!(length_ > 0)) length_ = 1.0;
    speed_ = -problem.initial_gap_rate();
    time_ = length_ / speed_;
    accel_scale_ = length_ / (speed_ * speed_);
    levels_ = law_.switching_gaps();
    if (const double c = law_.contact_gap(); std::isfinite(c)) levels_.push_back(c);  // contact start/end events
    std::sort(levels_.begin(), levels_.end());
    levels_.erase(std::unique(levels_.begin(), levels_.end()), levels_.end());
    max_time_ = options.max_time > 0 ? options.max_time : 1e9 * time_;
  }

  /// One run. With `grid` (physical sample times) the history rows are passed to `history`.
  ImpactResult run(SampleClock* grid, const HistorySink* history) {
    ImpactResult r;
    r.method = "integrator";
    r.peak_force = -std::numeric_limits<double>::infinity();
    r.min_force = std::numeric_limits<double>::infinity();
    events_.clear();
    departure_ = false;
    touched_ = true;
    const double total = m1_ + m2_;
    State y{(problem_.body1().position - com_x0_) / length_, (problem_.body1().velocity - com_v0_) / speed_,
            (problem_.body2().position - com_x0_) / length_, (problem_.body2().velocity - com_v0_) / speed_};
    const double contact_gap = contact_gap_of(law_);
    r.contact = !std::isnan(contact_gap) && d_ref_ <= contact_gap;  // started at or inside the contact edge
    r.contact_start = 0.0;
    r.contact_end = nan;
    // next switching gap below d(t_s) (approach)
    std::ptrdiff_t next = static_cast<std::ptrdiff_t>(std::lower_bound(levels_.begin(), levels_.end(), d_ref_) -
                                                      levels_.begin()) - 1;
    auto emit_until = [&](double s_limit, const auto& state_at) {
      if (!grid) return;
      for (; !grid->done() && grid->peek() <= s_limit * time_; grid->pop()) {
        State z{};
        state_at(grid->peek() / time_, z);
        (*history)(sample(grid->peek(), z));
      }
    };
    auto track_force = [&](const State& z) {
      const double f = force_at(z);
      r.peak_force = std::max(r.peak_force, f);
      r.min_force = std::min(r.min_force, f);
    };
    track_force(y);
    emit_until(0.0, [&](double, State& z) { z = y; });

    auto stepper = odeint::make_dense_output(options_.absolute_tolerance, options_.relative_tolerance,
                                             odeint::runge_kutta_dopri5<State>());
    auto system = [this](const State& z, State& dz, double s) { rhs(z, dz, s); };
    double s = 0.0, ds = 1e-3;
    stepper.initialize(y, s, ds);
    long steps = 0;
    for (;;) {
      if (++steps > options_.max_steps)
        throw NumericalFailure(fmt::format("impact integration: step budget max_steps = {} exhausted at t = {} "
                                           "(gap {}, gap rate {})",
                                           options_.max_steps, s * time_, gap(y), rate(y)));
      try {
        stepper.do_step(system);
      } catch (const odeint::step_adjustment_error& e) {
        throw NumericalFailure(fmt::format("impact integration: step size control failed at t = {}: {}", s * time_,
                                           e.what()));
      }
      const double s0 = stepper.previous_time(), s1 = stepper.current_time();
      const State& y1 = stepper.current_state();
      if (!std::all_of(y1.begin(), y1.end(), [](double v) { return std::isfinite(v); }))
        throw NumericalFailure(fmt::format("impact integration: non-finite state at t = {}", s1 * time_));

      // Which events fire within [s0, s1]? Locate each on the interpolant and keep the earliest.
      Event event = Event::none;
      double s_event = s1;
      auto consider = [&](Event kind, auto guard) {
        State z{};
        auto g = [&](double tau) {
          stepper.calc_state(tau, z);
          return guard(z);
        };
        const double g0 = guard(stepper.previous_state()), g1 = guard(y1);
        if (g1 < 0) return;  // guard written so that >= 0 means "fired"
        double root = s1;
        if (g0 < 0) {
          std::uintmax_t iterations = 200;
          const auto bracket = boost::math::tools::toms748_solve(g, s0, s1, g0, g1,
                                                                 boost::math::tools::eps_tolerance<double>(50),
                                                                 iterations);
          root = 0.5 * (bracket.first + bracket.second);
        } else {
          root = s0;
        }
        if (event == Event::none || root < s_event) {
          event = kind;
          s_event = root;
        }
      };
      if (!departure_) {
        consider(Event::turning, [&](const State& z) { return rate(z) / speed_; });
        if (next >= 0) {
          const double level = levels_[static_cast<std::size_t>(next)];
          consider(Event::level, [&](const State& z) { return (level - gap(z)) / length_; });
        }
      } else {
        consider(Event::turning, [&](const State& z) { return -rate(z) / speed_; });
        if (next >= 0 && static_cast<std::size_t>(next) < levels_.size() &&
            levels_[static_cast<std::size_t>(next)] < d_ref_) {
          const double level = levels_[static_cast<std::size_t>(next)];
          consider(Event::level, [&](const State& z) { return (gap(z) - level) / length_; });
        }
        consider(Event::end, [&](const State& z) { return (gap(z) - d_ref_) / length_; });
      }

      if (event == Event::none) {
        s = s1;
        y = y1;
        track_force(y);
        emit_until(s1, [&](double tau, State& z) { stepper.calc_state(tau, z); });
        if (s * time_ > max_time_)
          throw NumericalFailure(fmt::format("impact integration: time budget max_time = {} exhausted (gap {}, gap "
                                             "rate {}); the approach may never stop",
                                             max_time_, gap(y), rate(y)));
        continue;
      }
      stepper.calc_state(s_event, y);
      s = s_event;
      if (event == Event::end) {  // land exactly on d(t_s): tiny shift of both bodies along the gap
        const double excess = (gap(y) - d_ref_) / length_;
        y[0] += m2_ / total * excess;
        y[2] -= m1_ / total * excess;
      }
      emit_until(s, [&](double tau, State& z) {
        if (tau >= s) z = y;
        else stepper.calc_state(tau, z);
      });
      track_force(y);
      events_.push_back(s * time_);
      const double t = s * time_;
      if (event == Event::level) {
        const double level = levels_[static_cast<std::size_t>(next)];
        if (level == contact_gap) {
          if (!departure_) {
            r.contact = true;
            r.contact_start = t;
          } else {
            r.contact_end = t;
          }
        }
        next += departure_ ? 1 : -1;
      } else if (event == Event::turning) {
        // ḋ = 0 exactly, momentum kept: both bodies move with the centre-of-mass velocity
        const double com = (m1_ * y[1] + m2_ * y[3]) / total;
        y[1] = y[3] = com;
        if (!departure_) {
          r.minimum_time = t;
          r.minimum_gap = gap(y);
          departure_ = true;
          // a contact-aware law departs on H_b only after an impact: the approach (monotone in d) reached the
          // contact gap iff its minimum did (docs/force-laws.md#hysteresis); else H_a, as above the release gap
          touched_ = !law_.contact_aware() || r.minimum_gap <= law_.contact_gap();
          track_force(y);
          if (grid && history) (*history)(sample(t, y));  // departure-branch row at t̄
          next = static_cast<std::ptrdiff_t>(std::upper_bound(levels_.begin(), levels_.end(), r.minimum_gap) -
                                             levels_.begin());
          State dz{};
          rhs(y, dz, s);
          const double departure_accel = (dz[3] - dz[1]) * speed_ / time_;
          if (departure_accel <= 0) {
            r.outcome = ImpactOutcome::captured;
            r.capture_reason = fmt::format(
                "stuck at the minimum gap {}: the departure branch does not pull the bodies apart (relative "
                "acceleration {} <= 0)",
                r.minimum_gap, departure_accel);
            finish(r, y, t, steps);
            return r;
          }
        } else {
          r.outcome = ImpactOutcome::captured;
          r.capture_reason =
              fmt::format("the bodies turn back at gap {} < d(t_s) = {} without separating", gap(y), d_ref_);
          finish(r, y, t, steps);
          return r;
        }
      } else {  // end
        if (!std::isnan(contact_gap) && r.contact && std::isnan(r.contact_end) && contact_gap >= d_ref_)
          r.contact_end = t;
        r.outcome = ImpactOutcome::separated;
        finish(r, y, t, steps);
        return r;
      }
      stepper.initialize(y, s, std::max(stepper.current_time_step(), 1e-12 * std::max(1.0, s)));
    }
  }

  const std::vector<double>& events() const { return events_; }

 private:
  const ImpactProblem& problem_;
  const ImpactOptions& options_;
  const ForceLaw& law_;
  const ExternalForces& ext_;
  double m1_ = 0, m2_ = 0, com_x0_ = 0, com_v0_ = 0, d_ref_ = 0;
  double length_ = 1, speed_ = 1, time_ = 1, accel_scale_ = 1, max_time_ = 0;
  std::vector<double> levels_;
  std::vector<double> events_;
  bool departure_ = false;
  bool touched_ = true;  // contact-aware laws: the approach reached the contact gap (H_b applies on departure)

  double gap(const State& z) const { return length_ * (z[2] - z[0]); }
  double rate(const State& z) const { return speed_ * (z[3] - z[1]); }
  /// H_b while departing, except for a contact-aware law that did not touch, or above its release gap (there the
  /// law is H_a: docs/force-laws.md#hysteresis)
  double branch(double d) const {
    const bool released = law_.contact_aware() && d >= law_.release_gap();
    return departure_ && touched_ && !released ? law_.departure(d) : law_.approach(d);
  }
  /// H of the current phase with the Kelvin–Voigt term −c(d)ḋ of laws that have one.
  double force_at(const State& z) const {
    const double d = gap(z);
    return law_.has_damping() ? branch(d) - law_.damping(d) * rate(z) : branch(d);
  }

  void rhs(const State& z, State& dz, double s) const {
    const double d = gap(z);
    const double force = force_at(z);
    if (!std::isfinite(force))
      throw NumericalFailure(fmt::format("force law '{}' returned {} at gap {}", law_.name(), force, d));
    const double t = s * time_;
    dz[0] = z[1];
    dz[2] = z[3];
    dz[1] = accel_scale_ * (ext_.force1(t) - force) / m1_;  // m1 ẍ1 = F1 − H  (eq. 1, H1 = −H)
    dz[3] = accel_scale_ * (ext_.force2(t) + force) / m2_;  // m2 ẍ2 = F2 + H
  }

  ImpactSample sample(double t, const State& z) const {
    ImpactSample out{};
    out.time = t;
    out.gap = gap(z);
    out.gap_rate = rate(z);
    out.force = force_at(z);
    out.position1 = com_x0_ + com_v0_ * t + length_ * z[0];
    out.velocity1 = com_v0_ + speed_ * z[1];
    out.position2 = com_x0_ + com_v0_ * t + length_ * z[2];
    out.velocity2 = com_v0_ + speed_ * z[3];
    return out;
  }

  void finish(ImpactResult& r, const State& z, double t, long steps) const {
    const ImpactSample s = sample(t, z);
    r.end_time = t;
    r.steps = steps;
    r.body1_after = {m1_, s.position1, s.velocity1};
    r.body2_after = {m2_, s.position2, s.velocity2};
  }
};

}  // namespace

ImpactResult integrated_impact(const ImpactProblem& problem, const ImpactOptions& options) {
  ImpactIntegrator integrator(problem, options);
  ImpactResult r = integrator.run(nullptr, nullptr);
  if (options.history_points > 0) {
    SampleClock grid(r.end_time, options.history_points, integrator.events());
    std::vector<ImpactSample> history;
    const HistorySink sink(options, history);
    integrator.run(&grid, &sink);  // identical steps; samples from the dense output
    r.history = std::move(history);
  }
  // Constant external forces: the relative motion conserves ½ μ ḋ² + U(d) − μ g d on each branch, so
  // ½ μ ḋ(t_f)² = ½ μ ḋ(t_s)² − ∫_{d(t̄)}^{d(t_s)} (H_a − H_b) dξ (seed-1 eqs. 3, 6). ḋ(t_f) is taken from this
  // balance at the integrated d(t̄): its relative error is that of d(t̄) (~ the tolerance), also as e → 1,
  // where the integrated ḋ(t_f) has an absolute error ~ tolerance·|ḋ(t_s)|, i.e. a relative error
  // tolerance/(1 − e) of the loss. The centre-of-mass velocity is kept from the integration.
  double relative_loss = std::numeric_limits<double>::quiet_NaN();
  r.energy_balance_residual = relative_loss;
  // A Kelvin–Voigt term dissipates ∫ c(d) ḋ² dt on top of the area (eq. 6): no closed balance, the integrated
  // state is reported as is.
  if (r.outcome == ImpactOutcome::separated && problem.external().constant() && !problem.law().has_damping()) {
    const double m1 = problem.body1().mass, m2 = problem.body2().mass, total = m1 + m2;
    const double mu = problem.reduced_mass(), v_s = problem.initial_gap_rate();
    const double v_raw = r.body2_after.velocity - r.body1_after.velocity;
    relative_loss = hysteresis_energy_loss(problem.law(), r.minimum_gap, problem.initial_gap());
    r.energy_balance_residual = 0.5 * mu * (v_s - v_raw) * (v_s + v_raw) - relative_loss;
    const double x = relative_loss / (0.5 * mu * v_s * v_s);  // 1 − e²
    if (x < 1) {
      const double v_f = -v_s * std::sqrt(1.0 - x);
      const double com = (m1 * r.body1_after.velocity + m2 * r.body2_after.velocity) / total;
      r.body1_after.velocity = com - m2 / total * v_f;
      r.body2_after.velocity = com + m1 / total * v_f;
    } else {
      relative_loss = std::numeric_limits<double>::quiet_NaN();  // inconsistent: report the integrated state
    }
  }
  complete_result(problem, r, relative_loss);
  return r;
}

}  // namespace afmkit::impact::detail
