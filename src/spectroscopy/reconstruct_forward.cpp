// The first-order large-amplitude frequency shift (Giessibl 2001) of a force law, by quadrature: the forward model
// of the FM round trip until the exact-orbit FM model replaces it (docs/reconstruction.md#round-trip).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <boost/math/quadrature/gauss_kronrod.hpp>

#include "afmkit/spectroscopy/reconstruct_kernels.hpp"

namespace afmkit::spectroscopy {

double forward_frequency_shift(const std::function<double(double)>& force, double z, double spring_constant,
                               double resonance_frequency, double amplitude, const std::vector<double>& breaks) {
  // u = −cos θ: ∫_{−1}^{1} F(z + A(1 + u)) u/√(1 − u²) du = −∫_0^π F(z + A(1 − cos θ)) cos θ dθ (smooth in θ)
  std::vector<double> cuts = {0.0, std::numbers::pi};
  for (double b : breaks) {
    const double x = (b - z) / amplitude;  // 1 − cos θ
    if (x > 0.0 && x < 2.0) cuts.push_back(std::acos(1.0 - x));
  }
  std::sort(cuts.begin(), cuts.end());
  const auto f = [&](double theta) { return -force(z + amplitude * (1.0 - std::cos(theta))) * std::cos(theta); };
  double integral = 0.0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
    if (cuts[i + 1] > cuts[i])
      integral += boost::math::quadrature::gauss_kronrod<double, 31>::integrate(f, cuts[i], cuts[i + 1], 8, 1e-11);
  return -resonance_frequency / (std::numbers::pi * spring_constant * amplitude) * integral;
}

}  // namespace afmkit::spectroscopy
