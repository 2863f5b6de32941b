#pragma once
// Shared helpers of the control tests.
#include <algorithm>
#include <complex>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
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

/// One row of a `control tf` CSV (frequency,magnitude,phase,real,imag) and the line it was read from.
struct TfRow {
  double frequency = 0, magnitude = 0, phase = 0, real = 0, imag = 0;
  std::string line;
};
/// The header and the rows of a `control tf` CSV.
inline std::vector<TfRow> read_tf_csv(const std::filesystem::path& path, std::string* header = nullptr) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  if (header) *header = line;
  std::vector<TfRow> rows;
  while (std::getline(in, line)) {
    TfRow r;
    char c;
    std::stringstream ss(line);
    ss >> r.frequency >> c >> r.magnitude >> c >> r.phase >> c >> r.real >> c >> r.imag;
    r.line = line;
    rows.push_back(r);
  }
  return rows;
}

}  // namespace afmkit::control::testing
