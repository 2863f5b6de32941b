// The exact discrete inverse of seed 2's first-order plant (plant_inverse.hpp).
#include "afmkit/scan/plant_inverse.hpp"

#include <cmath>
#include <limits>

#include "afmkit/core/validate.hpp"

namespace afmkit::scan {

void ReconstructionSpec::validate() const {
  validate::non_negative("reconstruction_bandwidth", assumed_bandwidth);
  validate::non_negative("prior_increment", prior_increment);
}

PlantInverse::PlantInverse(double bandwidth, double sample_rate) {
  validate::positive("reconstruction_bandwidth", bandwidth);
  validate::positive("sample_rate", sample_rate);
  const double x = bandwidth / sample_rate;  // γ̂ h
  a_ = std::exp(-x);
  double b0 = 0, b1 = 0;
  if (x < 1e-2) {  // the series, free of the cancellation in 1 − (1 − a)/x (truncation below 1e-13 relative)
    b1 = x * (0.5 + x * (-1.0 / 6 + x * (1.0 / 24 + x * (-1.0 / 120 + x * (1.0 / 720)))));
    b0 = x * (0.5 + x * (-1.0 / 3 + x * (1.0 / 8 + x * (-1.0 / 30 + x * (1.0 / 144)))));
  } else {
    const double m = -std::expm1(-x) / x;  // (1 − a)/x
    b1 = 1.0 - m;
    b0 = m - a_;
  }
  b0_ = b0;
  inv_b1_ = 1.0 / b1;
  const double p = std::abs(pole());
  settle_ = p > 0.0 ? static_cast<std::int64_t>(std::ceil(std::log(0.01) / std::log(p))) : 0;
  if (settle_ < 0) settle_ = 0;
}

double PlantInverse::noise_gain() const {
  const double p = pole();
  return std::sqrt(1.0 + (p - a_) * (p - a_) / (1.0 - p * p)) * inv_b1_;
}

double PlantInverse::noise_correlation() const {
  const double p = pole(), q = p - a_;
  const double g = noise_gain() / inv_b1_;  // G b1
  return (q + q * q * p / (1.0 - p * p)) / (g * g);
}

double PlantInverse::image_noise_gain() const {
  return noise_gain() * std::sqrt((2.0 / 3.0) * (2.0 / 3.0 + noise_correlation() / 3.0));
}

double PlantInverse::nan() noexcept { return std::numeric_limits<double>::quiet_NaN(); }

}  // namespace afmkit::scan
