// Energy dissipated by a hysteresis force law over one impact: the area between the branches (seed-1 eq. 6).
// Written in the branch *differences* so that it keeps relative accuracy when the branches nearly coincide
// (nearly elastic impacts, e → 1: the loss (1 − e²) μ v²/2 of eq. 3 tends to 0).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/impact/impact.hpp"

namespace afmkit::impact {

namespace {

/// Laws without a closed form: adaptive Gauss–Kronrod of H_a − H_b split at the switching gaps.
double quadrature_area(const ForceLaw& law, double minimum_gap, double reference_gap) {
  // Split at the switching gaps so that every piece is smooth inside, then map each piece with the
  // smoothstep ξ = lo + (hi − lo)(3t² − 2t³): the Jacobian 6t(1 − t) vanishes at both ends, which smooths
  // (a0 − ξ)^{3/2}-type endpoint behaviour of contact laws; adaptive Gauss–Kronrod (61 points) on t ∈ [0, 1].
  std::vector<double> cuts{minimum_gap};
  for (double g : law.switching_gaps())
    if (g > minimum_gap && g < reference_gap) cuts.push_back(g);
  cuts.push_back(reference_gap);
  constexpr double eps = std::numeric_limits<double>::epsilon();
  double area = 0.0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    if (cuts[i + 1] <= cuts[i]) continue;
    const double lo = cuts[i], width = cuts[i + 1] - cuts[i];
    auto gap_at = [&](double t) { return lo + width * t * t * (3.0 - 2.0 * t); };
    auto jacobian = [&](double t) { return width * 6.0 * t * (1.0 - t); };
    auto mapped = [&](double t) {
      const double g = gap_at(t);
      return (law.approach(g) - law.departure(g)) * jacobian(t);  // H_a − H_b
    };
    double error = 0.0, l1 = 0.0;
    const double piece =
        boost::math::quadrature::gauss_kronrod<double, 61>::integrate(mapped, 0.0, 1.0, 12, 1e-14, &error, &l1);
    // Convergence is judged relative to the area itself, or to the rounding floor of the integrand: H_a − H_b
    // is a difference of branch values, each known to ~ε|H|, so no quadrature can beat ε ∫(|H_a| + |H_b|)
    // (for nearly coincident custom branches the relative accuracy is ~ε ∫(|H_a| + |H_b|) / area).
    auto magnitude = [&](double t) {
      const double g = gap_at(t);
      return (std::abs(law.approach(g)) + std::abs(law.departure(g))) * jacobian(t);
    };
    const double floor =
        boost::math::quadrature::gauss_kronrod<double, 61>::integrate(magnitude, 0.0, 1.0, 0, 1e-3);
    // (the adaptive estimate sums |Kronrod − Gauss| over up to 2^12 panels, so the floor carries a margin)
    if (!std::isfinite(piece) || error > 1e-9 * l1 + 1e3 * eps * floor)
      throw NumericalFailure(fmt::format("eq. (6) quadrature on [{}, {}] did not converge (error estimate {:.3g}, "
                                         "area {:.3g})",
                                         cuts[i], cuts[i + 1], error, piece));
    area += piece;
  }
  return area;
}

}  // namespace

double hysteresis_energy_loss(const ForceLaw& law, double minimum_gap, double reference_gap) {
  validate::finite("minimum_gap", minimum_gap);
  validate::finite("reference_gap", reference_gap);
  validate::require(minimum_gap <= reference_gap, "minimum_gap", minimum_gap,
                    fmt::format("<= reference_gap = {}", reference_gap));
  // a contact-aware law dissipates only after an impact: nothing when the approach stops above the contact gap
  // (docs/force-laws.md#hysteresis); above the release gap its branches are equal
  if (law.contact_aware() && minimum_gap > law.contact_gap()) return 0.0;
  // and nothing above its release gap, where the law is H_a (a release tolerance may hide a difference there)
  if (law.contact_aware()) reference_gap = std::max(minimum_gap, std::min(reference_gap, law.release_gap()));
  const double closed_form = law.hysteresis_area(minimum_gap, reference_gap);
  if (!std::isnan(closed_form)) return closed_form;
  return quadrature_area(law, minimum_gap, reference_gap);
}

}  // namespace afmkit::impact
