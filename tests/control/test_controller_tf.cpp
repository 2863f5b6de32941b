// Closed-form controller transfer functions (seed-2 eqs. 10, 18, 25, 28–31) against state space and each other.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "afmkit/control/controller_tf.hpp"
#include "afmkit/control/loop.hpp"
#include "afmkit/control/state_space.hpp"
#include "test_helpers.hpp"

using namespace afmkit::control;
using afmkit::control::testing::random_points;
using afmkit::control::testing::rel_err;
using cplx = std::complex<double>;

namespace {
constexpr double kOmegaTf = 1.3;
OscillatorBank random_bank(std::mt19937& rng, int n, std::vector<int> rejected = {1}) {
  std::normal_distribution<double> nd;
  std::vector<double> a(n), b(n);
  for (int k = 0; k < n; ++k) {
    a[k] = nd(rng);
    b[k] = nd(rng);
  }
  return OscillatorBank(kOmegaTf, nd(rng), a, b, 0.3 + std::abs(nd(rng)), std::move(rejected));
}
// Reference C∞ near its removable points from the series definition (eq. 25 with N = ∞):
// C∞ = K H1/(1 + α/s + Σ_{k≥2} H_k), summed in long double to M = 20000 plus an Euler–Maclaurin tail
// Σ_{k>M} 1/(k²Ω² + s²) = Σ_j (−s²)^j ζ_M(2j+2)/Ω^{2j+2}. No cancellation near s = 0 or ±iΩ.
cplx infinite_tf_series(const InfiniteBank& b, cplx s_in) {
  using L = long double;
  using CL = std::complex<L>;
  const CL s(s_in.real(), s_in.imag());
  const L w = b.rotation_frequency;
  const CL iw(0.0L, w);
  const int m = 20000;
  CL sum = 0.0L;
  for (int k = m; k >= 2; --k) sum += L(1) / ((s - L(k) * iw) * (s + L(k) * iw));
  auto zeta_tail = [m](int p) {  // Σ_{k>M} k^{−p}
    const L mm = m;
    return std::pow(mm, L(1 - p)) / L(p - 1) - std::pow(mm, L(-p)) / L(2) + L(p) * std::pow(mm, L(-p - 1)) / L(12) -
           L(p) * L(p + 1) * L(p + 2) * std::pow(mm, L(-p - 3)) / L(720);
  };
  sum += zeta_tail(2) / (w * w) - s * s * zeta_tail(4) / (w * w * w * w) +
         s * s * s * s * zeta_tail(6) / (w * w * w * w * w * w);
  const CL lin = L(2) * (L(b.alpha) * s + L(b.beta) * w);
  const CL h1 = lin / ((s - iw) * (s + iw));
  const CL c = L(b.gain) * h1 / (L(1) + L(b.alpha) / s + lin * sum);
  return {static_cast<double>(c.real()), static_cast<double>(c.imag())};
}
}  // namespace

TEST(ControllerTf, SingleOscillatorEq10MatchesStateSpace) {
  std::mt19937 rng(7);
  std::normal_distribution<double> nd;
  double worst = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const double a = nd(rng), b = nd(rng), k = 0.2 + std::abs(nd(rng));
    // (5)–(6) directly: ẋ = −Ωz + a m, ż = Ωx + b m, w = K x (2 states, no x0)
    Eigen::MatrixXd am(2, 2), bm(2, 1), cm(1, 2), dm = Eigen::MatrixXd::Zero(1, 1);
    am << 0, -kOmegaTf, kOmegaTf, 0;
    bm << a, b;
    cm << k, 0;
    const auto g = ss(am, bm, cm, dm);
    const auto rational = single_oscillator_tf(kOmegaTf, a, b, k);
    const OscillatorBank single = OscillatorBank::single(kOmegaTf, a, b, k);
    for (auto s : random_points(8, 12)) {
      const cplx ref = g(s);
      worst = std::max(worst, rel_err(single_oscillator_tf(kOmegaTf, a, b, k, s), ref));
      worst = std::max(worst, rel_err(rational(s), ref));
      worst = std::max(worst, rel_err(controller_response(single, s), ref));
      worst = std::max(worst, rel_err(bank_tf(single, s), ref));
    }
  }
  EXPECT_LT(worst, 1e-13);
}

TEST(ControllerTf, BankEq18AndComplexFormMatchStateSpace) {
  std::mt19937 rng(9);
  double worst18 = 0.0, worst39 = 0.0, worst_robust = 0.0;
  for (int n = 1; n <= 8; ++n) {
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<int> rejected{1};
      if (n >= 4 && trial >= 3) rejected = {1, 2, 4};  // general rejected set
      if (n >= 2 && trial == 2) rejected = {2};
      const auto bank = random_bank(rng, n, rejected);
      const auto g = ss(bank);
      for (auto s : random_points(100 + n, 12)) {
        const cplx ref = g(s);
        worst18 = std::max(worst18, rel_err(bank_tf(bank, s), ref));
        worst39 = std::max(worst39, rel_err(complex_form_tf(bank, s), ref));
        worst_robust = std::max(worst_robust, rel_err(controller_response(bank, s), ref));
      }
    }
  }
  EXPECT_LT(worst18, 1e-12);
  EXPECT_LT(worst39, 1e-12);
  EXPECT_LT(worst_robust, 1e-12);
}

TEST(ControllerTf, ShermanMorrisonMatchesDirectInverse) {
  std::mt19937 rng(10);
  double worst = 0.0;
  for (int n : {2, 4, 7}) {
    const auto bank = random_bank(rng, n, n >= 4 ? std::vector<int>{1, 3} : std::vector<int>{1});
    for (auto s : random_points(200 + n, 10)) {
      // 𝓜 = diag(s − ikΩ) + g wᵀ (eq. 36), solved by LU
      Eigen::MatrixXcd m = Eigen::MatrixXcd::Zero(2 * n + 1, 2 * n + 1);
      Eigen::VectorXcd g(2 * n + 1), w(2 * n + 1);
      for (int k = -n; k <= n; ++k) {
        const int i = k + n;
        g(i) = k == 0 ? cplx(bank.a0()) : k > 0 ? 0.5 * cplx(bank.a(k), bank.b(k)) : 0.5 * cplx(bank.a(-k), -bank.b(-k));
        w(i) = (k != 0 && bank.is_rejected(std::abs(k))) ? 0.0 : 1.0;
        m(i, i) = s - cplx(0.0, k * kOmegaTf);
      }
      m += g * w.transpose();
      const Eigen::VectorXcd direct = m.partialPivLu().solve(g);
      const Eigen::VectorXcd sm = complex_form_states(bank, s);
      worst = std::max(worst, (direct - sm).cwiseAbs().maxCoeff() / direct.cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LT(worst, 1e-13);
}

TEST(ControllerTf, CouplingsEq25AndQnEq28MatchEq18With20) {
  double worst25 = 0.0, worst28 = 0.0;
  for (int n : {1, 2, 5, 12, 40}) {
    for (auto [alpha, beta, k] : {std::tuple{0.3, 0.1, 2.0}, {1.5, -0.2, 20.0}, {0.05, 0.7, 1.0}}) {
      const auto bank = OscillatorBank::with_couplings(kOmegaTf, n, alpha, beta, k);
      const auto g = ss(bank);
      for (auto s : random_points(300 + n, 10)) {
        const cplx ref18 = bank_tf(bank, s);
        if (n <= 12) worst25 = std::max(worst25, rel_err(couplings_tf(kOmegaTf, n, alpha, beta, k, s), g(s)));
        worst25 = std::max(worst25, rel_err(couplings_tf(kOmegaTf, n, alpha, beta, k, s), ref18));
        worst28 = std::max(worst28, rel_err(qn_tf(kOmegaTf, n, alpha, beta, k, s), ref18));
      }
    }
  }
  EXPECT_LT(worst25, 1e-12);
  EXPECT_LT(worst28, 1e-11);
}

TEST(ControllerTf, InfiniteForms29And31AgreeAndAreTheLimitOfCN) {
  const double alpha = 0.4, beta = 0.15, k = 3.0;
  const InfiniteBank inf(kOmegaTf, alpha, beta, k);
  double worst = 0.0;
  for (auto s : random_points(400, 14)) {
    worst = std::max(worst, rel_err(infinite_tf_quasi(inf, s), infinite_tf(inf, s)));
    worst = std::max(worst, rel_err(controller_response(inf, s), infinite_tf(inf, s)));
  }
  EXPECT_LT(worst, 1e-11);
  // |C_N − C∞| ≈ 1.14/N at the points of the independent reference check (docs/theory-control.md#infinite-bank)
  const std::vector<cplx> pts{{0.0, 0.37 * kOmegaTf}, {0.0, 1.5 * kOmegaTf}, {0.0, 2.71 * kOmegaTf}, {0.0, 5.5 * kOmegaTf},
                              {0.2, 3.3}, {1.0, 0.5}};
  double prev = 1e9;
  for (int n : {10, 50, 200, 800}) {
    double d = 0.0;
    for (auto s : pts) d = std::max(d, std::abs(couplings_tf(kOmegaTf, n, alpha, beta, k, s) - infinite_tf(inf, s)));
    EXPECT_LT(d, prev);
    prev = d;
    if (n >= 200) {
      EXPECT_NEAR(n * d, 1.14, 0.05) << n;
    }
  }
}

TEST(ControllerTf, ZerosAndPolesAtTheHarmonics) {
  // eq. (18): zeros at s = 0 and ±ikΩ (k ≥ 2), pole at ±iΩ; every form returns the limit there
  const auto bank = OscillatorBank::with_couplings(kOmegaTf, 5, 0.4, 0.15, 3.0);
  const InfiniteBank inf(kOmegaTf, 0.4, 0.15, 3.0);
  for (int k : {0, 2, 3, 5}) {
    const cplx s(0.0, k * kOmegaTf);
    EXPECT_EQ(std::abs(bank_tf(bank, s)), 0.0);
    EXPECT_EQ(std::abs(couplings_tf(kOmegaTf, 5, 0.4, 0.15, 3.0, s)), 0.0);
    EXPECT_EQ(std::abs(complex_form_tf(bank, s)), 0.0);
    EXPECT_EQ(std::abs(qn_tf(kOmegaTf, 5, 0.4, 0.15, 3.0, s)), 0.0);
    EXPECT_LT(std::abs(infinite_tf(inf, s)), 1e-12);
    EXPECT_LT(std::abs(infinite_tf_quasi(inf, s)), 1e-12);
  }
  EXPECT_TRUE(std::isinf(std::abs(bank_tf(bank, cplx(0.0, kOmegaTf)))));
  EXPECT_TRUE(std::isinf(std::abs(controller_response(inf, cplx(0.0, -kOmegaTf)))));
  EXPECT_TRUE(std::isinf(std::abs(infinite_tf_quasi(inf, cplx(0.0, kOmegaTf)))));
  // near the pole: |C| ~ residue/|δ|; the pole-free form and the state space agree to full relative accuracy
  const auto g = ss(bank);
  for (double delta : {1e-4, 1e-8, 1e-11}) {
    const cplx s(0.0, kOmegaTf * (1.0 + delta));
    EXPECT_LT(rel_err(controller_response(bank, s), bank_tf(bank, s)), 1e-9);
    EXPECT_LT(rel_err(controller_response(bank, s), g(s)), 1e-4);  // LU of a nearly singular matrix
  }
  // near the removable points of the infinite bank (s = 0, ±iΩ) the pole-free form stays accurate: compared
  // with the series definition (no cancellation there) and with the N = ∞ value of the literal form far away
  double worst = 0.0;
  for (double delta : {1e-1, 1e-3, 1e-6, 1e-9, 1e-12}) {
    for (cplx s : {cplx(delta, kOmegaTf), cplx(-delta, -kOmegaTf + delta), cplx(delta, delta), cplx(0.0, delta)})
      worst = std::max(worst, rel_err(controller_response(inf, s), infinite_tf_series(inf, s)));
  }
  EXPECT_LT(worst, 1e-13);
  for (auto s : random_points(401, 6)) EXPECT_LT(rel_err(infinite_tf_series(inf, s), infinite_tf(inf, s)), 1e-13);
}
