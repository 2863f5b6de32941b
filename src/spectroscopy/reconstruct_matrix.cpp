// The matrix method (Giessibl, APL 78, 123 (2001)): the first-order frequency-shift integral discretised with F
// linear between the nodes, its weights in closed form, solved by back substitution.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "afmkit/spectroscopy/reconstruct_kernels.hpp"

namespace afmkit::spectroscopy {

namespace {
// Antiderivatives of u/√(1 − u²) and u²/√(1 − u²) on [−1, 1].
double g1(double u) { return -std::sqrt(std::max(0.0, 1.0 - u * u)); }
double g2(double u) { return 0.5 * (std::asin(std::clamp(u, -1.0, 1.0)) + u * g1(u)); }
}  // namespace

std::vector<std::vector<double>> matrix_method_force(const std::vector<double>& t,
                                                     const std::vector<std::vector<double>>& omegas, double amplitude,
                                                     double spring_constant) {
  const std::size_t n = t.size(), r = omegas.size();
  std::vector<std::vector<double>> force(r, std::vector<double>(n, 0.0));
  std::vector<double> w;  // weights of row i: w[j − i] for nodes j ≥ i
  const double scale = -1.0 / (std::numbers::pi * spring_constant * amplitude);
  // the last node: F = 0 (no interval above it, the force vanishes at the end of the curve)
  for (std::size_t i = n - 1; i-- > 0;) {
    w.assign(1, 0.0);
    for (std::size_t j = i; j + 1 < n; ++j) {
      const double ua = (t[j] - t[i]) / amplitude - 1.0;
      if (ua >= 1.0) break;
      const double ub_raw = (t[j + 1] - t[i]) / amplitude - 1.0, ub = std::min(ub_raw, 1.0);
      const double h_u = ub_raw - ua;  // the interval's length in u (unclipped)
      const double total = g1(ub) - g1(ua);
      const double upper = (g2(ub) - g2(ua) - ua * (g1(ub) - g1(ua))) / h_u;  // hat of node j + 1
      w.back() += total - upper;                                                // hat of node j
      w.push_back(upper);
    }
    const double diag = scale * w[0];
    for (std::size_t k = 0; k < r; ++k) {
      double rhs = omegas[k][i];
      for (std::size_t m = 1; m < w.size() && i + m < n; ++m) rhs -= scale * w[m] * force[k][i + m];
      force[k][i] = rhs / diag;
    }
  }
  return force;
}

}  // namespace afmkit::spectroscopy
