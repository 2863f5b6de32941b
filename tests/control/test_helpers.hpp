#pragma once
// Shared helpers of the control tests.
#include <complex>
#include <random>
#include <vector>

namespace afmkit::control::testing {

/// Fixed pseudo-random complex points (normal real part σ=re, imaginary part σ=im) plus a few fixed ones.
inline std::vector<std::complex<double>> random_points(unsigned seed, int count, double re = 2.0, double im = 5.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> a(0.0, re), b(0.0, im);
  std::vector<std::complex<double>> p;
  for (int i = 0; i < count; ++i) p.emplace_back(a(rng), b(rng));
  p.emplace_back(0.37, 0.2);
  p.emplace_back(0.01, 2.5);
  return p;
}

inline double rel_err(std::complex<double> a, std::complex<double> b) {
  return std::abs(a - b) / std::max(std::abs(b), 1e-300);
}

}  // namespace afmkit::control::testing
