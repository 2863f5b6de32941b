#pragma once
// Internal: the DOP853 stepper for smooth force laws — explicit Runge–Kutta of order 8 with the 5th/3rd-order
// error estimator, step-size control and the 7th-order dense output of Hairer's DOP853 (tableau in
// dop853_tableau.hpp). Made for the tapping model between events: the dense output is built only when asked for
// (event isolation, an observer, a stop inside the step), so a step that crosses no guard costs 12 evaluations
// of the vector field. Interface as Boost.Odeint's dense-output steppers (initialize, do_step, calc_state).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "dop853_tableau.hpp"

namespace afmkit::tapping::detail {

template <class Field, std::size_t N>
class Dop853 {
 public:
  using State = std::array<double, N>;

  /// Error control per component i: |err_i| ≤ atol + rtol · max(|y_i|, |y_i,new|, magnitude_floor[i]) (RMS).
  Dop853(double absolute_tolerance, double relative_tolerance, double max_step, const State& magnitude_floor = {})
      : atol_(absolute_tolerance), rtol_(relative_tolerance), max_step_(max_step), floor_(magnitude_floor) {}

  /// Start at (t, y) with the vector field `field` and a first trial step dt.
  void initialize(const Field& field, const State& y, double t, double dt) {
    field_ = field;
    y_ = y;
    t_ = t;
    h_ = std::min(dt, max_step_);
    begin_step(t_);
    field_(y_, k_[0], t_);
  }

  /// One accepted step, never beyond t_limit; returns (t_old, t_new).
  std::pair<double, double> do_step(double t_limit = std::numeric_limits<double>::infinity()) {
    using namespace dop853;
    const double h_min = 16.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t_));
    bool last_rejected = false;
    for (;;) {
      double h = std::min(h_, max_step_);
      bool clipped = false;
      // a step that would end less than the smallest step before t_limit ends there instead (steps that add up
      // to just below t_limit, e.g. whole periods in max_step pieces, left a remainder the next step refused)
      if (t_ + h >= t_limit - h_min) {
        h = t_limit - t_;
        clipped = true;
      }
      if (!(h > h_min))
        throw NumericalFailure(fmt::format("tapping simulation (adaptive): step size {:.3g} underflows at t = {:.9g}",
                                           h, t_));
      begin_step(t_);
      // stages 1–11 (unrolled at compile time: the tableau's zeros skipped, the same sums in the same order)
      [&]<int... S>(std::integer_sequence<int, S...>) {
        State tmp;
        ((stage_combine<S + 1>(y_, h, k_.data(), tmp), field_(tmp, k_[S + 1], t_ + c[S + 1] * h)), ...);
      }(std::make_integer_sequence<int, 11>{});
      State y_new;
      weights_combine(y_, h, k_.data(), y_new);
      const double t_new = clipped ? t_limit : t_ + h;
      field_(y_new, k_[12], t_new);
      // error norm (DOP853): |h| Σ(err5/sk)² / sqrt(N (Σ(err5/sk)² + 0.01 Σ(err3/sk)²))
      State err5{}, err3{};
      for (int j = 0; j < 13; ++j) {
        const double w5 = e5[j], w3 = e3[j];
        for (std::size_t i = 0; i < N; ++i) {
          err5[i] += w5 * k_[j][i];
          err3[i] += w3 * k_[j][i];
        }
      }
      double s5 = 0.0, s3 = 0.0;
      for (std::size_t i = 0; i < N; ++i) {
        const double e5v = err5[i], e3v = err3[i];
        const double sk = atol_ + rtol_ * std::max({std::abs(y_[i]), std::abs(y_new[i]), floor_[i]});
        s5 += (e5v / sk) * (e5v / sk);
        s3 += (e3v / sk) * (e3v / sk);
      }
      const double denominator = s5 + 0.01 * s3;
      const double err = denominator > 0.0 ? h * s5 / std::sqrt(static_cast<double>(N) * denominator) : 0.0;
      if (!std::isfinite(err))
        throw NumericalFailure(fmt::format("tapping simulation (adaptive): non-finite state at t = {:.9g}", t_));
      // step-size factor: 0.9 err^(−1/8), within [1/3, 6] (Hairer's defaults), no growth right after a rejection
      const double grow = err > 0.0 ? std::clamp(0.9 * std::pow(err, -0.125), 1.0 / 3.0, 6.0) : 6.0;
      if (err <= 1.0) {
        const double t_old = t_;
        y_old_ = y_;
        h_used_ = h;
        t_old_ = t_old;
        y_ = y_new;
        t_ = t_new;
        k0_old_ = k_[0];  // the dense output of this step needs f(t_old) ...
        k_[0] = k_[12];   // ... while f(t_new) starts the next step (and stays stage 12 of this one)
        dense_ready_ = false;
        const double next = h * (last_rejected ? std::min(1.0, grow) : grow);
        // a step clipped to t_limit says nothing about the step the accuracy allows: keep the longer one
        h_ = clipped ? std::max(h_, next) : next;
        return {t_old, t_new};
      }
      last_rejected = true;
      h_ = h * std::min(1.0, grow);
    }
  }

  /// State at t inside the last step (the 7th-order dense output; exact at both ends).
  void calc_state(double t, State& out) const {
    if (t == t_) {
      out = y_;
      return;
    }
    if (t == t_old_) {
      out = y_old_;
      return;
    }
    if (!dense_ready_) build_dense();
    const double x = (t - t_old_) / h_used_, x1 = 1.0 - x;
    for (std::size_t i = 0; i < N; ++i) {
      // y_old + x(F0 + (1−x)(F1 + x(F2 + (1−x)(F3 + x(F4 + (1−x)(F5 + x F6))))))
      double p = f_[6][i] * x;
      p = (p + f_[5][i]) * x1;
      p = (p + f_[4][i]) * x;
      p = (p + f_[3][i]) * x1;
      p = (p + f_[2][i]) * x;
      p = (p + f_[1][i]) * x1;
      p = (p + f_[0][i]) * x;
      out[i] = y_old_[i] + p;
    }
  }

  /// The last accepted step's stages with nonzero weight b_j: visit(t_j, h b_j, Y_j), Y_j = y_old + h Σ_l a_jl k_l
  /// the stage state (no evaluation of the field: the stages' k are kept until the next step).
  template <class Visit>
  void visit_stages(Visit&& visit) const {
    using namespace dop853;
    const double h = h_used_;
    visit(t_old_, h * b[0], y_old_);
    // b_1..b_4 = 0; the stages' k_0 is the last step's (k_[0] already holds the next step's)
    [&]<int... S>(std::integer_sequence<int, S...>) {
      State y;
      ((stage_state<S + 5>(h, y), visit(t_old_ + c[S + 5] * h, h * b[S + 5], y)), ...);
    }(std::make_integer_sequence<int, 7>{});
  }

  double current_time() const { return t_; }
  double current_time_step() const { return h_; }
  const State& current_state() const { return y_; }

 private:
  void build_dense() const {
    using namespace dop853;
    const double h = h_used_;
    begin_step(t_old_);
    std::array<State, 16> k;
    k[0] = k0_old_;
    for (int s = 1; s < 13; ++s) k[s] = k_[s];
    for (int s = 13; s < 16; ++s) {
      State tmp;
      combine(y_old_, h, a[s], s, k.data(), tmp);
      field_(tmp, k[s], t_old_ + c[s] * h);
    }
    const State zero{};
    for (int r = 0; r < 4; ++r) combine(zero, h, d[r], 16, k.data(), f_[3 + r]);
    for (std::size_t i = 0; i < N; ++i) {
      const double dy = y_[i] - y_old_[i];
      f_[0][i] = dy;
      f_[1][i] = h * k[0][i] - dy;
      f_[2][i] = 2.0 * dy - h * (k[12][i] + k[0][i]);
    }
    dense_ready_ = true;
  }
  /// out = base + h Σ_{j<S} a_Sj k_j, stage S's state, as combine(base, h, a[S], S, k, out) with the zero weights
  /// skipped at compile time
  template <int S>
  static void stage_combine(const State& base, double h, const State* k, State& out) {
    using namespace dop853;
    out = base;
    [&]<int... J>(std::integer_sequence<int, J...>) {
      ((a[S][J] != 0.0 ? add_weighted(h * a[S][J], k[J], out) : void()), ...);
    }(std::make_integer_sequence<int, S>{});
  }
  /// out = base + h Σ_{j<12} b_j k_j (the 8th-order solution), as combine(base, h, b, 12, k, out)
  static void weights_combine(const State& base, double h, const State* k, State& out) {
    using namespace dop853;
    out = base;
    [&]<int... J>(std::integer_sequence<int, J...>) {
      ((b[J] != 0.0 ? add_weighted(h * b[J], k[J], out) : void()), ...);
    }(std::make_integer_sequence<int, 12>{});
  }
  /// stage S's state of the last accepted step (after it: k_0 in k0_old_)
  template <int S>
  void stage_state(double h, State& out) const {
    using namespace dop853;
    out = y_old_;
    add_weighted(h * a[S][0], k0_old_, out);
    [&]<int... J>(std::integer_sequence<int, J...>) {
      ((a[S][J + 1] != 0.0 ? add_weighted(h * a[S][J + 1], k_[J + 1], out) : void()), ...);
    }(std::make_integer_sequence<int, S - 1>{});
  }
  static void add_weighted(double hw, const State& k, State& out) {
    for (std::size_t i = 0; i < N; ++i) out[i] += hw * k[i];
  }
  /// out = base + h Σ_{j<count} w_j k_j (zero weights skipped: most of the tableau is zero)
  static void combine(const State& base, double h, const double* w, int count, const State* k, State& out) {
    out = base;
    for (int j = 0; j < count; ++j) {
      if (w[j] == 0.0) continue;
      const double hw = h * w[j];
      for (std::size_t i = 0; i < N; ++i) out[i] += hw * k[j][i];
    }
  }

  // a field with time-dependent forcing may prepare it once per step (begin_step(t0)), for t in [t0, t0 + h]
  void begin_step(double t0) const {
    if constexpr (requires(Field& f) { f.begin_step(t0); }) field_.begin_step(t0);
  }

  double atol_, rtol_, max_step_;
  State floor_;
  mutable Field field_{};
  State y_{}, y_old_{}, k0_old_{};
  double t_ = 0.0, t_old_ = 0.0, h_ = 0.0, h_used_ = 0.0;
  std::array<State, 13> k_{};
  mutable std::array<State, 7> f_{};
  mutable bool dense_ready_ = false;
};

}  // namespace afmkit::tapping::detail
