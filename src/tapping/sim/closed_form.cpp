// Closed-form stepper: exact flow of the linear modes of a piecewise-linear law (flow.hpp), guards scanned on
// a grid no coarser than a fraction of the shortest period present and isolated on the closed form.
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/flow.hpp"
#include "engine.hpp"

namespace afmkit::tapping::detail {

namespace {

class ClosedFormSegment final : public Segment {
 public:
  ClosedFormSegment(double a, double b, Mode m, const LinearModeFlow& flow, Eigen::Vector2d h0)
      : Segment(a, b, m), flow_(&flow), h0_(std::move(h0)) {}
  TipState state(double t) const override {
    const Eigen::Vector2d y = flow_->state(h0_, t, t - t_begin());
    return {y.x(), y.y()};
  }

 private:
  const LinearModeFlow* flow_;
  Eigen::Vector2d h0_;
};

/// The three linear modes of a piecewise-linear law: free, contact approach, contact departure.
struct ModeFlows {
  LinearModeFlow free, approach, departure;
  explicit ModeFlows(const TappingSystem& sys) {
    const auto& m = sys.model();
    const auto* p = m.law.piecewise_linear();
    const double c = sys.damping(), k0 = sys.stiffness(), l = m.separation;
    const double g = m.drive.amplitude, w = m.drive.frequency;
    free = LinearModeFlow(c, k0, g, w, 0.0, 0.0);
    // contact: ẍ + cẋ + (ω_n² + K) x = Γ cos ωt − (F + K l)   (seed-1 eqs. 8, 26)
    const double ka = p->approach_stiffness, kb = p->departure_stiffness;
    approach = LinearModeFlow(c, k0 + ka, g, w, -(p->approach_adhesion + ka * l), -ka / (k0 + ka));
    departure = LinearModeFlow(c, k0 + kb, g, w, -(p->departure_adhesion + kb * l), -kb / (k0 + kb));
  }
  const LinearModeFlow& of(const Mode& mode) const {
    if (mode.region != 0) return free;
    return mode.branch == ContactBranch::departure ? departure : approach;
  }
};

inline TipState to_tip(const Eigen::Vector2d& y) { return {y.x(), y.y()}; }

/// The flow on the scan grid t_k = t0 + k h. Underdamped modes (always, for Q > 1/2) use exact complex
/// rotations — x = f/k + Re(Z u) + Re(V w), u = e^{iωt}, w = e^{λτ}, λ = −α + i√−D — so a grid point costs a few
/// multiplications instead of three transcendental calls; other modes evaluate the closed form directly.
/// (Grid values only detect crossings; events are isolated on the exact closed form.)
class FlowSampler {
 public:
  FlowSampler(const LinearModeFlow& flow, double t0, const Eigen::Vector2d& h0, double h)
      : flow_(&flow), t0_(t0), h_(h), h0_(h0) {
    if (flow.underdamped()) {
      const double w = flow.drive_frequency();
      lambda_ = {-flow.decay_rate(), flow.damped_frequency()};
      u_ = std::polar(1.0, w * t0);
      du_ = std::polar(1.0, w * h);
      w_ = 1.0;
      dw_ = std::exp(lambda_ * h);
      // x_h(0) = Re V, ẋ_h(0) = Re(λ V)
      v_ = {h0.x(), -(h0.y() + flow.decay_rate() * h0.x()) / flow.damped_frequency()};
    }
    evaluate();
  }
  double time() const { return t_; }
  TipState state() const { return s_; }
  double acceleration() const { return a_; }
  void advance(int steps = 1) {
    k_ += steps;
    if (flow_->underdamped()) {
      if (k_ - synced_ >= 64) {  // re-synchronise the rotations now and then (rounding drift)
        const double tau = k_ * h_;
        u_ = std::polar(1.0, flow_->drive_frequency() * (t0_ + tau));
        w_ = std::exp(lambda_ * tau);
        synced_ = k_;
      } else {
        for (int i = 0; i < steps; ++i) {
          u_ *= du_;
          w_ *= dw_;
        }
      }
    }
    evaluate();
  }

 private:
  void evaluate() {
    t_ = t0_ + k_ * h_;
    const LinearModeFlow& f = *flow_;
    if (f.underdamped()) {
      const std::complex<double> zu = f.harmonic() * u_, vw = v_ * w_;
      const double omega = f.drive_frequency();
      s_.position = f.static_offset() + zu.real() + vw.real();
      s_.velocity = -omega * zu.imag() + (lambda_ * vw).real();
      a_ = f.drive_amplitude() * u_.real() + f.force() - f.damping() * s_.velocity - f.stiffness() * s_.position;
    } else {
      s_ = to_tip(f.state(h0_, t_, t_ - t0_));
      a_ = f.drive_amplitude() * std::cos(f.drive_frequency() * t_) + f.force() - f.damping() * s_.velocity -
           f.stiffness() * s_.position;
    }
  }
  const LinearModeFlow* flow_;
  double t0_, h_;
  Eigen::Vector2d h0_;
  long k_ = 0, synced_ = 0;
  double t_ = 0;
  TipState s_;
  double a_ = 0;
  std::complex<double> lambda_, u_, du_, w_, dw_, v_;
};

/// Witness values and rates of the gap / velocity guards from a grid sample.
inline void fill_samples(const TappingSystem& sys, const std::array<Guard, 3>& guards, int n, const FlowSampler& fs,
                         GuardSamples& out) {
  const TipState s = fs.state();
  for (int i = 0; i < n; ++i) {
    if (guards[i].kind == GuardKind::gap) {
      out.value[i] = sys.gap(s.position) - guards[i].level;
      out.rate[i] = s.velocity;
    } else {  // velocity guard (release guards only occur while sticking)
      out.value[i] = s.velocity;
      out.rate[i] = fs.acceleration();
    }
  }
}

}  // namespace

void run_closed_form(const TappingSystem& sys, RunState& rs, double t_end, const SimulationOptions& options,
                     TrajectoryObserver* observer) {
  const ModeFlows flows(sys);
  std::array<Guard, 3> guards;
  GuardSamples a, b;
  while (rs.t < t_end) {
    if (rs.mode.branch == ContactBranch::sticking) {
      run_sticking(sys, rs, t_end, options, observer);
      continue;
    }
    const LinearModeFlow& flow = flows.of(rs.mode);
    const Mode mode = rs.mode;
    const double t0 = rs.t;
    const Eigen::Vector2d y0(rs.y.position, rs.y.velocity);
    const Eigen::Vector2d h0 = y0 - flow.particular(t0);
    auto state = [&](double t) { return to_tip(flow.state(h0, t, t - t0)); };
    const int n = sys.guards(mode, guards);

    // Out of contact the only guard is the gap falling to the contact edge; skip the scan when even the
    // lowest possible position (static offset − harmonic amplitude − bound of the decaying transient) stays
    // above it for the rest of the interval.
    bool skip = false;
    if (n == 1 && guards[0].kind == GuardKind::gap && guards[0].direction == CrossingDirection::falling) {
      const double lowest = flow.static_offset() - flow.harmonic_amplitude() - flow.homogeneous_bound(h0);
      skip = sys.gap(lowest) - guards[0].level > 0.0;
    }
    std::optional<Crossing> hit;
    if (!skip) {
      const double h = scan_step(sys, flow.mode_period(), options);
      const int max_skip = std::max(1, static_cast<int>(0.25 * std::min(sys.model().period(), flow.mode_period()) / h));
      // Safe skips: with |g''| ≤ C on the whole segment, g(ta + τ) stays on the pre-crossing side while
      // |g_a| − |g'_a| τ − C τ²/2 > 0 (g'' = ẍ for gap guards, d³x/dt³ for the velocity guard): advance by
      // as many grid steps as that allows (at least one).
      std::array<double, 3> curvature{};
      for (int i = 0; i < n; ++i)
        curvature[i] = guards[i].kind == GuardKind::gap ? flow.derivative_bound(h0, 2) : flow.derivative_bound(h0, 3);
      auto safe_steps = [&](const GuardSamples& s) {
        double tau = 1e300;
        for (int i = 0; i < n; ++i) {
          const double sign = guards[i].direction == CrossingDirection::falling ? 1.0 : -1.0;
          const double g = sign * s.value[i], r = sign * s.rate[i], c = curvature[i];
          if (!(g > 0) || !std::isfinite(c)) return 1;
          tau = std::min(tau, (r + std::sqrt(r * r + 2.0 * c * g)) / c);
        }
        return std::clamp(static_cast<int>(tau / h), 1, max_skip);
      };
      FlowSampler sampler(flow, t0, h0, h);
      fill_samples(sys, guards, n, sampler, a);
      start_on_pre_side(guards, n,
                        std::max({1.0, std::abs(rs.y.position), std::abs(rs.y.velocity), std::abs(sys.separation())}),
                        a);
      double ta = t0;
      while (ta < t_end) {
        sampler.advance(safe_steps(a));
        double tb = sampler.time();
        if (tb >= t_end) {
          tb = t_end;
          sample_guards(sys, mode, guards, n, tb, state(tb), b);
        } else {
          fill_samples(sys, guards, n, sampler, b);
        }
        ++rs.stats.steps;
        hit = first_crossing(sys, mode, guards, n, ta, tb, a, b, state);
        if (hit) break;
        ta = tb;
        a = b;
      }
    }
    const double t1 = hit ? hit->time : t_end;
    const Eigen::Matrix2d e = flow.propagator(t1 - t0);
    const TipState y1 = to_tip(flow.particular(t1) + e * h0);
    if (observer) observer->on_segment(sys, ClosedFormSegment(t0, t1, mode, flow, h0));
    if (options.sensitivity) {
      Eigen::Matrix3d seg = Eigen::Matrix3d::Identity();
      seg.topLeftCorner<2, 2>() = e;
      seg.topRightCorner<2, 1>() = flow.separation_sensitivity(e);
      rs.jacobian = seg * rs.jacobian;
    }
    if (hit) {
      handle_event(sys, rs, guards[hit->guard], t1, y1, options, observer);
    } else {
      rs.t = t_end;
      rs.y = y1;
    }
  }
}

}  // namespace afmkit::tapping::detail
