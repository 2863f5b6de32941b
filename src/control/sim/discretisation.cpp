#include "afmkit/control/discretisation.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

ZeroOrderHold zero_order_hold(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double step) {
  validate::positive("step", step);
  if (a.rows() != a.cols() || b.rows() != a.rows())
    throw InvalidParameter("input", fmt::format("zero_order_hold: A is {}x{} and B is {}x{}: A must be square and "
                                                "B must have as many rows as A",
                                                a.rows(), a.cols(), b.rows(), b.cols()));
  const Eigen::Index n = a.rows(), m = b.cols();
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(n + m, n + m);
  aug.topLeftCorner(n, n) = a * step;
  aug.topRightCorner(n, m) = b * step;
  const Eigen::MatrixXd e = aug.exp();
  return {e.topLeftCorner(n, n), e.topRightCorner(n, m)};
}

namespace {
template <class T>
T phi_impl(int k, T z) {
  if (k < 0 || k > 8) throw InvalidParameter("k", fmt::format("phi_function: k = {} is out of range: must be in [0, 8]", k));
  if (std::abs(z) < 1.0) {
    // Σ z^m/(m+k)!: 30 terms give |z|^30/30! < 4e-33 relative to the leading 1/k!.
    double fact = 1.0;
    for (int j = 2; j <= k; ++j) fact *= j;
    T term = T(1.0 / fact), sum = term;
    for (int m = 1; m < 30; ++m) {
      term *= z / static_cast<double>(m + k);
      sum += term;
    }
    return sum;
  }
  T phi = std::exp(z);
  double fact = 1.0;  // (j)!
  for (int j = 0; j < k; ++j) {
    if (j > 0) fact *= j;
    phi = (phi - T(1.0 / fact)) / z;
  }
  return phi;
}

std::complex<double> root_max_modulus(std::complex<double> w) {
  // ζ³ + c2 ζ² + c1 ζ + c0 = 0 via the companion matrix.
  const std::complex<double> c2 = -1.0 - 23.0 * w / 12.0, c1 = 16.0 * w / 12.0, c0 = -5.0 * w / 12.0;
  Eigen::Matrix3cd comp = Eigen::Matrix3cd::Zero();
  comp(0, 0) = -c2;
  comp(0, 1) = -c1;
  comp(0, 2) = -c0;
  comp(1, 0) = 1.0;
  comp(2, 1) = 1.0;
  Eigen::ComplexEigenSolver<Eigen::Matrix3cd> es(comp, false);
  return {es.eigenvalues().cwiseAbs().maxCoeff(), 0.0};
}
}  // namespace

double phi_function(int k, double z) { return phi_impl<double>(k, z); }
std::complex<double> phi_function(int k, std::complex<double> z) { return phi_impl<std::complex<double>>(k, z); }

namespace ab3 {

double amplification(std::complex<double> w) { return root_max_modulus(w).real(); }

bool is_stable(std::complex<double> w) { return amplification(w) <= 1.0 + 1e-10; }

std::complex<double> boundary(double theta) {
  const std::complex<double> z = std::polar(1.0, theta);
  return (z * z * z - z * z) * 12.0 / (23.0 * z * z - 16.0 * z + 5.0);
}

double real_axis_limit() { return boundary(std::numbers::pi).real(); }

double imaginary_axis_limit() {
  // Near θ = 0 the locus is w ≈ iθ + (3/8)θ⁴ (error constant of AB3), right of the axis; find where it crosses.
  double lo = 1e-2, hi = lo;
  while (boundary(hi).real() > 0.0 && hi < std::numbers::pi) {
    lo = hi;
    hi += 1e-2;
  }
  for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
    const double mid = 0.5 * (lo + hi);
    (boundary(mid).real() > 0.0 ? lo : hi) = mid;
  }
  return boundary(0.5 * (lo + hi)).imag();
}

long minimum_steps(const Eigen::VectorXcd& eigenvalues, double period) {
  validate::positive("period", period);
  auto ok = [&](long m) {
    const double h = period / static_cast<double>(m);
    for (Eigen::Index i = 0; i < eigenvalues.size(); ++i)
      if (!is_stable(h * eigenvalues(i))) return false;
    return true;
  };
  long hi = 1;
  while (!ok(hi)) {
    if (hi > (1L << 40)) throw NumericalFailure("ab3::minimum_steps: no stable step found (an eigenvalue with Re > 0?)");
    hi *= 2;
  }
  long lo = hi / 2;  // unstable (or 0)
  if (hi == 1) return 1;
  while (hi - lo > 1) {
    const long mid = lo + (hi - lo) / 2;
    (ok(mid) ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace ab3
}  // namespace afmkit::control
