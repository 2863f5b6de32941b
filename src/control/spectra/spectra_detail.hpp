#pragma once
// Private to src/control/spectra: evaluation of Δ and Δ' (loop.hpp), the argument principle with adaptive
// steps, Newton refinement, argument-principle subdivision search, and loop inspection helpers.
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "afmkit/control/loop.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/control/spectrum.hpp"
#include "fast_characteristic.hpp"

namespace afmkit::control::spectra_detail {

using cplx = std::complex<double>;

/// Δ and Δ' up to a common positive factor (only ratios and phases are used).
struct Eval {
  cplx v, d;
};

/// Δ and Δ' of a loop: the fast plain-complex evaluation (fast_characteristic.hpp, same scale as loop.hpp's
/// characteristic()), falling back to the scaled evaluation of loop.hpp where it is not finite.
/// Holds a reference to the loop: it must outlive the evaluator.
class Evaluator {
 public:
  explicit Evaluator(const LoopSpec& loop) : loop_(&loop), fast_(loop), omega_(loop.rotation_frequency()) {}
  Eval operator()(cplx s) const {
    cplx v, d;
    fast_.entire(s, v, d);
    if (std::isfinite(v.real()) && std::isfinite(v.imag()) && std::isfinite(d.real()) && std::isfinite(d.imag()) &&
        v != 0.0)
      return {v, d};
    const ScaledCharacteristic c = characteristic_scaled(*loop_, s);
    return {c.value, c.derivative};
  }
  const LoopSpec& loop() const { return *loop_; }
  double omega() const { return omega_; }

 private:
  const LoopSpec* loop_;
  FastCharacteristic fast_;
  double omega_;
};

/// The parts of a loop needed by the bounds and the neutral diagnosis.
struct LoopView {
  const OscillatorBank* bank = nullptr;    // finite bank (plain or inside the Smith predictor)
  const InfiniteBank* infinite = nullptr;  // N = ∞ bank (plain or inside the Smith predictor)
  const SmithPredictor* smith = nullptr;
  double omega = 1.0;
};
LoopView view(const LoopSpec& loop);

/// Result of a winding-number computation.
struct Winding {
  bool ok = false;      // false: a zero on (or within rounding of) the boundary, or a non-integer total
  int count = 0;
  long evaluations = 0;
};

/// Winding number of f along the positively oriented boundary of `box`. f(s) returns Eval (value, derivative).
/// Steps are accepted when the phase increment is ≤ 0.5 rad, agrees with the trapezoidal prediction
/// Im ∫ f'/f ds to 0.1 rad, and the step is at most half the Newton distance |f/f'| at both ends (so that no
/// zero can hide next to the step); otherwise halved. `scale` is the frequency scale (Ω) for the minimal step.
template <class F>
Winding winding(F&& f, const Box& box, double scale) {
  const cplx corners[4] = {{box.real_min, box.imag_min},
                           {box.real_max, box.imag_min},
                           {box.real_max, box.imag_max},
                           {box.real_min, box.imag_max}};
  Winding w;
  double total = 0.0;
  const double min_step = 1e-13 * std::max(scale, std::abs(corners[2]) + std::abs(corners[0]));
  for (int e = 0; e < 4; ++e) {
    const cplx a = corners[e], b = corners[(e + 1) % 4];
    const double length = std::abs(b - a);
    if (length == 0.0) continue;
    Eval cur = f(a);
    ++w.evaluations;
    if (!(std::isfinite(cur.v.real()) && std::isfinite(cur.v.imag())) || cur.v == 0.0) return w;
    double t = 0.0, h = std::min(0.25, 0.5 * scale / length);
    while (t < 1.0) {
      const double tn = std::min(1.0, t + h);
      const cplx ds = (b - a) * (tn - t);
      const Eval nxt = f(a + (b - a) * tn);
      ++w.evaluations;
      if (!(std::isfinite(nxt.v.real()) && std::isfinite(nxt.v.imag())) || nxt.v == 0.0) return w;
      const double dphi = std::arg(nxt.v / cur.v);
      const cplx lc = cur.d / cur.v, ln = nxt.d / nxt.v;  // logarithmic derivatives
      const double pred = 0.5 * std::imag((lc + ln) * ds);
      // a step longer than half the Newton distance |f/f'| at either end could pass next to a zero unseen
      const double reach = 0.5 / std::max(std::abs(lc), std::abs(ln));
      if (std::abs(dphi) > 0.5 || std::abs(dphi - pred) > 0.1 || !std::isfinite(pred) || std::abs(ds) > reach) {
        h *= 0.5;
        if (h * length < min_step) return w;  // zero on the boundary
        continue;
      }
      total += dphi;
      t = tn;
      cur = nxt;
      h = std::min(1.0, 1.6 * h);
    }
  }
  const double turns = total / (2.0 * std::numbers::pi);
  const double rounded = std::round(turns);
  if (std::abs(turns - rounded) > 0.05) return w;
  w.ok = true;
  w.count = static_cast<int>(rounded);
  return w;
}

/// Winding of Δ of the loop.
Winding winding(const Evaluator& f, const Box& box);

/// Newton on Δ with step limiting. `multiplicity` > 1 uses the modified step m·Δ/Δ'.
struct NewtonResult {
  cplx root;
  bool converged = false;
  double correction = 0.0;
  int iterations = 0;
};
NewtonResult newton(const Evaluator& f, cplx guess, double tolerance, int max_iterations = 80,
                    int multiplicity = 1);

/// All roots in `box` (which must contain exactly `count` roots, from a previous winding computation), by
/// recursive bisection with argument-principle counts and Newton from box centres. Appends (root, multiplicity).
void subdivision_search(const Evaluator& f, const Box& box, int count, double tolerance,
                        std::vector<std::pair<cplx, int>>& out);

/// Argument-principle count with automatic nudging of the box edges (up to 6 attempts) if a root lies on the
/// boundary; `box` is updated to the box actually used. Returns false if every attempt failed.
bool robust_count(const Evaluator& f, Box& box, int& count);

/// Banks with more oscillators than this get their initial root guesses from the delay-free poles (Aberth,
/// O(N²)) instead of the dense Chebyshev collocation (O((2N + nodes)³)).
inline constexpr int kCollocationMaxHarmonics = 40;
/// Initial guesses for a finite bank without dense matrices: the delay-free closed-loop poles
/// (undelayed_poles, stability_tau0.hpp), each continued by Newton on Δ of the delayed loop; upper half-plane
/// and real axis, distinct. O(N) per evaluation, O(N) starts: O(N²).
/// `limit`: continue only the `limit` rightmost delay-free poles (root tracking keeps a few rightmost roots).
std::vector<cplx> delay_free_continuation(const Evaluator& f, double tolerance,
                                          std::size_t limit = static_cast<std::size_t>(-1));

/// Merge `s` into `roots` unless a root within `radius` is already present.
bool add_unique(std::vector<cplx>& roots, cplx s, double radius);

/// The (x, y) window of a chart or a tuning search: finite bounds, x_min < x_max, y_min < y_max.
inline void validate_window(double x_min, double x_max, double y_min, double y_max) {
  validate::finite("x_min", x_min);
  validate::finite("x_max", x_max);
  validate::finite("y_min", y_min);
  validate::finite("y_max", y_max);
  validate::require(x_max > x_min, "x_max", x_max, "> x_min");
  validate::require(y_max > y_min, "y_max", y_max, "> y_min");
}

}  // namespace afmkit::control::spectra_detail
