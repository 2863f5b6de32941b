// Closed loop: characteristic function Δ(s) vs the delay-differential determinant and τ = 0 eigenvalues,
// its derivative vs finite differences, limits and identities of docs/theory-control.md (seed-2 eqs. 20–33),
// sensitivities, Smith predictor.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "afmkit/control/controller_tf.hpp"
#include "afmkit/control/loop.hpp"
#include "afmkit/control/stability_tau0.hpp"
#include "afmkit/core/error.hpp"
#include "test_helpers.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit::control;
using afmkit::InvalidParameter;
using afmkit::control::testing::random_points;
using afmkit::control::testing::rel_err;
using cplx = std::complex<double>;
using Structure = SmithPredictor::Structure;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kT;

OscillatorBank general_bank() {
  return OscillatorBank(kOmega, 0.3, {0.4, -0.2, 0.5, 0.1}, {0.2, 0.3, -0.4, 0.25}, 15.0, {1, 3});
}

// Finite-bank loops of every kind, with the normalisation of Δ relative to det(sI − A0 − Σ A_i e^{−sτ_i}).
struct Case {
  LoopSpec loop;
  double norm;
};
std::vector<Case> finite_cases() {
  const auto bank = OscillatorBank::with_couplings(kOmega, 4, 0.2, -0.1, 20.0);
  const auto single = OscillatorBank::single(kOmega, 0.5, 0.1, 20.0);
  double p4 = 1.0;
  for (int k = 1; k <= 4; ++k) p4 *= k * k * kOmega * kOmega;
  std::vector<Case> c;
  c.push_back({LoopSpec(bank, PlantKind::Static, 20.0, 0.1 * kT), p4});
  c.push_back({LoopSpec(bank, PlantKind::FirstOrder, 20.0, 0.17 * kT), p4 * 20.0});
  c.push_back({LoopSpec(general_bank(), PlantKind::Static, 12.0, 0.05 * kT), p4});
  c.push_back({LoopSpec(general_bank(), PlantKind::FirstOrder, 12.0, 0.3 * kT), p4 * 12.0});
  c.push_back({LoopSpec(single, PlantKind::Static, 20.0, 0.2 * kT), 1.0});
  c.push_back({LoopSpec(single, PlantKind::FirstOrder, 8.0, 0.2 * kT), 8.0});
  for (auto st : {Structure::Classic, Structure::Periodic}) {
    c.push_back({LoopSpec(SmithPredictor(bank, PlantKind::Static, 25.0, 0.4 * kT, st), PlantKind::Static, 20.0,
                          0.45 * kT),
                 p4});
    c.push_back({LoopSpec(SmithPredictor(bank, PlantKind::FirstOrder, 17.0, 1.3 * kT, st), PlantKind::FirstOrder,
                          20.0, 1.2 * kT),
                 p4 * 20.0 * 17.0});
    c.push_back({LoopSpec(SmithPredictor(general_bank(), PlantKind::FirstOrder, 10.0, 0.2 * kT, st),
                          PlantKind::Static, 12.0, 0.25 * kT),
                 p4 * 10.0});
  }
  return c;
}

cplx five_point_derivative(const LoopSpec& loop, cplx s, double h) {
  return (-characteristic(loop, s + 2.0 * h) + 8.0 * characteristic(loop, s + h) - 8.0 * characteristic(loop, s - h) +
          characteristic(loop, s - 2.0 * h)) /
         (12.0 * h);
}
}  // namespace

TEST(Loop, CharacteristicEqualsDelayDifferentialDeterminant) {
  double worst = 0.0;
  for (const auto& c : finite_cases()) {
    const auto dde = closed_loop_dde(c.loop);
    for (auto s : random_points(31, 10, 1.0, 4.0)) {
      const cplx det = dde.determinant(s) / c.norm;
      // both sides add terms of size |e^{−sτ_i}| that cancel when Re s < 0: allow for that conditioning
      double growth = 1.0;
      for (const auto& [tau, a] : dde.delayed) growth = std::max(growth, std::exp(-s.real() * tau));
      worst = std::max(worst, rel_err(characteristic(c.loop, s), det) / growth);
    }
  }
  EXPECT_LT(worst, 1e-11);
}

TEST(Loop, DerivativeMatchesFiniteDifferences) {
  std::vector<LoopSpec> loops;
  for (const auto& c : finite_cases()) loops.push_back(c.loop);
  const InfiniteBank inf(kOmega, 0.1, -0.1, 20.0);
  loops.emplace_back(inf, PlantKind::Static, 20.0, 0.1 * kT);
  loops.emplace_back(inf, PlantKind::FirstOrder, 20.0, 0.1 * kT);
  loops.emplace_back(SmithPredictor(inf, PlantKind::FirstOrder, 15.0, 0.3 * kT), PlantKind::FirstOrder, 20.0, 0.2 * kT);
  auto pts = random_points(32, 8, 1.0, 4.0);
  for (cplx extra : {cplx(1e-3, kOmega), cplx(0.0, -kOmega + 0.05), cplx(0.02, 0.01), cplx(-40.0, 3.0),
                     cplx(45.0, 2.0)})  // near the removable points of Δ∞ and in the scaled (|Re πs/Ω| > 30) regime
    pts.push_back(extra);
  double worst = 0.0;
  for (const auto& loop : loops) {
    for (auto s : pts) {
      const cplx exact = characteristic_derivative(loop, s);
      const cplx fd = five_point_derivative(loop, s, 2e-4);
      const double scale = std::abs(characteristic(loop, s)) + std::abs(exact);
      worst = std::max(worst, std::abs(exact - fd) / scale);
    }
  }
  EXPECT_LT(worst, 1e-9);
}

TEST(Loop, ZerosAtZeroDelayAreTheClosedLoopEigenvalues) {
  for (const auto& c : finite_cases()) {
    const LoopSpec loop0 = c.loop.with_delay(0.0);
    if (std::holds_alternative<SmithPredictor>(loop0.controller)) continue;  // Smith keeps its own delays
    const auto poles = undelayed_poles(loop0);
    for (const auto& z : poles) {
      EXPECT_LT(std::abs(newton_step(loop0, z)), 1e-9 * (1.0 + std::abs(z))) << loop0.describe() << " at " << z;
    }
    // degree check: Δ is a polynomial of degree = state dimension; its leading behaviour matches det/norm
    const cplx far(3.0, 50.0);
    EXPECT_LT(rel_err(characteristic(loop0, far), closed_loop_dde(loop0).determinant(far) / c.norm), 1e-10);
  }
}

TEST(Loop, StaticPlantDesignPointIsThePolynomial22) {
  // τ = 0, K = γ, couplings (20): Δ = p_N / ∏ k²Ω²
  for (int n : {1, 3, 6}) {
    const LoopSpec loop(OscillatorBank::with_couplings(kOmega, n, 0.3, 0.1, 20.0), PlantKind::Static, 20.0, 0.0);
    const Polynomial p = closed_loop_polynomial(n, kOmega, 0.3, 0.1);
    double norm = 1.0;
    for (int k = 1; k <= n; ++k) norm *= k * k * kOmega * kOmega;
    for (auto s : random_points(33, 8)) EXPECT_LT(rel_err(characteristic(loop, s), p(s) / norm), 1e-12);
  }
}

TEST(Loop, InfiniteBankIsTheLimitOfFiniteBanksAndTheReducedQuasiPolynomial) {
  const double alpha = 0.1, beta = -0.1, gamma = 20.0, tau = 0.1 * kT;
  const InfiniteBank inf(kOmega, alpha, beta, gamma);
  const LoopSpec loop_inf(inf, PlantKind::Static, gamma, tau);
  const std::vector<cplx> pts{{-0.05, 0.5}, {0.1, 1.7}, {-0.3, 3.2}, {0.0, 0.2}};
  // Δ_N = Q_N (F_N − H1 + ρe^{−sτ}H1) and Δ∞ = Q∞ (F∞ − H1 + ρe^{−sτ}H1): compare Δ_N Q∞/Q_N with Δ∞,
  // whose difference is the tail Σ_{k>N} H_k = O(1/N); Q_N = s ∏(1 + s²/k²Ω²), Q∞ = (Ω/π) sinh(πs/Ω) (eq. 44)
  std::vector<double> err;
  for (int n : {80, 320, 1280}) {
    const LoopSpec loop_n(OscillatorBank::with_couplings(kOmega, n, alpha, beta, gamma), PlantKind::Static, gamma, tau);
    double d = 0.0;
    for (auto s : pts) {
      cplx qn = s;
      for (int k = 1; k <= n; ++k) qn *= 1.0 + s * s / (double(k) * k * kOmega * kOmega);
      const cplx qinf = kOmega / std::numbers::pi * std::sinh(std::numbers::pi * s / kOmega);
      d = std::max(d, rel_err(characteristic(loop_n, s) * qinf / qn, characteristic(loop_inf, s)));
    }
    err.push_back(d);
  }
  EXPECT_LT(err.back(), 1e-3);
  EXPECT_NEAR(err[0] / err[1], 4.0, 0.5);
  EXPECT_NEAR(err[1] / err[2], 4.0, 0.5);
  // γ(𝒜 − ℬe^{−sT}) + e^{−sτ}𝒩(1 − e^{−sT}) = (2π/Ω) γ s²(s² + Ω²) e^{−πs/Ω} Δ(s)   (loop.hpp)
  const auto a = inf.a_coefficients(), b = inf.b_coefficients();
  const auto nn = inf.n_coefficients();
  for (auto s : random_points(34, 10, 1.0, 3.0)) {
    cplx av = 0.0, bv = 0.0, nv = 0.0;
    for (int j = 4; j >= 0; --j) {
      av = av * s + a[j];
      bv = bv * s + b[j];
    }
    for (int j = 3; j >= 0; --j) nv = nv * s + nn[j];
    const cplx z = std::exp(-s * kT);
    const cplx quasi = gamma * (av - bv * z) + std::exp(-s * tau) * nv * (1.0 - z);
    const cplx reduced = (kT) * gamma * s * s * (s * s + kOmega * kOmega) * std::exp(-std::numbers::pi * s / kOmega) *
                         characteristic(loop_inf, s);
    EXPECT_LT(rel_err(reduced, quasi), 1e-11) << s;
  }
  // the reduced Δ has no roots at the cancelled points 0, ±iΩ (docs/theory-control.md#neutral-realisation caveat)
  EXPECT_GT(std::abs(characteristic(loop_inf, 0.0)), 1e-3);
  EXPECT_GT(std::abs(characteristic(loop_inf, cplx(0.0, kOmega))), 1e-3);
}

TEST(Loop, NewtonStepSurvivesOverflow) {
  // N = 160 at |s| = 1000Ω: Δ itself overflows a double, the Newton step does not. Reference: Δ'/Δ =
  // Q'/Q + G'/G with Q = s ∏ q_k (analytic log-derivative) and G = D + ρ e^{−sτ} H1 (finite differences).
  const int n = 160;
  const double alpha = 0.1, beta = -0.1, gamma = 20.0, tau = 0.1 * kT;
  const auto bank = OscillatorBank::with_couplings(kOmega, n, alpha, beta, gamma);
  const LoopSpec loop(bank, PlantKind::Static, gamma, tau);
  auto g = [&](cplx s) {
    cplx d = 1.0 + alpha / s, h1 = 0.0;
    for (int k = 1; k <= n; ++k) {
      const cplx hk = 2.0 * (alpha * s + beta * kOmega) / (s * s + double(k * k) * kOmega * kOmega);
      if (k == 1) h1 = hk;
      else d += hk;
    }
    return d + std::exp(-s * tau) * h1;
  };
  for (cplx s : {cplx(5.0, 1000.0), cplx(-3.0, 730.5), cplx(200.0, 10.0)}) {
    if (std::abs(s) > 500.0) {
      EXPECT_FALSE(std::isfinite(std::abs(characteristic(loop, s))));
    }
    cplx qlog = 1.0 / s;
    for (int k = 1; k <= n; ++k) qlog += 2.0 * s / (s * s + double(k * k) * kOmega * kOmega);
    const double h = 1e-3;
    const cplx dg = (-g(s + 2.0 * h) + 8.0 * g(s + h) - 8.0 * g(s - h) + g(s - 2.0 * h)) / (12.0 * h);
    const cplx ref = 1.0 / (qlog + dg / g(s));
    EXPECT_LT(rel_err(newton_step(loop, s), ref), 1e-8) << s;
  }
}

TEST(Loop, SensitivityVanishesAtRejectedAndIsOneAtKeptHarmonics) {
  const auto bank = OscillatorBank::with_couplings(kOmega, 6, 0.1, -0.1, 20.0, {1, 3});
  for (auto kind : {PlantKind::Static, PlantKind::FirstOrder}) {
    const LoopSpec loop(bank, kind, 20.0, 0.13 * kT);
    for (int k = 1; k <= 6; ++k) {
      const cplx s(0.0, k * kOmega);
      const cplx sens = sensitivity(loop, s);
      if (k == 1 || k == 3) {
        EXPECT_EQ(std::abs(sens), 0.0) << k;
      } else {
        EXPECT_LT(std::abs(sens - 1.0), 1e-15) << k;
      }
      const cplx expected_dist = kind == PlantKind::Static ? 1.0 : 20.0 / (s + 20.0);  // uncontrolled response
      if (k != 1 && k != 3) {
        EXPECT_LT(std::abs(disturbance_response(loop, s) - expected_dist), 1e-15);
      }
    }
    EXPECT_LT(std::abs(sensitivity(loop, 0.0) - 1.0), 1e-15);  // x0 holds the offset
  }
  const LoopSpec loop_inf(InfiniteBank(kOmega, 0.1, -0.1, 20.0), PlantKind::Static, 20.0, 0.1 * kT);
  EXPECT_EQ(std::abs(sensitivity(loop_inf, cplx(0.0, kOmega))), 0.0);
  for (int k : {2, 5, 40}) EXPECT_LT(std::abs(sensitivity(loop_inf, cplx(0.0, k * kOmega)) - 1.0), 1e-12) << k;
  // loop/sensitivity consistency away from the harmonics
  const LoopSpec loop(bank, PlantKind::FirstOrder, 20.0, 0.13 * kT);
  for (auto s : random_points(35, 8))
    EXPECT_LT(rel_err(sensitivity(loop, s), 1.0 / (1.0 + loop_response(loop, s))), 1e-12);
}

TEST(Loop, SmithPredictorWithExactModelRemovesTheDelay) {
  const auto bank = OscillatorBank::with_couplings(kOmega, 5, 0.1, -0.1, 20.0);
  const auto delay_free = undelayed_poles(LoopSpec(bank, PlantKind::FirstOrder, 20.0, 0.0));
  for (auto st : {Structure::Classic, Structure::Periodic}) {
    for (double tau : {0.3 * kT, 0.9 * kT, 2.4 * kT}) {
      const LoopSpec loop(SmithPredictor(bank, PlantKind::FirstOrder, 20.0, tau, st), PlantKind::FirstOrder, 20.0, tau);
      for (const auto& z : delay_free) {
        if (std::exp(-z.real() * tau) < 1e4) {  // far-left poles: the cancelling predictor terms are ~e^{−Re(s)τ}
          EXPECT_LT(std::abs(newton_step(loop, z)), 1e-9 * (1.0 + std::abs(z))) << tau << " " << z;
        }
      }
      EXPECT_LT(std::abs(characteristic(loop, -20.0)), 1e-12);  // the model's own (stable) mode s = −γ̂
    }
  }
}

TEST(Loop, SmithPredictorRejectionClassicVsPeriodic) {
  const auto bank = OscillatorBank::with_couplings(kOmega, 5, 0.1, -0.1, 20.0);
  const cplx s1(0.0, kOmega);
  for (double tau : {0.15 * kT, 0.4 * kT}) {
    // classic, exact static model: S(iΩ) = 1 − e^{−iΩτ} (smith_predictor.hpp), so |S| = 2|sin(Ωτ/2)|
    const LoopSpec classic(SmithPredictor(bank, PlantKind::Static, 20.0, tau, Structure::Classic), PlantKind::Static,
                           20.0, tau);
    EXPECT_LT(std::abs(sensitivity(classic, s1) - (1.0 - std::exp(-s1 * tau))), 1e-13);
    // classic with model errors: S(iΩ) = 1/(1 + e^{−iΩτ} γ̂/(γ(1 − e^{−iΩτ̂})))
    const double gh = 14.0, th = 0.8 * tau;
    const LoopSpec classic_err(SmithPredictor(bank, PlantKind::Static, gh, th, Structure::Classic), PlantKind::Static,
                               20.0, tau);
    const cplx expected = 1.0 / (1.0 + std::exp(-s1 * tau) * gh / (20.0 * (1.0 - std::exp(-s1 * th))));
    EXPECT_LT(std::abs(sensitivity(classic_err, s1) - expected), 1e-13);
    // periodic: exact rejection for any model error, kept harmonics untouched
    for (auto mk : {PlantKind::Static, PlantKind::FirstOrder}) {
      const LoopSpec periodic(SmithPredictor(bank, mk, gh, th, Structure::Periodic), PlantKind::FirstOrder, 20.0, tau);
      EXPECT_LT(std::abs(sensitivity(periodic, s1)), 1e-14);
      EXPECT_LT(std::abs(sensitivity(periodic, cplx(0.0, 3.0 * kOmega)) - 1.0), 1e-12);
    }
  }
}

TEST(Loop, SmithRealisationReproducesTheControllerResponse) {
  const auto bank = general_bank();
  for (auto st : {Structure::Classic, Structure::Periodic}) {
    for (auto mk : {PlantKind::Static, PlantKind::FirstOrder}) {
      const SmithPredictor sp(bank, mk, 13.0, 0.7 * kT, st);
      const SmithRealisation r = smith_realisation(sp);
      EXPECT_EQ(r.model.states(), mk == PlantKind::FirstOrder ? 1 : 0);
      for (auto s : random_points(36, 10, 1.0, 4.0)) {
        const cplx gb = r.bank(s), gm = r.model(s);
        const cplx expected = gb * std::exp(-s * r.measurement_delay) /
                              (1.0 + gb * gm * (1.0 - std::exp(-s * r.correction_delay)));
        EXPECT_LT(rel_err(controller_response(sp, s), expected), 1e-11) << s;
      }
    }
  }
  EXPECT_THROW(smith_realisation(SmithPredictor(InfiniteBank(kOmega, 0.1, 0.0, 1.0), PlantKind::Static, 1.0, 0.1)),
               InvalidParameter);
  // delays of the two structures (smith_predictor.hpp): n = ⌈τ̂/T⌉
  const SmithPredictor per(bank, PlantKind::Static, 1.0, 1.3 * kT), cla(bank, PlantKind::Static, 1.0, 1.3 * kT,
                                                                       Structure::Classic);
  EXPECT_EQ(per.model_periods(), 2);
  EXPECT_NEAR(per.measurement_delay(), 0.7 * kT, 1e-12);
  EXPECT_NEAR(per.correction_delay(), 2.0 * kT, 1e-12);
  EXPECT_EQ(cla.measurement_delay(), 0.0);
  EXPECT_NEAR(cla.correction_delay(), 1.3 * kT, 1e-15);
  EXPECT_EQ(SmithPredictor(bank, PlantKind::Static, 1.0, 0.0).model_periods(), 0);
}

TEST(Loop, BadInputNamesTheParameter) {
  const auto bank = OscillatorBank::with_couplings(kOmega, 3, 0.1, -0.1, 20.0);
  auto expect_param = [](auto&& f, const std::string& name) {
    try {
      f();
      ADD_FAILURE() << "no exception for " << name;
    } catch (const InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), name);
    }
  };
  expect_param([&] { LoopSpec(bank, PlantKind::Static, 20.0, -0.1); }, "delay");
  expect_param([&] { LoopSpec(bank, PlantKind::Static, 0.0, 0.1); }, "plant_rate");
  expect_param([&] { LoopSpec(bank, PlantKind::Static, std::nan(""), 0.1); }, "plant_rate");
  expect_param([&] { SmithPredictor(bank, PlantKind::Static, -1.0, 0.1); }, "model_rate");
  expect_param([&] { SmithPredictor(bank, PlantKind::Static, 1.0, -0.1); }, "model_delay");
  expect_param([&] { OscillatorBank::with_couplings(kOmega, 0, 0.1, -0.1, 20.0); }, "harmonics");
  expect_param([&] { OscillatorBank::with_couplings(0.0, 3, 0.1, -0.1, 20.0); }, "rotation_frequency");
  expect_param([&] { OscillatorBank::with_couplings(-1.0, 3, 0.1, -0.1, 20.0); }, "rotation_frequency");
  expect_param([&] { OscillatorBank::with_couplings(kOmega, 3, std::nan(""), -0.1, 20.0); }, "alpha");
  expect_param([&] { OscillatorBank::with_couplings(kOmega, 3, 0.1, std::nan(""), 20.0); }, "beta");
  expect_param([&] { OscillatorBank(kOmega, 0.1, {0.1, std::nan("")}, {0.0, 0.0}, 1.0); }, "a[2]");
  expect_param([&] { InfiniteBank(kOmega, std::nan(""), 0.0, 1.0); }, "alpha");
  expect_param([&] { closed_loop_dde(LoopSpec(InfiniteBank(kOmega, 0.1, 0.0, 1.0), PlantKind::Static, 1.0, 0.0)); },
               "controller");
}
