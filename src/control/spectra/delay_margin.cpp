// Delay margin from the crossing conditions (delay_margin.hpp; seed-2 ext. E1/E2, docs/theory-control.md#delay-margin).
#include "afmkit/control/delay_margin.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <boost/math/tools/toms748_solve.hpp>
#include <fmt/format.h>

#include "afmkit/core/numbers.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/control/stability_tau0.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "fast_characteristic.hpp"
#include "spectra_detail.hpp"

namespace afmkit::control {

using spectra_detail::cplx;

namespace {
using afmkit::numbers::two_pi;
using afmkit::numbers::infinity;

// τ0 ∈ (0, 2π/ν]: the smallest positive delay with e^{−iντ} = w.
DelayCrossing crossing_from_phase(double nu, cplx w) {
  double t = std::fmod(-std::arg(w), two_pi);
  if (t <= 1e-14) t += two_pi;
  return {nu, t / nu, two_pi / nu};
}

bool is_single_oscillator(const LoopSpec& loop) {
  const auto* b = std::get_if<OscillatorBank>(&loop.controller);
  return b && b->harmonics() == 1 && b->a0() == 0.0 && loop.plant_kind == PlantKind::Static;
}

// Δ(iν; τ)/Q(iν) = X + Y e^{−iντ} (fast_characteristic.hpp); G = (|X|² − |Y|²)/(|X|² + |Y|²) ∈ [−1, 1]
// (the normaliser Q cancels; G stays bounded next to the oscillator poles).
class CrossingFunction {
 public:
  explicit CrossingFunction(const LoopSpec& loop) : f_(loop) {}
  void xy(double nu, cplx& x, cplx& y) const { f_.crossing_parts(nu, x, y); }
  double g(double nu) const {
    cplx x, y;
    f_.crossing_parts(nu, x, y);
    const double ax = std::norm(x), ay = std::norm(y);
    return (ax - ay) / (ax + ay);
  }

 private:
  spectra_detail::FastCharacteristic f_;
};

// Unstable roots at the reference delay: closed-loop eigenvalues for a plain finite bank at τ = 0 (polynomial
// case), the argument principle otherwise.
UnstableCount reference_count(const LoopSpec& loop) {
  const bool finite_plain = std::holds_alternative<OscillatorBank>(loop.controller);
  if (!(finite_plain && loop.delay == 0.0)) return unstable_roots(loop);
  UnstableCount u;
  const double omega = loop.rotation_frequency();
  for (const auto& e : undelayed_poles(loop)) {
    if (std::abs(e.real()) <= 1e-11 * (omega + std::abs(e))) u.marginal = true;
    else if (e.real() > 0.0) ++u.count;
  }
  return u;
}
}  // namespace

std::vector<DelayCrossing> single_oscillator_crossings(double a, double b, double kappa, double omega) {
  validate::finite("a", a);
  validate::finite("b", b);
  validate::positive("gain_ratio", kappa);
  validate::positive("rotation_frequency", omega);
  std::vector<DelayCrossing> out;
  const double p = 2.0 * omega * omega + kappa * kappa * a * a;
  const double q = omega * omega * omega * omega - kappa * kappa * b * b * omega * omega;
  const double disc = p * p - 4.0 * q;
  if (disc < 0.0 || (a == 0.0 && b == 0.0)) return out;
  for (double sg : {-1.0, 1.0}) {
    const double nu2 = 0.5 * (p + sg * std::sqrt(disc));
    if (nu2 <= 0.0) continue;
    if (sg > 0 && disc == 0.0) continue;
    const double nu = std::sqrt(nu2);
    const cplx w = (nu2 - omega * omega) / (kappa * cplx(-b * omega, a * nu));  // e^{−iντ}, ext. E1
    out.push_back(crossing_from_phase(nu, w));
  }
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return x.frequency < y.frequency; });
  return out;
}

std::vector<DelayCrossing> delay_crossings(const LoopSpec& loop, const MarginOptions& o) {
  const double omega = loop.rotation_frequency();
  validate::in_range("grid_points_per_omega", static_cast<long>(o.grid_points_per_omega), 4L, 100000L);
  double nu_max = o.max_frequency;
  if (!std::isnan(nu_max)) {
    validate::positive("max_frequency", nu_max);
  } else {
    const RootBounds rb = root_bounds(loop, 0.0);
    const auto v = spectra_detail::view(loop);
    nu_max = rb.proven ? rb.imag_max : ((v.bank ? v.bank->harmonics() : 1) + 20) * omega;
  }
  const CrossingFunction f(loop);
  const double h = omega / o.grid_points_per_omega;
  const long steps = static_cast<long>(std::ceil(nu_max / h));
  std::vector<DelayCrossing> out;
  double nu_prev = 1e-6 * omega, g_prev = f.g(nu_prev);
  for (long k = 1; k <= steps; ++k) {
    const double nu = std::min((k + 0.0137) * h, nu_max);  // offset: never exactly on an oscillator pole kΩ
    const double g = f.g(nu);
    double root = std::numeric_limits<double>::quiet_NaN();
    if (g == 0.0) {
      root = nu;
    } else if (g_prev * g < 0.0) {
      std::uintmax_t it = 100;
      const auto tol = [omega](double lo, double hi) { return std::abs(hi - lo) <= 1e-15 * std::max(omega, hi); };
      const auto r = boost::math::tools::toms748_solve([&f](double x) { return f.g(x); }, nu_prev, nu, g_prev, g, tol, it);
      root = 0.5 * (r.first + r.second);
    }
    if (!std::isnan(root)) {
      cplx x, y;
      f.xy(root, x, y);
      out.push_back(crossing_from_phase(root, -x / y));
    }
    nu_prev = nu;
    g_prev = g;
  }
  return out;
}

DelayMargin delay_margin(const LoopSpec& loop, const MarginOptions& o) {
  const double period = loop.period();
  const bool smith = std::holds_alternative<SmithPredictor>(loop.controller);
  validate::in_range("grid_points_per_omega", static_cast<long>(o.grid_points_per_omega), 4L, 100000L);
  if (!std::isnan(o.max_frequency)) validate::positive("max_frequency", o.max_frequency);
  DelayMargin m;
  m.reference_delay = std::isnan(o.reference_delay)
                          ? (smith ? std::get<SmithPredictor>(loop.controller).model_delay : 0.0)
                          : validate::non_negative("reference_delay", o.reference_delay);
  const LoopSpec at_ref = loop.with_delay(m.reference_delay);
  if (o.check_reference) {
    const UnstableCount u = reference_count(at_ref);
    m.unstable_at_reference = u.count;
    m.marginal_at_reference = u.marginal;
    m.stable_at_reference = u.count == 0 && !u.marginal;
  } else {
    m.stable_at_reference = true;
  }
  const bool closed_form = o.use_closed_form && !smith && is_single_oscillator(loop);
  m.method = closed_form ? "E1" : "E2";
  if (!m.stable_at_reference) {
    m.note = "not stable at the reference delay: no delay margin";
    if (m.unstable_at_reference < 0) m.note += " (neutral chain of roots in Re s >= 0: alpha <= 0)";
    else if (m.marginal_at_reference) m.note += " (roots on the imaginary axis)";
    else m.note += fmt::format(" ({} unstable roots)", m.unstable_at_reference);
    return m;
  }
  if (closed_form) {
    const auto& b = std::get<OscillatorBank>(loop.controller);
    m.crossings = single_oscillator_crossings(b.a(1), b.b(1), loop.gain_ratio(), loop.rotation_frequency());
  } else {
    m.crossings = delay_crossings(loop, o);
  }
  const double ref = m.reference_delay;
  m.upper = infinity;
  m.lower = 0.0;
  bool lower_found = false;
  for (const auto& c : m.crossings) {
    // smallest crossing delay > ref
    double k = std::ceil((ref - c.first_delay) / c.delay_period);
    if (k < 0) k = 0;
    double up = c.first_delay + k * c.delay_period;
    if (up <= ref) up += c.delay_period;
    if (up < m.upper) {
      m.upper = up;
      m.upper_frequency = c.frequency;
    }
    // largest crossing delay < ref
    if (ref > c.first_delay) {
      double dn = c.first_delay + std::floor((ref - c.first_delay) / c.delay_period) * c.delay_period;
      if (dn >= ref) dn -= c.delay_period;
      if (dn > 0 && (!lower_found || dn > m.lower)) {
        m.lower = dn;
        m.lower_frequency = c.frequency;
        lower_found = true;
      }
    }
  }
  m.upper_exceeds_period = m.upper >= period;
  if (m.crossings.empty()) m.note = "no crossing frequency: stable for every delay";
  else if (m.upper_exceeds_period) m.note = "critical delay >= T (outside the paper's assumption tau < T)";
  return m;
}

}  // namespace afmkit::control
