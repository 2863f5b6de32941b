// One drive cycle's integrals for the time-domain imaging engine (cycle_integrals.hpp).
#include "afmkit/tapping/image/cycle_integrals.hpp"

#include <algorithm>
#include <cmath>

#include "afmkit/tapping/events.hpp"
#include "afmkit/tapping/gauss_panels.hpp"
#include "afmkit/tapping/system.hpp"

namespace afmkit::tapping::image {

void CycleIntegrals::force_at(const TappingSystem& system, const Segment& segment, double t) {
  const TipState s = segment.state(t);
  const Mode m = segment.mode();
  peak_force = std::max(peak_force, 0.0 - system.interaction(m.branch, s.position, s.velocity, m.region));
}

void CycleIntegrals::on_segment(const TappingSystem& system, const Segment& segment) {
  const double t0 = segment.t_begin(), t1 = segment.t_end();
  if (!(t1 > t0)) return;
  gauss_panels<7>(
      t0, t1, panel_, system.drive_frequency(), [](double u) { return std::polar(1.0, u); },
      [&](double t, double w, std::complex<double> e) {  // e = e^{−iωt}
        const TipState s = segment.state(t);
        first_harmonic += (w * s.position) * e;
        velocity_square += w * s.velocity * s.velocity;
      },
      [](double, double) {});
  // the largest force: at the ends, and at the bottom of the motion (ẋ rising through 0) inside the segment
  force_at(system, segment, t0);
  force_at(system, segment, t1);
  const double va = segment.state(t0).velocity, vb = segment.state(t1).velocity;
  if (va < 0.0 && vb > 0.0) {
    auto rate = [&](double t) { return segment.state(t).velocity; };
    force_at(system, segment,
             isolate_crossing(rate, t0, t1, CrossingDirection::rising, 1e-15 * std::max(1.0, std::abs(t1))));
  }
}

}  // namespace afmkit::tapping::image
