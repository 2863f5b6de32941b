#pragma once
// Gauss–Legendre quadrature over a smooth segment of trajectory against the drive's phasor (the observers'
// integrals, observer.hpp, and the time-domain imaging engine's lock-in): panels no longer than `max_panel`,
// `Points` nodes each; every node gets its weight and e^{−iωt}, from one phasor per panel times rotations that all
// panels share (equal widths; the last one's rounding difference is below 1e-16).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>

#include <boost/math/quadrature/gauss.hpp>

namespace afmkit::tapping {

/// `Points`: a rule Boost tabulates (7, 10, 15, 20, 25, 30: no computation at run time).
/// Calls node(t, weight, e^{−iωt}) at every node of every panel of [t0, t1] (t1 > t0), then panel_done(a, b) after
/// each panel [a, b]. `phasor(u)` answers e^{iu} for the rotations (std::polar, or a series for small angles).
template <int Points, class Phasor, class Node, class PanelDone>
void gauss_panels(double t0, double t1, double max_panel, double omega, Phasor&& phasor, Node&& node,
                  PanelDone&& panel_done) {
  using Rule = boost::math::quadrature::gauss<double, Points>;
  const auto& nodes = Rule::abscissa();
  const auto& weights = Rule::weights();
  const int panels = std::max(1, static_cast<int>(std::ceil((t1 - t0) / max_panel)));
  const double width = (t1 - t0) / panels;
  // e^{−iωt} at the nodes mid ± half·ξ_i: e^{−iω mid} (one sincos per panel) times the rotations e^{∓iω half ξ_i}
  std::array<std::complex<double>, Points / 2 + 1> rotation{};  // the rule's non-negative nodes (Points/2 + 1 at most)
  for (std::size_t i = 0; i < nodes.size(); ++i) rotation[i] = phasor(-omega * 0.5 * width * nodes[i]);
  for (int p = 0; p < panels; ++p) {
    const double a = t0 + p * width, b = (p + 1 == panels) ? t1 : a + width;
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    const std::complex<double> e_mid = std::polar(1.0, -omega * mid);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if (nodes[i] == 0.0) {
        node(mid, half * weights[i], e_mid);
      } else {
        node(mid - half * nodes[i], half * weights[i], e_mid * std::conj(rotation[i]));
        node(mid + half * nodes[i], half * weights[i], e_mid * rotation[i]);
      }
    }
    panel_done(a, b);
  }
}

}  // namespace afmkit::tapping
