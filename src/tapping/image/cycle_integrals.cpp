// One drive cycle's integrals for the time-domain imaging engine (cycle_integrals.hpp).
#include "afmkit/tapping/image/cycle_integrals.hpp"

#include <algorithm>
#include <cmath>

#include "afmkit/tapping/events.hpp"
#include "afmkit/tapping/gauss_panels.hpp"
#include "afmkit/tapping/system.hpp"
#include "../sim/small_angle.hpp"

namespace afmkit::tapping::image {

void CycleIntegrals::force_at(const TappingSystem& system, const Mode& m, const TipState& s) {
  peak_force = std::max(peak_force, 0.0 - system.interaction(m.branch, s.position, s.velocity, m.region));
}

void CycleIntegrals::on_segment(const TappingSystem& system, const Segment& segment) {
  const double t0 = segment.t_begin(), t1 = segment.t_end();
  if (!(t1 > t0)) return;
  // the panels' rotations e^{iu}, |u| <= ω · panel / 2 = π/16: the series (exact to rounding) instead of sincos
  const auto phasor = [](double u) {
    return std::abs(u) <= tapping::detail::small_angle_limit ? tapping::detail::small_angle_phasor(u)
                                                             : std::polar(1.0, u);
  };
  // a whole step of DOP853: its own stages and weights (order 8, no dense output); e^{−iωt} = e^{−iω mid} e^{−iω(t − mid)}
  struct Stages final : StageVisitor {
    double omega, mid;
    std::complex<double> e_mid, harmonic{};
    double square = 0.0;
    Stages(double w, double m) : omega(w), mid(m), e_mid(std::polar(1.0, -w * m)) {}
    void node(double t, double w, const TipState& s) override {
      harmonic += (w * s.position) * tapping::detail::stage_rotation(-omega * (t - mid));
      square += w * s.velocity * s.velocity;
    }
  } stages(system.drive_frequency(), 0.5 * (t0 + t1));
  if (segment.stage_quadrature(stages)) {
    first_harmonic += stages.harmonic * stages.e_mid;
    velocity_square += stages.square;
  } else {
    gauss_panels<7>(
        t0, t1, panel_, system.drive_frequency(), phasor,
        [&](double t, double w, std::complex<double> e) {  // e = e^{−iωt}
          const TipState s = segment.state(t);
          first_harmonic += (w * s.position) * e;
          velocity_square += w * s.velocity * s.velocity;
        },
        [](double, double) {});
  }
  // the largest force: at the ends, and at the bottom of the motion (ẋ rising through 0) inside the segment. A step
  // that continues the last one (same mode, from its end) starts where the force was taken already.
  const Mode m = segment.mode();
  const TipState s0 = segment.state(t0), s1 = segment.state(t1);
  if (!(t0 == last_end_ && m == last_mode_)) force_at(system, m, s0);
  force_at(system, m, s1);
  last_end_ = t1;
  last_mode_ = m;
  if (s0.velocity < 0.0 && s1.velocity > 0.0) {
    auto rate = [&](double t) { return segment.state(t).velocity; };
    const double tb = isolate_crossing(rate, t0, t1, CrossingDirection::rising, 1e-15 * std::max(1.0, std::abs(t1)));
    force_at(system, m, segment.state(tb));
  }
}

}  // namespace afmkit::tapping::image
