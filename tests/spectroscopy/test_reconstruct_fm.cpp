// FM force reconstruction (Sader–Jarvis, matrix method) against closed forms of the first-order frequency shift,
// against an independent quadrature of the forward integral, with noise, and its round trip.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/spectroscopy/reconstruct_fm.hpp"
#include "afmkit/spectroscopy/reconstruct_kernels.hpp"
#include "afmkit/spectroscopy/reconstruct_law.hpp"

namespace sp = afmkit::spectroscopy;

namespace {

constexpr double k_qplus = 1800.0;    // qPlus sensor [N/m]
constexpr double f0_qplus = 25000.0;  // [Hz]
constexpr double F0 = 1e-9;     // [N]
constexpr double lambda = 0.1e-9;  // [m]

/// Independent quadrature of the forward integral: Gauss–Chebyshev of the second form? No: midpoint rule in θ
/// with many nodes (u = −cos θ makes the integrand smooth), written here without the library's code.
template <class F>
double forward_midpoint(const F& force, double z, double a) {
  const int m = 4000;
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    const double th = (i + 0.5) * std::numbers::pi / m;
    sum += force(z + a * (1.0 - std::cos(th))) * std::cos(th);
  }
  return f0_qplus / (std::numbers::pi * k_qplus * a) * sum * std::numbers::pi / m;  // −(f0/πkA)·(−∫ F cos θ dθ)
}

double exponential_force(double z) { return -F0 * std::exp(-z / lambda); }

sp::FmCurve exponential_curve(const sp::FmSettings& s, int n, double z_max) {
  sp::FmCurve c;
  for (int i = 0; i < n; ++i) {
    const double z = 0.05e-9 + z_max * i / (n - 1);
    c.distance.push_back(z);
    c.frequency_shift.push_back(sp::exponential_force_frequency_shift(z, F0, lambda, s));
  }
  return c;
}

double max_error(const sp::FmReconstruction& r, double (*law)(double), double z_limit) {
  double e = 0.0;
  for (std::size_t i = 0; i < r.distance.size(); ++i)
    if (r.distance[i] <= z_limit) e = std::max(e, std::abs(r.force[i] - law(r.distance[i])));
  return e;
}

}  // namespace

TEST(ReconstructFm, ClosedFormsMatchAnIndependentQuadrature) {
  for (double a : {0.01e-9, 0.1e-9, 1e-9, 10e-9}) {
    const sp::FmSettings s(k_qplus, f0_qplus, a);
    for (double z : {0.05e-9, 0.2e-9, 0.5e-9}) {
      const double exact = sp::exponential_force_frequency_shift(z, F0, lambda, s);
      EXPECT_NEAR(forward_midpoint(exponential_force, z, a), exact, 1e-9 * std::abs(exact)) << a << " " << z;
      const double c = 1e-28;  // C = A_H R / 6 [N m²]
      const double vdw = sp::inverse_square_force_frequency_shift(z, c, s);
      EXPECT_NEAR(forward_midpoint([c](double x) { return -c / (x * x); }, z, a), vdw, 1e-6 * std::abs(vdw));
      // the library's forward quadrature
      EXPECT_NEAR(sp::forward_frequency_shift(exponential_force, z, k_qplus, f0_qplus, a, {}), exact, 1e-9 * std::abs(exact));
    }
  }
}

TEST(ReconstructFm, ExponentialForceAtSmallMediumAndLargeAmplitude) {
  // bound: 1 % of F0 (Sader–Jarvis: the formula is within ~5 % of the exact inverse at intermediate amplitudes,
  // measured here below 1 % for the exponential law; matrix method: discretisation only)
  for (double a : {0.01e-9, 0.1e-9, 1e-9, 5e-9}) {
    const sp::FmSettings s(k_qplus, f0_qplus, a);
    const sp::FmCurve c = exponential_curve(s, 400, 2.0e-9);
    for (auto method : {sp::FmMethod::sader_jarvis, sp::FmMethod::matrix}) {
      sp::FmOptions o;
      o.method = method;
      const auto r = sp::reconstruct_fm(c, s, o);
      const double bound = method == sp::FmMethod::sader_jarvis ? 0.05 * F0 : 0.01 * F0;
      EXPECT_LT(max_error(r, exponential_force, 1.0e-9), bound) << sp::to_string(method) << " A = " << a;
      // round trip: the table law back through the forward formula reproduces Δf
      double df_max = 0;
      for (double v : c.frequency_shift) df_max = std::max(df_max, std::abs(v));
      EXPECT_LT(r.residual_rms, 0.02 * df_max) << sp::to_string(method) << " A = " << a;
    }
  }
}

namespace {
constexpr double c_vdw = 1e-19 * 10e-9 / 6.0;  // A_H R / 6 [N m²]: A_H = 1e-19 J, R = 10 nm
double vdw_force(double z) { return -c_vdw / (z * z); }
}  // namespace

TEST(ReconstructFm, VanDerWaalsForceOnAGeometricGrid) {
  // the closed form of the forward integral, Δf = −f0 C/(k (z(z + 2A))^{3/2}), on a non-uniform grid
  for (double a : {0.05e-9, 1e-9, 20e-9}) {
    const sp::FmSettings s(k_qplus, f0_qplus, a);
    sp::FmCurve c;
    const int n = 300;
    for (int i = 0; i < n; ++i) {
      const double z = 0.3e-9 * std::pow(100.0, static_cast<double>(i) / (n - 1));
      c.distance.push_back(z);
      c.frequency_shift.push_back(sp::inverse_square_force_frequency_shift(z, c_vdw, s));
    }
    for (auto method : {sp::FmMethod::sader_jarvis, sp::FmMethod::matrix}) {
      sp::FmOptions o;
      o.method = method;
      const auto r = sp::reconstruct_fm(c, s, o);
      // relative bound over z ≤ 3 nm: 5 % (Sader–Jarvis interpolation formula), 2 % (matrix: discretisation on a
      // grid 1.6 % geometric steps)
      const double bound = method == sp::FmMethod::sader_jarvis ? 0.05 : 0.02;
      for (std::size_t i = 0; i < r.distance.size(); ++i) {
        if (r.distance[i] <= 3e-9) {
          EXPECT_NEAR(r.force[i], vdw_force(r.distance[i]), bound * std::abs(vdw_force(r.distance[i])))
              << sp::to_string(method) << " A = " << a << " z = " << r.distance[i];
        }
      }
    }
  }
}

TEST(ReconstructFm, ExponentialTailRecoversATruncatedCurve) {
  // the curve stops at 0.2 nm (2λ) where |Δf| is still 22 % of its largest value; the zero tail biases the force,
  // the exponential one (fitted to the last points) restores it
  const double a = 1e-9;
  const sp::FmSettings s(k_qplus, f0_qplus, a);
  const sp::FmCurve c = exponential_curve(s, 200, 0.15e-9);
  for (auto method : {sp::FmMethod::sader_jarvis, sp::FmMethod::matrix}) {
    sp::FmOptions zero, expo;
    zero.method = expo.method = method;
    expo.tail = sp::TailModel::exponential;
    const auto rz = sp::reconstruct_fm(c, s, zero), re = sp::reconstruct_fm(c, s, expo);
    ASSERT_TRUE(re.tail.active);
    EXPECT_NEAR(re.tail.decay_length, lambda, 1e-3 * lambda);
    EXPECT_GT(max_error(rz, exponential_force, 1.0), 0.1 * F0) << "the zero tail must show its bias here";
    EXPECT_LT(max_error(re, exponential_force, 1.0), 0.02 * F0) << sp::to_string(method);
    bool noted = false;
    for (const auto& n : rz.notes) noted = noted || n.find("does not reach the free region") != std::string::npos;
    EXPECT_TRUE(noted);
  }
}

TEST(ReconstructFm, NoiseIsEstimatedAndPropagatedWithAFixedSeed) {
  const double a = 1e-9;
  const sp::FmSettings s(k_qplus, f0_qplus, a);
  sp::FmCurve c = exponential_curve(s, 400, 2.0e-9);
  double df_max = 0.0;
  for (double v : c.frequency_shift) df_max = std::max(df_max, std::abs(v));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01 * df_max);
  for (double& v : c.frequency_shift) v += noise(rng);
  for (auto method : {sp::FmMethod::sader_jarvis, sp::FmMethod::matrix}) {
    sp::FmOptions o;
    o.method = method;
    o.exact_round_trip = false;  // this test is about the noise; the exact round trip is tested in Python
    const auto r1 = sp::reconstruct_fm(c, s, o), r2 = sp::reconstruct_fm(c, s, o);
    EXPECT_EQ(r1.force_uncertainty, r2.force_uncertainty);  // fixed seed
    EXPECT_NEAR(r1.noise, 0.01 * df_max, 0.3 * 0.01 * df_max);  // the estimate finds the noise added
    // the error is within 5σ of the reported uncertainty (itself estimated from 8 realisations) plus the formula's
    // own bound
    for (std::size_t i = 0; i < r1.distance.size(); ++i)
      EXPECT_LT(std::abs(r1.force[i] - exponential_force(r1.distance[i])),
                5.0 * r1.force_uncertainty[i] + 0.02 * F0)
          << sp::to_string(method) << " z = " << r1.distance[i];
  }
}

TEST(ReconstructFm, SeveralCurvesOnOneGridGiveWhatEachGivesAlone) {
  // the noise realisations are inverted together (the intervals' geometry shared): each exactly as alone, with
  // and without a tail, for both term choices, on an uneven grid with a varying amplitude
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  std::vector<double> t, amp;
  double z = 0.05e-9;
  for (int i = 0; i < 60; ++i, z += 0.02e-9 * u(rng)) {
    t.push_back(z);
    amp.push_back(1e-9 * u(rng));
  }
  std::vector<std::vector<double>> omegas(3, std::vector<double>(t.size()));
  for (auto& om : omegas)
    for (std::size_t i = 0; i < t.size(); ++i) om[i] = -1e-4 * std::exp(-t[i] / lambda) * u(rng);
  sp::ExponentialTail tail;
  tail.active = true;
  tail.value = omegas[0].back();
  tail.decay_length = lambda;
  for (const auto& with_tail : {sp::ExponentialTail{}, tail})
    for (bool inside : {false, true}) {
      sp::SaderJarvisTerms terms;
      terms.amplitude_inside_derivative = inside;
      const auto all = sp::sader_jarvis_forces(t, omegas, amp, k_qplus, terms, with_tail);
      ASSERT_EQ(all.size(), omegas.size());
      for (std::size_t m = 0; m < omegas.size(); ++m)
        EXPECT_EQ(all[m], sp::sader_jarvis_force(t, omegas[m], amp, k_qplus, terms, with_tail)) << m;
    }
}

TEST(ReconstructFm, ExactRoundTripOfADenseNoisyCurveReportsItsOrbitsAndStaysAtTheNoise) {
  // a qPlus curve with a 1 mHz ripple over 300 points: the reconstructed table law has a knot per point (a jump
  // of curvature at each), the hard case of the FM orbits' integration. The round trip at 12 distances finds an
  // orbit at each, counts the one-period simulations of their Newton solves (warm started: a few per orbit), and
  // reproduces the measured Δf to about the ripple (its RMS is 0.71 mHz; the inversion smooths part of it)
  const sp::FmSettings s(k_qplus, f0_qplus, 0.5e-9);
  sp::FmCurve c;
  double ripple2 = 0.0;
  for (int i = 0; i < 300; ++i) {
    const double z = 0.05e-9 + 2e-9 * i / 299.0, ripple = 1e-3 * std::sin(7.0 * i);
    c.distance.push_back(z);
    c.frequency_shift.push_back(sp::exponential_force_frequency_shift(z, F0, lambda, s) + ripple);
    ripple2 += ripple * ripple;
  }
  sp::FmOptions o;
  o.round_trip_points = 12;
  o.noise_realisations = 0;
  const auto r = sp::reconstruct_fm(c, s, o);
  EXPECT_EQ(r.round_trip_orbits, 12);
  EXPECT_GE(r.round_trip_simulations, 12);
  EXPECT_LE(r.round_trip_simulations, 6 * 12);
  EXPECT_LT(r.residual_rms, 3.0 * std::sqrt(ripple2 / 300.0));
  const auto first = [&] {
    sp::FmOptions f = o;
    f.exact_round_trip = false;
    return sp::reconstruct_fm(c, s, f);
  }();
  EXPECT_EQ(first.round_trip_orbits, 0);
  EXPECT_EQ(first.round_trip_simulations, 0);
}

TEST(ReconstructFm, BadInputNamesTheParameterAndIndex) {
  const sp::FmSettings s(k_qplus, f0_qplus, 1e-9);
  sp::FmCurve c = exponential_curve(s, 10, 1e-9);
  auto bad = c;
  bad.frequency_shift[8] = std::nan("");
  bad.frequency_shift[9] = std::nan("");
  try {
    sp::reconstruct_fm(bad, s);
    FAIL();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "frequency_shift");
    EXPECT_NE(std::string(e.what()).find("frequency_shift[8]"), std::string::npos);
  }
  bad = c;
  std::swap(bad.distance[3], bad.distance[4]);
  EXPECT_THROW(sp::reconstruct_fm(bad, s), afmkit::InvalidParameter);
  EXPECT_THROW(sp::FmSettings(k_qplus, f0_qplus, 0.0), afmkit::InvalidParameter);
  EXPECT_THROW(sp::FmSettings(-1.0, f0_qplus, 1e-9), afmkit::InvalidParameter);
  // a curve in decreasing distance order is the same curve
  auto reversed = c;
  std::reverse(reversed.distance.begin(), reversed.distance.end());
  std::reverse(reversed.frequency_shift.begin(), reversed.frequency_shift.end());
  EXPECT_EQ(sp::reconstruct_fm(reversed, s).force, sp::reconstruct_fm(c, s).force);
}
