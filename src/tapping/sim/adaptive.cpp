// Adaptive stepper: DOP853 (order 8, 7th-order dense output; dop853.hpp) on the smooth vector field of the
// current mode (Dormand–Prince 5(4) for laws only C¹ between switching gaps, e.g. measured tables). The guards are tested at both ends of every accepted step — a sign change, or a witness rate
// turning towards the post-crossing side (an excursion inside the step) — and a crossing is isolated on the
// dense output. With sensitivities, the variational equations are integrated alongside (8 states).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <type_traits>

#include <boost/numeric/odeint.hpp>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "dop853.hpp"
#include "engine.hpp"
#include "small_angle.hpp"

namespace afmkit::tapping::detail {

namespace {

namespace odeint = boost::numeric::odeint;

/// cos ωt inside one step [t0, t0 + h] with ωh ≤ 2π/24·(ω/ω_min) small: one sincos per step, then the
/// rotation cos ω(t0 + τ) = cos ωt0 · C(ωτ) − sin ωt0 · S(ωτ) with Taylor polynomials C, S (degree 16/17: below
/// 1e-19 for |ωτ| ≤ 0.35; beyond that std::cos).
class DriveClock {
 public:
  DriveClock() = default;  // not explicit: value-initialised members ({}) need an implicit default constructor (clang)
  explicit DriveClock(double omega) : omega_(omega) {}
  void begin(double t0) {
    t0_ = t0;
    c0_ = std::cos(omega_ * t0);
    s0_ = std::sin(omega_ * t0);
  }
  double cos_at(double t) const {
    const double u = omega_ * (t - t0_);
    if (!(std::abs(u) <= detail::small_angle_limit)) return std::cos(omega_ * t);
    const std::complex<double> e = detail::small_angle_phasor(u);  // cos(ωt0 + u) = c0 cos u − s0 sin u
    return c0_ * e.real() - s0_ * e.imag();
  }

 private:
  double omega_ = 0.0, t0_ = 0.0, c0_ = 1.0, s0_ = 0.0;
};

/// Vector field of one mode; N = 2 (x, ẋ) or 8 (+ ∂(x,ẋ)/∂(x0,ẋ0) column-major, ∂(x,ẋ)/∂l).
template <std::size_t N>
struct ModeField {
  const TappingSystem* sys = nullptr;
  Mode mode;
  DriveClock clock;
  static ModeField make(const TappingSystem& s, const Mode& m) { return {&s, m, DriveClock(s.drive_frequency())}; }
  void begin_step(double t0) { clock.begin(t0); }
  void operator()(const std::array<double, N>& y, std::array<double, N>& dy, double t) const {
    const TipState s{y[0], y[1]};
    const double drive = sys->model().drive.amplitude * clock.cos_at(t);
    dy[0] = y[1];
    if constexpr (N == 2) {
      dy[1] = sys->acceleration_given_drive(mode, drive, s);
    } else {
      // J_f = [[0, 1], [−ω_n² − h_x, −2ξω_n − h_ẋ]],  ∂f/∂l = (0, −h_x)
      double slope = 0.0;
      const double h = sys->interaction_with_slope(mode.branch, y[0], y[1], mode.region, slope);
      dy[1] = drive - sys->damping() * y[1] - sys->stiffness() * y[0] - h;
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

/// The tip state of an integrated state: (x, ẋ) first; a multi-mode state (N = 4, 6) carries the higher modal
/// coordinates next (N = 8 is the single-mode state with its sensitivities).
template <std::size_t N>
TipState tip_of(const std::array<double, N>& y) {
  TipState s{y[0], y[1]};
  if constexpr (N == 4 || N == 6)
    for (std::size_t i = 2; i < N; ++i) s.modal[i - 2] = y[i];
  return s;
}

/// Vector field of one mode (region, branch) of a multi-mode cantilever: y = (x, ẋ, q_2, q̇_2, q_3, q̇_3), N = 2M.
template <std::size_t N>
struct ModalField {
  const TappingSystem* sys = nullptr;
  Mode mode;
  static ModalField make(const TappingSystem& s, const Mode& m) { return {&s, m}; }
  void begin_step(double /*t0*/) {}  // the modal forcing is evaluated where needed
  void operator()(const std::array<double, N>& y, std::array<double, N>& dy, double t) const {
    double a[kMaxEigenmodes];
    dy[0] = y[1];
    dy[1] = sys->modal_accelerations(mode.branch, mode.region, t, tip_of(y), a);  // 0 while sticking
    for (std::size_t j = 1; 2 * j < N; ++j) {
      dy[2 * j] = y[2 * j + 1];
      dy[2 * j + 1] = a[j];
    }
  }
};

template <class Dense, std::size_t N>
class DenseSegment final : public Segment {
 public:
  DenseSegment(double a, double b, Mode m, const Dense& dense, bool whole_step)
      : Segment(a, b, m), dense_(&dense), whole_step_(whole_step) {}
  TipState state(double t) const override {
    dense_->calc_state(t, buffer_);
    return tip_of(buffer_);
  }
  bool stage_quadrature(StageVisitor& visitor) const override {
    if constexpr (requires { dense_->visit_stages([](double, double, const std::array<double, N>&) {}); }) {
      if (!whole_step_) return false;
      dense_->visit_stages([&](double t, double w, const std::array<double, N>& y) { visitor.node(t, w, tip_of(y)); });
      return true;
    } else {
      return false;
    }
  }

 private:
  const Dense* dense_;
  bool whole_step_;  // the segment is the stepper's whole last step (not cut by an event)
  mutable std::array<double, N> buffer_{};
};

/// Error control of Dopri5 as Dop853's: |err_i| ≤ atol + rtol · max(|y_i| + h|ẏ_i|, floor_i) (Boost.Odeint's default
/// with the magnitude floor): the sensitivities are controlled relative to the identity they start from, not to
/// their own (possibly tiny) entries. For a law only C¹ at its knots the variational equations' right-hand side
/// (the law's slope) is only C⁰ there, and an entry near 0 held to atol alone took short steps at every knot
/// crossed (3 to 4 times the steps per period of a 1000-point table; the FM round trip of a reconstruction).
template <std::size_t N>
struct FloorErrorChecker {
  using State = std::array<double, N>;
  double atol = 0.0, rtol = 0.0;
  State floor{};
  template <class Algebra, class Deriv, class Err>
  double error(Algebra& /*algebra*/, const State& x_old, const Deriv& dxdt_old, Err& x_err, double dt) const {
    double worst = 0.0;
    for (std::size_t i = 0; i < N; ++i) {
      const double magnitude = std::max(std::abs(x_old[i]) + std::abs(dt * dxdt_old[i]), floor[i]);
      worst = std::max(worst, std::abs(x_err[i]) / (atol + rtol * magnitude));
    }
    return worst;
  }
};

/// Dormand–Prince 5(4) with dense output (Boost.Odeint runge_kutta_dopri5) behind the interface of Dop853, for
/// laws that are only C¹ between switching gaps: there the 8th order buys nothing and costs rejected steps.
template <class Field, std::size_t N>
class Dopri5 {
 public:
  using State = std::array<double, N>;
  Dopri5(double absolute_tolerance, double relative_tolerance, double max_step, const State& floor = {})
      : dense_(Controlled(FloorErrorChecker<N>{absolute_tolerance, relative_tolerance, floor},
                          odeint::default_step_adjuster<double, double>(max_step))) {}
  void initialize(const Field& field, const State& y, double t, double dt) {
    field_ = field;
    dense_.initialize(y, t, dt);
  }
  /// One accepted step; a step ending beyond t_limit is reported as ending there (the run stops at t_limit).
  std::pair<double, double> do_step(double t_limit) {
    // the drive's clock from the step's start (as Dop853 does): else every evaluation more than 0.35 rad of the
    // drive after the mode's start fell back to std::cos
    field_.begin_step(dense_.current_time());
    auto [t_old, t_new] = dense_.do_step(field_);
    if (t_new > t_limit) {
      t_new = t_limit;
      dense_.calc_state(t_limit, y_);
    } else {
      y_ = dense_.current_state();
    }
    return {t_old, t_new};
  }
  void calc_state(double t, State& out) const { dense_.calc_state(t, out); }
  double current_time() const { return dense_.current_time(); }
  double current_time_step() const { return dense_.current_time_step(); }
  const State& current_state() const { return y_; }

 private:
  using Controlled = odeint::controlled_runge_kutta<odeint::runge_kutta_dopri5<State>, FloorErrorChecker<N>>;
  using Dense = odeint::dense_output_runge_kutta<Controlled>;
  Dense dense_;
  Field field_{};
  State y_{};
};

/// The magnitude below which the sensitivities' errors are held to the tolerance relative to this floor (DOP853).
constexpr double kSensitivityFloor = 10.0;

template <std::size_t N, template <class, std::size_t> class StepperFor, class Field = ModeField<N>>
void run(const TappingSystem& sys, RunState& rs, double t_end, const SimulationOptions& options,
         TrajectoryObserver* observer) {
  using State = std::array<double, N>;
  const double drive_period = sys.model().period();
  // Shortest natural period of the cantilever (contact stiffening shortens it; the error control handles it).
  const double max_dt = scan_step(sys, 2.0 * 3.141592653589793 / sys.model().cantilever.natural_frequency, options);
  using Stepper = StepperFor<Field, N>;
  // the sensitivities are controlled relative to the identity they start from, not to their own (possibly tiny)
  // entries: their right-hand side jumps with the law's slope at a switching gap, just where a step must reach.
  // DOP853 (a smooth law) measures the error by the RMS over the N components: with the sensitivities (N = 8) the
  // state's two terms weigh as in the run without them at half the tolerances (√(8/2) = 2: the state is held as
  // that run holds it), and the six sensitivities, as smooth as the state there, to kSensitivityFloor times the
  // tolerance: held to the tolerance itself they took 1.75 times the steps of the state, 1.36 times now (pyDAMPF's
  // DMT sweep at tolerance 1e-10 against one at 1e-13, 50 / 1000 points: Floquet multipliers within 1e-10 / 7.3e-9
  // instead of 6e-12 / 3e-10, amplitudes within 7.7e-10 / 8.1e-9 instead of 1.7e-10 / 8.1e-9; at 100 times the
  // tolerance 1.2 times the steps, multipliers within 2.8e-9 / 1.3e-8: measured). Dopri5 (a law only C¹ at its
  // knots: the sensitivities' right-hand side only C⁰ there) holds them all to the tolerance.
  State floor{};
  double tolerance_scale = 1.0;
  if constexpr (N == 8) {
    constexpr bool rms = std::is_same_v<Stepper, Dop853<Field, N>>;
    for (std::size_t i = 2; i < N; ++i) floor[i] = rms ? 2.0 * kSensitivityFloor : 1.0;
    if (rms) tolerance_scale = 0.5;
  }
  Stepper dense(tolerance_scale * options.absolute_tolerance, tolerance_scale * options.relative_tolerance, max_dt,
                floor);
  std::array<Guard, 3> guards;
  GuardSamples a, b;
  State y{}, tmp{};
  double dt = std::min(max_dt, options.initial_step > 0.0 ? options.initial_step : 1e-3 * drive_period);
  while (rs.t < t_end) {
    // an event located less than the smallest step before t_end: the state stands for that remainder
    if (t_end - rs.t <= 16.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t_end))) {
      rs.t = t_end;
      break;
    }
    // one mode: the tip rests (run_sticking); more modes: the modes move on with the tip held (ModalField)
    if (rs.mode.branch == ContactBranch::sticking && !sys.modal()) {
      run_sticking(sys, rs, t_end, options, observer);
      continue;
    }
    const double segment_begin = rs.t;
    const Mode mode = rs.mode;
    y.fill(0.0);
    y[0] = rs.y.position;
    y[1] = rs.y.velocity;
    if constexpr (N == 8) y[2] = y[5] = 1.0;  // per-segment state-transition matrix starts at I
    if constexpr (N == 4 || N == 6)
      for (std::size_t i = 2; i < N; ++i) y[i] = rs.y.modal[i - 2];
    dense.initialize(Field::make(sys, mode), y, rs.t, dt);
    const int n = sys.guards(mode, guards);
    auto state = [&](double t) {
      dense.calc_state(t, tmp);
      return tip_of(tmp);
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
      const auto [t_old, t_new] = dense.do_step(t_end);
      const State& y_new = dense.current_state();
      sample_guards(sys, mode, guards, n, t_new, tip_of(y_new), b);
      hit = first_crossing(sys, mode, guards, n, t_old, t_new, a, b, state);
      if (!hit) a = b;
      const double seg_end = hit ? hit->time : t_new;
      if (observer) observer->on_segment(sys, DenseSegment<Stepper, N>(t_old, seg_end, mode, dense, !hit));
      if (hit || t_new >= t_end) {
        t_stop = seg_end;
        break;
      }
    }
    dt = std::min(max_dt, dense.current_time_step());
    dense.calc_state(t_stop, tmp);
    const TipState y1 = tip_of(tmp);
    if constexpr (N == 8) {
      Eigen::Matrix3d seg = Eigen::Matrix3d::Identity();
      seg << tmp[2], tmp[4], tmp[6], tmp[3], tmp[5], tmp[7], 0.0, 0.0, 1.0;
      rs.jacobian = seg * rs.jacobian;
    }
    if (mode.branch == ContactBranch::sticking) rs.stats.sticking_duration += t_stop - segment_begin;
    if (hit) {
      handle_event(sys, rs, guards[hit->guard], t_stop, y1, options, observer);
    } else {
      rs.t = t_end;
      rs.y = y1;
    }
  }
  rs.stats.next_step = dt;
}

}  // namespace

void run_adaptive(const TappingSystem& sys, RunState& rs, double t_end, const SimulationOptions& options,
                  TrajectoryObserver* observer) {
  const bool smooth = sys.model().law.smooth();
  if (sys.modal()) {  // the same engine on the modal state (x, ẋ, q_2, q̇_2, q_3, q̇_3)
    switch (sys.mode_count()) {
      case 1:
        return smooth ? run<2, Dop853, ModalField<2>>(sys, rs, t_end, options, observer)
                      : run<2, Dopri5, ModalField<2>>(sys, rs, t_end, options, observer);
      case 2:
        return smooth ? run<4, Dop853, ModalField<4>>(sys, rs, t_end, options, observer)
                      : run<4, Dopri5, ModalField<4>>(sys, rs, t_end, options, observer);
      default:
        return smooth ? run<6, Dop853, ModalField<6>>(sys, rs, t_end, options, observer)
                      : run<6, Dopri5, ModalField<6>>(sys, rs, t_end, options, observer);
    }
  }
  if (options.sensitivity)
    smooth ? run<8, Dop853>(sys, rs, t_end, options, observer) : run<8, Dopri5>(sys, rs, t_end, options, observer);
  else
    smooth ? run<2, Dop853>(sys, rs, t_end, options, observer) : run<2, Dopri5>(sys, rs, t_end, options, observer);
}

}  // namespace afmkit::tapping::detail
