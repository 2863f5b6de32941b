// Reduced Chebyshev collocation of the infinitesimal generator (dde_collocation.hpp).
#include "afmkit/control/dde_collocation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include <Eigen/SVD>

#include "afmkit/control/eigenvalues.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

Eigen::MatrixXd chebyshev_differentiation(int n) {
  validate::in_range("nodes", static_cast<long>(n), 1L, 400L);
  Eigen::VectorXd x(n + 1), c(n + 1);
  for (int j = 0; j <= n; ++j) {
    x(j) = std::cos(std::numbers::pi * j / n);
    c(j) = ((j == 0 || j == n) ? 2.0 : 1.0) * ((j % 2) ? -1.0 : 1.0);
  }
  Eigen::MatrixXd d(n + 1, n + 1);
  for (int i = 0; i <= n; ++i) {
    double row = 0.0;
    for (int j = 0; j <= n; ++j) {
      if (i == j) continue;
      d(i, j) = (c(i) / c(j)) / (x(i) - x(j));
      row += d(i, j);
    }
    d(i, i) = -row;  // negative-sum trick
  }
  return d;
}

std::vector<std::complex<double>> collocation_eigenvalues(const DelayDifferentialSystem& system, int nodes,
                                                          double frequency_scale) {
  validate::in_range("nodes", static_cast<long>(nodes), 0L, 400L);
  validate::positive("frequency_scale", frequency_scale);
  const int d = static_cast<int>(system.a0.rows());
  Eigen::MatrixXd a0 = system.a0;
  // group delayed matrices by delay; zero delays go into A0
  std::map<double, Eigen::MatrixXd> groups;
  for (const auto& [tau, a] : system.delayed) {
    if (tau <= 0.0) {
      a0 += a;
      continue;
    }
    auto it = groups.find(tau);
    if (it == groups.end()) groups.emplace(tau, a);
    else it->second += a;
  }
  struct Part {
    double tau;
    int n, r;
    Eigen::MatrixXd u, v;  // A = U Vᵀ, U: d×r, V: d×r
  };
  std::vector<Part> parts;
  int size = d;
  for (const auto& [tau, a] : groups) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const auto& sv = svd.singularValues();
    if (sv.size() == 0 || sv(0) == 0.0) continue;
    int r = 0;
    while (r < sv.size() && sv(r) > 1e-13 * sv(0)) ++r;
    Part p;
    p.tau = tau;
    p.r = r;
    p.u = svd.matrixU().leftCols(r) * sv.head(r).asDiagonal();
    p.v = svd.matrixV().leftCols(r);
    p.n = nodes > 0 ? nodes
                    : std::clamp(static_cast<int>(std::ceil(0.8 * frequency_scale * tau)) + 16, 16, 160);
    size += p.r * p.n;
    parts.push_back(std::move(p));
  }
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(size, size);
  m.topLeftCorner(d, d) = a0;
  int off = d;
  for (const Part& p : parts) {
    const Eigen::MatrixXd dm = chebyshev_differentiation(p.n) * (2.0 / p.tau);  // θ = τ(x − 1)/2
    // x' = … + U h(θ_n)
    m.block(0, off + (p.n - 1) * p.r, d, p.r) += p.u;
    // h'(θ_j) = Σ_l D_jl h(θ_l), h(θ_0) = Vᵀ x
    for (int j = 1; j <= p.n; ++j) {
      const int row = off + (j - 1) * p.r;
      m.block(row, 0, p.r, d) += dm(j, 0) * p.v.transpose();
      for (int l = 1; l <= p.n; ++l)
        m.block(row, off + (l - 1) * p.r, p.r, p.r) += dm(j, l) * Eigen::MatrixXd::Identity(p.r, p.r);
    }
    off += p.r * p.n;
  }
  const Eigen::VectorXcd ev = eigenvalues(m, "collocation");
  std::vector<std::complex<double>> out(ev.data(), ev.data() + size);
  return out;
}

}  // namespace afmkit::control
