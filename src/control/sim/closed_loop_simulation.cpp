#include "afmkit/control/closed_loop_simulation.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/control/discretisation.hpp"
#include "afmkit/control/harmonic_analysis.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "controller_steppers.hpp"

namespace afmkit::control {

std::string to_string(ControllerStepping s) {
  switch (s) {
    case ControllerStepping::ZeroOrderHold: return "zoh";
    case ControllerStepping::BlockZeroOrderHold: return "block_zoh";
    default: return "ab3";
  }
}

namespace {

int max_disturbance_order(const Disturbance& f) {
  int k = 0;
  for (const auto& h : f.harmonics) k = std::max(k, h.order);
  return k;
}

/// Eigenvalues that the AB3 step must keep inside its region: controller state matrix (finite bank) or the
/// roots of 𝒜(s) (N = ∞: the undelayed part of eqs. 32–33). Growing modes are mirrored to −λ̄.
Eigen::VectorXcd controller_modes(const Bank& bank) {
  Eigen::VectorXcd ev;
  if (const auto* ob = std::get_if<OscillatorBank>(&bank)) {
    const std::vector<std::complex<double>> e = bank_eigenvalues(*ob);  // O(N²), no dense matrix
    ev = Eigen::Map<const Eigen::VectorXcd>(e.data(), static_cast<Eigen::Index>(e.size()));
  } else {
    const auto a = std::get<InfiniteBank>(bank).a_coefficients();
    Eigen::Matrix4d comp = Eigen::Matrix4d::Zero();
    for (int j = 0; j < 4; ++j) comp(0, j) = -a[3 - j] / a[4];
    for (int j = 1; j < 4; ++j) comp(j, j - 1) = 1.0;
    ev = Eigen::EigenSolver<Eigen::Matrix4d>(comp, false).eigenvalues();
  }
  for (Eigen::Index i = 0; i < ev.size(); ++i)
    if (ev(i).real() > 0.0) ev(i) = -std::conj(ev(i));
  return ev;
}

/// Ring buffer of the plant output on the grid, indexable from −(capacity/2) on.
class History {
 public:
  explicit History(long max_back) {
    cap_ = std::bit_ceil(static_cast<std::size_t>(max_back) + 16);
    buf_.assign(cap_, 0.0);
    mask_ = cap_ - 1;
  }
  double& operator[](long j) { return buf_[static_cast<std::size_t>(j + static_cast<long>(cap_)) & mask_]; }

 private:
  std::size_t cap_, mask_;
  std::vector<double> buf_;
};

/// Cubic Lagrange weights for nodes j0..j0+3 at position s (grid units).
std::array<double, 4> lagrange4(long j0, double s) {
  std::array<double, 4> w;
  for (int i = 0; i < 4; ++i) {
    double l = 1.0;
    for (int k = 0; k < 4; ++k)
      if (k != i) l *= (s - static_cast<double>(j0 + k)) / static_cast<double>(i - k);
    w[i] = l;
  }
  return w;
}

struct LoopContext {
  const Plant* plant;
  int M;
  long total;
  double h;
  int record_every;
  bool first_order;
  // tables over one period (index n mod M)
  std::vector<double> f, forcing, target, f_minus_first;
  std::vector<std::complex<double>> phasor;  // e^{−2πin/M}
  double decay;                              // e^{−γh}
  std::array<double, 4> psi;                 // ∫₀ʰ e^{−γ(h−s)} s^j ds
  // measurement delay
  enum class DelayMode { Grid, FixedInterpolation, Varying } delay_mode;
  long delay_steps;        // Grid
  long fixed_j0;           // FixedInterpolation: nodes n + fixed_j0 .. +3
  std::array<double, 4> fixed_w;
  long max_back;
};

struct LastPeriod {
  std::vector<double> y, u;  // samples of the last period (empty if the run diverged)
};

template <class Stepper>
void run_loop(Stepper& ctrl, const LoopContext& cx, SimulationResult& res, LastPeriod& last,
              const SimulationProgress& progress, const SampleSink& sink) {
  const Plant& plant = *cx.plant;
  const int M = cx.M;
  const double h = cx.h, gamma = plant.rate;
  History y_hist(cx.max_back);
  for (long j = -cx.max_back; j < 0; ++j) y_hist[j] = uncontrolled_output(plant, static_cast<double>(j) * h);
  double y = uncontrolled_output(plant, 0.0);

  auto& rep = res.report;
  auto& ser = res.series;
  std::vector<double> last_y(M), last_u(M);
  if (cx.record_every > 0 && !sink) {
    const std::size_t n_rec = static_cast<std::size_t>(cx.total / cx.record_every + 1);
    for (auto* v : {&ser.t, &ser.y, &ser.u, &ser.m, &ser.target, &ser.f_minus_first}) v->reserve(n_rec);
  }
  rep.envelope.reserve(static_cast<std::size_t>(cx.total / M));
  std::complex<double> acc = 0.0;
  detail::OutputPolynomial poly{};
  const long last_start = cx.total - M;
  long n = 0;
  long i = 0;  // n mod M
  for (; n < cx.total; ++n, i = (i + 1 == M ? 0 : i + 1)) {
    const double t = static_cast<double>(n) * h;
    const double u = ctrl.output();
    if (!cx.first_order) y = cx.f[i] + u / gamma;  // eq. 3
    if (!(std::abs(y) < 1e100)) {
      rep.diverged = true;
      break;
    }
    y_hist[n] = y;
    double m;
    switch (cx.delay_mode) {
      case LoopContext::DelayMode::Grid:
        m = y_hist[n - cx.delay_steps];
        break;
      case LoopContext::DelayMode::FixedInterpolation: {
        const long j0 = n + cx.fixed_j0;
        m = cx.fixed_w[0] * y_hist[j0] + cx.fixed_w[1] * y_hist[j0 + 1] + cx.fixed_w[2] * y_hist[j0 + 2] +
            cx.fixed_w[3] * y_hist[j0 + 3];
        break;
      }
      default: {
        const double s = static_cast<double>(n) - plant.delay_at(t) / h;
        long j0 = static_cast<long>(std::floor(s)) - 1;
        j0 = std::min(j0, n - 3);
        const auto w = lagrange4(j0, s);
        m = w[0] * y_hist[j0] + w[1] * y_hist[j0 + 1] + w[2] * y_hist[j0 + 2] + w[3] * y_hist[j0 + 3];
      }
    }
    ctrl.step(m, cx.first_order ? &poly : nullptr);
    if (cx.record_every > 0 && n % cx.record_every == 0 && sink) {
      sink(TimeSample{t, y, u, m, cx.target[i], cx.f_minus_first[i]});
    } else if (cx.record_every > 0 && n % cx.record_every == 0) {
      ser.t.push_back(t);
      ser.y.push_back(y);
      ser.u.push_back(u);
      ser.m.push_back(m);
      ser.target.push_back(cx.target[i]);
      ser.f_minus_first.push_back(cx.f_minus_first[i]);
    }
    acc += y * cx.phasor[i];
    if (n >= last_start) {
      last_y[n - last_start] = y;
      last_u[n - last_start] = u;
    }
    if (i == M - 1) {
      rep.envelope.push_back(std::abs(2.0 * acc / static_cast<double>(M)));
      acc = 0.0;
      if (progress) progress(n / M + 1, cx.total / M);
    }
    if (cx.first_order) {  // exact step of eq. (1) for the cubic u and the trigonometric f
      y = cx.decay * y + cx.forcing[i] + poly[0] * cx.psi[0] + poly[1] * cx.psi[1] + poly[2] * cx.psi[2] +
          poly[3] * cx.psi[3];
    }
  }
  rep.periods_completed = static_cast<int>(n / M);
  if (!rep.diverged) {
    last.y = std::move(last_y);
    last.u = std::move(last_u);
  }
}

LoopContext make_context(const Plant& plant, const SimulationOptions& o, std::span<const int> rejected) {
  LoopContext cx{};
  cx.plant = &plant;
  cx.M = o.steps_per_period;
  cx.total = static_cast<long>(o.periods) * o.steps_per_period;
  cx.h = plant.period() / o.steps_per_period;
  cx.record_every = o.record_every;
  cx.first_order = plant.kind == PlantKind::FirstOrder;
  const int M = cx.M;
  const double h = cx.h, g = plant.rate, w = plant.rotation_frequency;
  const Disturbance& f = plant.disturbance;
  cx.f.resize(M);
  cx.target.resize(M);
  cx.f_minus_first.resize(M);
  cx.phasor.resize(M);
  cx.forcing.assign(M, 0.0);
  cx.decay = std::exp(-g * h);
  double fact = 1.0;
  for (int j = 0; j < 4; ++j) {
    if (j > 0) fact *= j;
    cx.psi[j] = fact * std::pow(h, j + 1) * phi_function(j + 1, -g * h);
  }
  // e^{2πij/M}: every harmonic of the grid tables is a lookup (index k·i mod M), no trigonometry per entry
  std::vector<std::complex<double>> unit(M);
  for (int j = 0; j < M; ++j) unit[j] = std::polar(1.0, 2.0 * std::numbers::pi * j / M);
  struct Term {
    int k;
    std::complex<double> f, target, forcing;  // amplitudes of e^{ikθ} (real part taken)
  };
  std::vector<Term> terms;
  for (const auto& hk : f.harmonics) {
    const std::complex<double> fk = disturbance_harmonic(hk);
    const bool rej = std::find(rejected.begin(), rejected.end(), hk.order) != rejected.end();
    // ∫₀ʰ e^{−γ(h−s)} γ e^{ikΩs} ds = γ (e^{ikΩh} − e^{−γh})/(γ + ikΩ)
    const std::complex<double> gain =
        g * (std::polar(1.0, hk.order * w * h) - cx.decay) / std::complex<double>(g, hk.order * w);
    terms.push_back({hk.order, fk, rej ? 0.0 : uncontrolled_harmonic(plant, hk), fk * gain});
  }
  const std::complex<double> f1 = disturbance_harmonic(f, 1);
  for (int i = 0; i < M; ++i) {
    double fv = f.offset, tv = f.offset, fo = f.offset * (1.0 - cx.decay);
    for (const Term& term : terms) {
      const std::complex<double> e = unit[(static_cast<long>(term.k) * i) % M];
      fv += (term.f * e).real();
      tv += (term.target * e).real();
      fo += (term.forcing * e).real();
    }
    cx.f[i] = fv;
    cx.target[i] = tv;
    cx.f_minus_first[i] = fv - (f1 * unit[i]).real();
    cx.phasor[i] = std::conj(unit[i]);
    if (cx.first_order) cx.forcing[i] = fo;
  }
  const bool constant = plant.delay_variation == 0.0 || plant.delay_variation_frequency == 0.0;
  cx.max_back = static_cast<long>(std::ceil((plant.delay + plant.delay_variation) / h)) + 8;
  if (constant) {
    const double r = plant.delay / h;
    const double rr = std::round(r);
    if (std::abs(r - rr) <= 1e-9 * std::max(1.0, r)) {
      cx.delay_mode = LoopContext::DelayMode::Grid;
      cx.delay_steps = static_cast<long>(rr);
    } else {
      cx.delay_mode = LoopContext::DelayMode::FixedInterpolation;
      cx.fixed_j0 = std::min(static_cast<long>(std::floor(-r)) - 1, -3L);
      cx.fixed_w = lagrange4(cx.fixed_j0, -r);
    }
  } else {
    cx.delay_mode = LoopContext::DelayMode::Varying;
  }
  return cx;
}

}  // namespace

ClosedLoopSimulation::ClosedLoopSimulation(Plant plant, Bank controller, SimulationOptions options)
    : plant_(std::move(plant)), controller_(std::move(controller)), options_(options) {
  const auto& o = options_;
  validate::in_range("periods", static_cast<long>(o.periods), 1L, 100000000L);
  validate::in_range("steps_per_period", static_cast<long>(o.steps_per_period), 8L, 100000000L);
  validate::in_range("record_every", static_cast<long>(o.record_every), 0L, 1000000000L);
  if (o.record_every > 0) {
    const double rows = static_cast<double>(o.periods) * o.steps_per_period / o.record_every;
    if (rows > 5e7)
      throw InvalidParameter("record_every",
                             fmt::format("record_every = {} is out of range: the run would record {:.3g} rows of the time "
                                         "series; must be >= {} (at most 5e7 rows) or 0 (no time series)",
                                         o.record_every, rows,
                                         static_cast<long>(std::ceil(static_cast<double>(o.periods) *
                                                                     o.steps_per_period / 5e7))));
  }
  if (o.report_max_order < 0 || 2L * o.report_max_order >= o.steps_per_period)
    throw InvalidParameter("report_max_order",
                           fmt::format("report_max_order = {} is out of range: must be an integer in [0, {}] (below "
                                       "half of steps_per_period = {})",
                                       o.report_max_order, (o.steps_per_period - 1) / 2, o.steps_per_period));
  const bool infinite = std::holds_alternative<InfiniteBank>(controller_);
  int highest = max_disturbance_order(plant_.disturbance);
  if (!infinite) highest = std::max(highest, std::get<OscillatorBank>(controller_).harmonics());
  highest = std::max(highest, 1);
  if (o.steps_per_period <= 2 * highest)
    throw InvalidParameter("steps_per_period",
                           fmt::format("steps_per_period = {} is out of range: must be > {} (Nyquist: more than two "
                                       "samples per period of harmonic {}, the highest of the controller and of f)",
                                       o.steps_per_period, 2 * highest, highest));
  if (infinite) {
    const auto& ib = std::get<InfiniteBank>(controller_);
    if (o.stepping != ControllerStepping::AdamsBashforth3)
      throw InvalidParameter("stepping", fmt::format("stepping = {} is not available for the N = infinity controller: "
                                                     "must be ab3 (the neutral realisation, eqs. 32-33, is stepped by "
                                                     "AB3)", to_string(o.stepping)));
    validate::require(ib.alpha > 0.0, "alpha", ib.alpha,
                      "> 0 for the N = infinity neutral realisation (|B4/A4| < 1, docs/theory-control.md#infinite-bank)");
    const double wc = ib.rotation_frequency, wp = plant_.rotation_frequency;
    validate::require(std::abs(wc - wp) <= 1e-12 * wp, "rotation_frequency", wc,
                      fmt::format("equal to the plant's rotation frequency {} for the N = infinity controller (its "
                                  "delay lines are one period of the grid)", wp));
  }
  if (o.stepping == ControllerStepping::AdamsBashforth3) {
    const Eigen::VectorXcd ev = controller_modes(controller_);
    const double h = step();
    for (Eigen::Index i = 0; i < ev.size(); ++i) {
      if (!ab3::is_stable(h * ev(i))) {
        const long need = ab3::minimum_steps(ev, plant_.period());
        throw InvalidParameter(
            "steps_per_period",
            fmt::format("steps_per_period = {} is out of range: must be >= {} for AB3 (h*lambda = {:.4g}{:+.4g}i for "
                        "the controller mode lambda = {:.4g}{:+.4g}i lies outside the AB3 stability region, which "
                        "reaches {:.4f} on the real axis and +-{:.4f}i on the imaginary axis)",
                        o.steps_per_period, need, (h * ev(i)).real(), (h * ev(i)).imag(), ev(i).real(),
                        ev(i).imag(), ab3::real_axis_limit(), ab3::imaginary_axis_limit()));
      }
    }
  }
}

double ClosedLoopSimulation::step() const { return plant_.period() / options_.steps_per_period; }

std::vector<int> ClosedLoopSimulation::rejected() const {
  if (const auto* ob = std::get_if<OscillatorBank>(&controller_)) return ob->rejected();
  return {1};
}

SimulationResult ClosedLoopSimulation::run(const SimulationProgress& progress, const SampleSink& sink) const {
  const std::vector<int> rej = rejected();
  const LoopContext cx = make_context(plant_, options_, rej);
  SimulationResult res;
  LastPeriod last;
  auto& rep = res.report;
  rep.step = cx.h;
  rep.steps_per_period = cx.M;
  rep.delay_exceeds_period = plant_.delay_exceeds_period();
  if (const auto* ob = std::get_if<OscillatorBank>(&controller_)) {
    if (options_.stepping == ControllerStepping::ZeroOrderHold) {
      detail::BankZoh c(*ob, cx.h);
      run_loop(c, cx, res, last, progress, sink);
    } else if (options_.stepping == ControllerStepping::BlockZeroOrderHold) {
      detail::BankBlockZoh c(*ob, cx.h);
      run_loop(c, cx, res, last, progress, sink);
    } else {
      detail::BankAb3 c(*ob, cx.h);
      run_loop(c, cx, res, last, progress, sink);
    }
  } else {
    detail::NeutralAb3 c(std::get<InfiniteBank>(controller_), cx.M, cx.h);
    run_loop(c, cx, res, last, progress, sink);
  }
  const EnvelopeFit fit = fit_log_envelope(rep.envelope, plant_.period());
  rep.growth_rate = fit.growth_rate;
  rep.fit_first_period = fit.first_period;
  rep.fit_last_period = fit.last_period;
  if (rep.diverged || last.y.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    rep.first_harmonic = {nan, nan};
    rep.residual_first_harmonic = std::numeric_limits<double>::infinity();
    rep.max_harmonic_error = std::numeric_limits<double>::infinity();
    rep.max_harmonic_error_above = std::numeric_limits<double>::infinity();
    rep.control_first_harmonic = {nan, nan};
    return res;
  }
  int bank_order = std::max(max_disturbance_order(plant_.disturbance), 1);
  if (const auto* ob = std::get_if<OscillatorBank>(&controller_)) bank_order = ob->harmonics();
  rep.bank_max_order = bank_order;
  const int kmax = std::max(options_.report_max_order > 0 ? options_.report_max_order : bank_order, 1);
  const auto cy = fourier_coefficients(last.y, kmax);
  rep.first_harmonic = cy[1];
  rep.residual_first_harmonic = std::abs(cy[1]);
  rep.control_first_harmonic = fourier_coefficients(last.u, 1)[1];
  const bool first_rejected = std::find(rej.begin(), rej.end(), 1) != rej.end();
  rep.max_harmonic_error = 0.0;
  rep.max_harmonic_error_above = kmax > bank_order ? 0.0 : std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k <= kmax; ++k) {
    if (k == 1 && first_rejected) continue;
    const bool is_rej = std::find(rej.begin(), rej.end(), k) != rej.end();
    const std::complex<double> target = is_rej ? 0.0 : uncontrolled_harmonic(plant_, k);
    const double err = std::abs(cy[k] - target);
    rep.harmonics.push_back({k, cy[k], target, err});
    double& worst = k <= bank_order ? rep.max_harmonic_error : rep.max_harmonic_error_above;
    worst = std::max(worst, err);
  }
  return res;
}

SimulationResult simulate_closed_loop(const Plant& plant, const Bank& controller, const SimulationOptions& options) {
  return ClosedLoopSimulation(plant, controller, options).run();
}

}  // namespace afmkit::control
