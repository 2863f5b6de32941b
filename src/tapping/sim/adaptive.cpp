// Adaptive stepper: Dormand–Prince 5(4) with dense output (Boost.Odeint runge_kutta_dopri5) on the smooth
// vector field of the current mode, guards scanned on the dense output inside every accepted step and
// isolated on it. With sensitivities, the variational equations are integrated alongside (8 states).
#include <algorithm>
#include <array>
#include <cmath>

#include <boost/numeric/odeint.hpp>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "engine.hpp"

namespace afmkit::tapping::detail {

namespace {

namespace odeint = boost::numeric::odeint;

/// Vector field of one mode; N = 2 (x, ẋ) or 8 (+ ∂(x,ẋ)/∂(x0,ẋ0) column-major, ∂(x,ẋ)/∂l).
template <std::size_t N>
struct ModeField {
  const TappingSystem* sys;
  Mode mode;
  void operator()(const std::array<double, N>& y, std::array<double, N>& dy, double t) const {
    const TipState s{y[0], y[1]};
    dy[0] = y[1];
    dy[1] = sys->acceleration(mode, t, s);
    if constexpr (N == 8) {
      // J_f = [[0, 1], [−ω_n² − h_x, −2ξω_n − h_ẋ]],  ∂f/∂l = (0, −h_x)
      const double slope = sys->interaction_slope(mode.branch, y[0], y[1], mode.region);
      const double j10 = -sys->stiffness() - slope;
      const double j11 = -sys->damping() - sys->interaction_rate_slope(mode.branch, y[0], mode.region);
      for (int c = 0; c < 3; ++c) {
        const double px = y[2 + 2 * c], pv = y[3 + 2 * c];
        dy[2 + 2 * c] = pv;
        dy[3 + 2 * c] = j10 * px + j11 * pv;
      }
      dy[7] -= slope;
    }
  }
};

template <class Dense, std::size_t N>
class DenseSegment final : public Segment {
 public:
  DenseSegment(double a, double b, Mode m, const Dense& dense) : Segment(a, b, m), dense_(&dense) {}
  TipState state(double t) const override {
    dense_->calc_state(t, buffer_);
    return {buffer_[0], buffer_[1]};
  }

 private:
  const Dense* dense_;
  mutable std::array<double, N> buffer_{};
};

template <std::size_t N>
void run(const TappingSystem& sys, RunState& rs, double t_end, const SimulationOptions& options,
         TrajectoryObserver* observer) {
  using State = std::array<double, N>;
  const double drive_period = sys.model().period();
  // Shortest natural period of the cantilever (contact stiffening shortens it; the error control handles it).
  const double max_dt = scan_step(sys, 2.0 * 3.141592653589793 / sys.model().cantilever.natural_frequency, options);
  auto dense = odeint::make_dense_output(options.absolute_tolerance, options.relative_tolerance, max_dt,
                                         odeint::runge_kutta_dopri5<State>());
  using Dense = decltype(dense);
  std::array<Guard, 3> guards;
  GuardSamples a, b;
  State y{}, tmp{};
  double dt = std::min(max_dt, 1e-3 * drive_period);
  while (rs.t < t_end) {
    if (rs.mode.branch == ContactBranch::sticking) {
      run_sticking(sys, rs, t_end, options, observer);
      continue;
    }
    const Mode mode = rs.mode;
    const ModeField<N> field{&sys, mode};
    y.fill(0.0);
    y[0] = rs.y.position;
    y[1] = rs.y.velocity;
    if constexpr (N == 8) y[2] = y[5] = 1.0;  // per-segment state-transition matrix starts at I
    dense.initialize(y, rs.t, dt);
    const int n = sys.guards(mode, guards);
    auto state = [&](double t) {
      dense.calc_state(t, tmp);
      return TipState{tmp[0], tmp[1]};
    };
    sample_guards(sys, mode, guards, n, rs.t, rs.y, a);
    start_on_pre_side(guards, n,
                      std::max({1.0, std::abs(rs.y.position), std::abs(rs.y.velocity), std::abs(sys.separation())}),
                      a);
    std::optional<Crossing> hit;
    double t_stop = t_end;
    for (;;) {
      if (++rs.stats.steps > options.max_steps)
        throw NumericalFailure(fmt::format("tapping simulation (adaptive): step budget of {} steps exhausted at "
                                           "t = {:.9g}", options.max_steps, dense.current_time()));
      const auto [t_old, t_new] = dense.do_step(field);
      const double tb_end = std::min(t_new, t_end);
      // scan the step in two halves on the dense output
      double ta = t_old;
      for (int k = 1; k <= 2 && !hit; ++k) {
        const double tb = k == 2 ? tb_end : std::min(tb_end, t_old + 0.5 * (t_new - t_old));
        if (tb <= ta) continue;
        sample_guards(sys, mode, guards, n, tb, state(tb), b);
        hit = first_crossing(sys, mode, guards, n, ta, tb, a, b, state);
        if (!hit) {
          a = b;
          ta = tb;
        }
      }
      const double seg_end = hit ? hit->time : tb_end;
      if (observer) observer->on_segment(sys, DenseSegment<Dense, N>(t_old, seg_end, mode, dense));
      if (hit || t_new >= t_end) {
        t_stop = seg_end;
        break;
      }
    }
    dt = std::min(max_dt, dense.current_time_step());
    dense.calc_state(t_stop, tmp);
    const TipState y1{tmp[0], tmp[1]};
    if constexpr (N == 8) {
      Eigen::Matrix3d seg = Eigen::Matrix3d::Identity();
      seg << tmp[2], tmp[4], tmp[6], tmp[3], tmp[5], tmp[7], 0.0, 0.0, 1.0;
      rs.jacobian = seg * rs.jacobian;
    }
    if (hit) {
      handle_event(sys, rs, guards[hit->guard], t_stop, y1, options, observer);
    } else {
      rs.t = t_end;
      rs.y = y1;
    }
  }
}

}  // namespace

void run_adaptive(const TappingSystem& sys, RunState& rs, double t_end, const SimulationOptions& options,
                  TrajectoryObserver* observer) {
  if (options.sensitivity)
    run<8>(sys, rs, t_end, options, observer);
  else
    run<2>(sys, rs, t_end, options, observer);
}

}  // namespace afmkit::tapping::detail
