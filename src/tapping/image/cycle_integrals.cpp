// One drive cycle's integrals for the time-domain imaging engine (cycle_integrals.hpp).
#include "afmkit/tapping/image/cycle_integrals.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <boost/math/quadrature/gauss.hpp>

#include "afmkit/tapping/events.hpp"
#include "afmkit/tapping/system.hpp"

namespace afmkit::tapping::image {

void CycleIntegrals::force_at(const TappingSystem& system, const Segment& segment, double t) {
  const TipState s = segment.state(t);
  const Mode m = segment.mode();
  peak_force = std::max(peak_force, 0.0 - system.interaction(m.branch, s.position, s.velocity, m.region));
}

void CycleIntegrals::on_segment(const TappingSystem& system, const Segment& segment) {
  using Rule = boost::math::quadrature::gauss<double, 5>;  // nodes 0, ±ξ1, ±ξ2
  const auto& nodes = Rule::abscissa();
  const auto& weights = Rule::weights();
  const double t0 = segment.t_begin(), t1 = segment.t_end();
  if (!(t1 > t0)) return;
  const double omega = system.drive_frequency();
  const int panels = std::max(1, static_cast<int>(std::ceil((t1 - t0) / panel_)));
  const double width = (t1 - t0) / panels;
  std::array<std::complex<double>, 3> rotation{};  // e^{−iω half ξ_i}
  for (std::size_t i = 0; i < nodes.size(); ++i) rotation[i] = std::polar(1.0, -omega * 0.5 * width * nodes[i]);
  for (int p = 0; p < panels; ++p) {
    const double a = t0 + p * width, b = (p + 1 == panels) ? t1 : a + width;
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    const std::complex<double> e_mid = std::polar(1.0, -omega * mid);
    const auto add = [&](double t, double w, std::complex<double> e) {
      const TipState s = segment.state(t);
      first_harmonic += (w * s.position) * e;
      velocity_square += w * s.velocity * s.velocity;
    };
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if (nodes[i] == 0.0) {
        add(mid, half * weights[i], e_mid);
      } else {
        add(mid - half * nodes[i], half * weights[i], e_mid * std::conj(rotation[i]));
        add(mid + half * nodes[i], half * weights[i], e_mid * rotation[i]);
      }
    }
  }
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
