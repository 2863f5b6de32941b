// Energy dissipated by a hysteresis force law over one impact: the area between the branches (seed-1 eq. 6).
#include <cmath>
#include <vector>

#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/impact/impact.hpp"

namespace afmkit::impact {

double hysteresis_energy_loss(const ForceLaw& law, double minimum_gap, double reference_gap) {
  validate::finite("minimum_gap", minimum_gap);
  validate::finite("reference_gap", reference_gap);
  validate::require(minimum_gap <= reference_gap, "minimum_gap", minimum_gap,
                    fmt::format("<= reference_gap = {}", reference_gap));
  // Split at the switching gaps so that every piece is smooth inside, then map each piece with the
  // smoothstep ξ = lo + (hi − lo)(3t² − 2t³): the Jacobian 6t(1 − t) vanishes at both ends, which smooths
  // (a0 − ξ)^{3/2}-type endpoint behaviour of contact laws; adaptive Gauss–Kronrod (61 points) on t ∈ [0, 1].
  std::vector<double> cuts{minimum_gap};
  for (double g : law.switching_gaps())
    if (g > minimum_gap && g < reference_gap) cuts.push_back(g);
  cuts.push_back(reference_gap);
  auto difference = [&law](double gap) { return law.approach(gap) - law.departure(gap); };  // H_a − H_b
  double area = 0.0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    if (cuts[i + 1] <= cuts[i]) continue;
    double error = 0.0, l1 = 0.0;
    const double lo = cuts[i], width = cuts[i + 1] - cuts[i];
    auto mapped = [&](double t) { return difference(lo + width * t * t * (3.0 - 2.0 * t)) * width * 6.0 * t * (1.0 - t); };
    const double piece =
        boost::math::quadrature::gauss_kronrod<double, 61>::integrate(mapped, 0.0, 1.0, 12, 1e-14, &error, &l1);
    if (!std::isfinite(piece) || error > 1e-9 * l1)
      throw NumericalFailure(fmt::format("eq. (6) quadrature on [{}, {}] did not converge (error estimate {:.3g})",
                                         cuts[i], cuts[i + 1], error));
    area += piece;
  }
  return area;
}

}  // namespace afmkit::impact
