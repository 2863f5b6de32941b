// N0·A and N1 (seed-1 eqs. 12–14, 27–31) against adaptive quadrature of eq. (12) with the actual nonlinearity.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <boost/multiprecision/cpp_bin_float.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/describing_functions.hpp"
#include "reference.hpp"

namespace afmkit::tapping {
namespace {

using impact::PiecewiseLinearLaw;
using std::numbers::pi;

TappingModel model_with(const PiecewiseLinearLaw& law, double separation) {
  return TappingModel(Cantilever(1.0, 100.0), Drive(0.2, 1.0), law, separation);
}

TEST(DescribingFunctions, MatchQuadratureOverManyQ) {
  const PiecewiseLinearLaw laws[] = {PiecewiseLinearLaw::linear_repulsive(3.0),
                                     PiecewiseLinearLaw::linear_hysteresis(10.0, 8.0),
                                     PiecewiseLinearLaw::repulsive_attractive(2.0, 1.6, 0.1, 0.3),
                                     PiecewiseLinearLaw::repulsive_attractive(100.0, 64.0, 0.5, 1.0),
                                     PiecewiseLinearLaw::repulsive_attractive(5.0, 5.0, 0.2, 0.2)};
  const double separation = 1.3;
  double worst_mean = 0, worst_first = 0;
  int cases = 0;
  for (const auto& law : laws) {
    const auto model = model_with(law, separation);
    for (double amplitude : {0.7, 3.0}) {
      for (int k = 0; k <= 70; ++k) {
        const double q = -3.0 + 0.1 * k + 0.0123;  // avoid landing exactly on q = ±1
        const double offset = q * amplitude - separation;
        const DescribingFunctions df = describing_functions(model.law, q, amplitude);
        const test::QuadratureDf ref = test::quadrature_df(model, offset, amplitude);
        const double sum_k = law.approach_stiffness + law.departure_stiffness;
        const double sum_f = law.approach_adhesion + law.departure_adhesion;
        const double scale_mean = sum_f + sum_k * amplitude * (1.0 + std::abs(q));
        const double scale_first = sum_k * (1.0 + std::abs(q)) + sum_f / amplitude;
        worst_mean = std::max(worst_mean, std::abs(df.mean - ref.mean) / scale_mean);
        worst_first = std::max(worst_first, std::abs(df.first_harmonic - ref.first) / scale_first);
        ++cases;
      }
    }
  }
  EXPECT_EQ(cases, 710);
  EXPECT_LT(worst_mean, 1e-12);
  EXPECT_LT(worst_first, 1e-12);
  std::printf("[ quadrature ] %d cases: max scaled error N0A %.2e, N1 %.2e\n", cases, worst_mean, worst_first);
}

TEST(DescribingFunctions, NearGrazingAndAtTheEdgesAgainstQuadrature) {
  const auto law = PiecewiseLinearLaw::repulsive_attractive(10.0, 8.0, 0.3, 0.6);
  const double separation = 2.0;
  const auto model = model_with(law, separation);
  for (double q : {0.999, 0.99999, 0.9999999, -0.99999, -0.999, 1.0, -1.0, 1.0000001, -1.0000001}) {
    const double amplitude = 1.5;
    const DescribingFunctions df = describing_functions(model.law, q, amplitude);
    const test::QuadratureDf ref = test::quadrature_df(model, q * amplitude - separation, amplitude);
    EXPECT_NEAR(df.mean, ref.mean, 1e-13 * 40) << q;
    EXPECT_NEAR(std::abs(df.first_harmonic - ref.first), 0.0, 1e-13 * 40) << q;
  }
}

TEST(DescribingFunctions, ContinuousAtPlusMinusOne) {
  for (double edge : {1.0, -1.0}) {
    const double d = 1e-13;
    const BarFunctions lo = bar_functions(edge - d);
    const BarFunctions hi = bar_functions(edge + d);
    const BarFunctions at = bar_functions(edge);
    const double a[] = {lo.chi, lo.omega, lo.phi_r, lo.phi_i, lo.psi_r, lo.psi_i};
    const double b[] = {hi.chi, hi.omega, hi.phi_r, hi.phi_i, hi.psi_r, hi.psi_i};
    const double c[] = {at.chi, at.omega, at.phi_r, at.phi_i, at.psi_r, at.psi_i};
    for (int k = 0; k < 6; ++k) {
      // Φ̄_R = √(1−q²)/π has a square-root edge: |Δ| ~ √(2d)/π.
      EXPECT_NEAR(a[k], b[k], 2e-6) << "edge " << edge << " function " << k;
      EXPECT_NEAR(a[k], c[k], 2e-6) << "edge " << edge << " function " << k;
    }
  }
}

// Reference in 50-digit arithmetic with the direct (cancelling) formulas of table A.6.
TEST(DescribingFunctions, AccurateNearGrazingVersusHighPrecision) {
  using Big = boost::multiprecision::cpp_bin_float_50;
  const Big big_pi = boost::multiprecision::acos(Big(-1));
  for (double gap : {1e-16, 1e-14, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-2, 0.1, 0.3, 0.49, 0.51, 1.0, 1.7, 1.999}) {
    const Big s(gap);
    const Big q = 1 - s;
    const Big a = boost::multiprecision::acos(q);
    const Big root = boost::multiprecision::sqrt(1 - q * q);
    const double omega_ref = static_cast<double>((root - q * a) / (2 * big_pi));
    const double psi_r_ref = static_cast<double>((a - q * root) / (2 * big_pi));
    const double chi_ref = static_cast<double>(a / (2 * big_pi));
    const double phi_r_ref = static_cast<double>(root / big_pi);
    const BarFunctions bar = bar_functions_from_gap(gap);
    EXPECT_NEAR(bar.omega / omega_ref, 1.0, 2e-14) << gap;
    EXPECT_NEAR(bar.psi_r / psi_r_ref, 1.0, 2e-14) << gap;
    EXPECT_NEAR(bar.chi / chi_ref, 1.0, 1e-14) << gap;
    EXPECT_NEAR(bar.phi_r / phi_r_ref, 1.0, 1e-14) << gap;
    // The contact-angle form agrees (a from the same reference).
    const BarFunctions by_angle = bar_functions_from_contact_angle(static_cast<double>(a));
    EXPECT_NEAR(by_angle.omega / omega_ref, 1.0, 1e-13) << gap;
    EXPECT_NEAR(by_angle.psi_r / psi_r_ref, 1.0, 1e-13) << gap;
  }
}

TEST(DescribingFunctions, AngleDerivativesMatchFiniteDifferences) {
  for (double a : {1e-3, 0.1, 0.49, 0.7, 1.5, 2.5, 3.1}) {
    const double h = 1e-6;
    const BarFunctions p = bar_functions_from_contact_angle(a + h);
    const BarFunctions m = bar_functions_from_contact_angle(a - h);
    const BarFunctions d = bar_function_derivatives_in_angle(a);
    EXPECT_NEAR(d.chi, (p.chi - m.chi) / (2 * h), 1e-8);
    EXPECT_NEAR(d.omega, (p.omega - m.omega) / (2 * h), 1e-8);
    EXPECT_NEAR(d.phi_r, (p.phi_r - m.phi_r) / (2 * h), 1e-8);
    EXPECT_NEAR(d.phi_i, (p.phi_i - m.phi_i) / (2 * h), 1e-8);
    EXPECT_NEAR(d.psi_r, (p.psi_r - m.psi_r) / (2 * h), 1e-8);
    EXPECT_NEAR(d.psi_i, (p.psi_i - m.psi_i) / (2 * h), 1e-8);
  }
  const BarFunctions d = bar_function_derivatives_permanent_contact();
  const BarFunctions p = bar_functions(-3.0 + 1e-6), m = bar_functions(-3.0 - 1e-6);
  EXPECT_NEAR(d.omega, (p.omega - m.omega) / 2e-6, 1e-8);
  EXPECT_NEAR(d.psi_i, (p.psi_i - m.psi_i) / 2e-6, 1e-8);
}

TEST(DescribingFunctions, PrintedRepulsiveFormsWithCorrectedSign) {
  // Eqs. (13), (14) as printed (with the corrected sign of Im N1 for q < −1), written out independently.
  const double ka = 10.0, kb = 8.0, b = 2.0;
  const auto law = PiecewiseLinearLaw::linear_hysteresis(ka, kb);
  for (double q : {-2.5, -1.2, -0.6, 0.0, 0.4, 0.95, 1.3}) {
    double mean;
    std::complex<double> n1;
    if (q > 1) {
      mean = 0;
      n1 = 0;
    } else if (q >= -1) {
      mean = (ka + kb) / (2 * pi) * b * (q * std::acos(q) - std::sqrt(1 - q * q));
      n1 = {-(ka + kb) / (2 * pi) * (q * std::sqrt(1 - q * q) - std::acos(q)), (ka - kb) / (2 * pi) * (1 - q) * (1 - q)};
    } else {
      mean = (ka + kb) / 2 * b * q;
      n1 = {(ka + kb) / 2, -2 * (ka - kb) / pi * q};
    }
    const DescribingFunctions df = describing_functions(law, q, b);
    EXPECT_NEAR(df.mean, mean, 1e-13) << q;
    EXPECT_NEAR(std::abs(df.first_harmonic - n1), 0.0, 1e-13) << q;
    EXPECT_GE(df.first_harmonic.imag(), 0.0);  // dissipation for K_a ≥ K_b
  }
}

TEST(DescribingFunctions, BadInput) {
  const auto law = PiecewiseLinearLaw::linear_hysteresis(10.0, 8.0);
  EXPECT_THROW(describing_functions(law, std::nan(""), 1.0), InvalidParameter);
  EXPECT_THROW(describing_functions(law, INFINITY, 1.0), InvalidParameter);
  EXPECT_THROW(describing_functions(law, 0.5, 0.0), InvalidParameter);
  EXPECT_THROW(bar_functions_from_contact_angle(4.0), InvalidParameter);
  // (any other law now has numerical describing functions: test_numerical_df.cpp)
}

}  // namespace
}  // namespace afmkit::tapping
