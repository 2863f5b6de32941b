// AM force reconstruction on synthetic curves made by afmkit's own exact orbits (tapping sweep, approach) from a
// DMT + van der Waals law and from a hysteresis (adhesion-hysteresis DMT) law: conservative force, dissipation,
// round trip; bad input.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/force_law.hpp"
#include "afmkit/spectroscopy/reconstruct_am.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"

namespace sp = afmkit::spectroscopy;
namespace tp = afmkit::tapping;
namespace im = afmkit::impact;

namespace {

constexpr double k = 40.0, f0 = 300e3, Q = 400.0, A0 = 10e-9;
// measured 24 % with 5 pm / 0.05° noise on 40 points: the inversion differentiates the data
constexpr double NOISY_BOUND = 0.35;

struct Synthetic {
  sp::AmCurve curve;
  std::vector<double> contact_dissipation;  // [J], from the orbits' own energy balance
};

/// The approach of an instrument sweep (physical units: nm, nN) as a measured AM curve in SI units.
Synthetic synthetic(const im::ForceLaw& law, double l_min_nm, double l_max_nm, int n) {
  const tp::PhysicalCantilever pc(k, f0 * 1e-3, Q, A0 * 1e9, 1.0);
  std::vector<double> l;
  for (int i = 0; i < n; ++i) l.push_back(l_min_nm + (l_max_nm - l_min_nm) * i / (n - 1));
  const tp::TappingModel m(pc.cantilever(), pc.drive(), pc.normalised_law(law), l.back());
  tp::SweepOptions o;
  o.harmonic_balance = false;
  const auto sw = tp::sweep_instrument(m, l, o);
  Synthetic s;
  for (const auto& p : sw.approach) {
    s.curve.separation.push_back(p.separation * 1e-9);
    s.curve.amplitude.push_back(p.metrics.amplitude * 1e-9);
    s.curve.phase.push_back(p.metrics.phase);
    s.contact_dissipation.push_back(p.metrics.contact_dissipation * k * 1e-18);  // model nm² ω_n² · k -> aJ -> J
  }
  return s;
}

double max_force_error(const sp::AmReconstruction& r, const im::ForceLaw& law, double& f_max) {
  double e = 0.0;
  f_max = 0.0;
  for (std::size_t i = 0; i < r.gap.size(); ++i) {
    const double d = r.gap[i] * 1e9;
    const double truth = 0.5 * (law.approach(d) + law.departure(d)) * 1e-9;
    f_max = std::max(f_max, std::abs(truth));
    e = std::max(e, std::abs(r.force[i] - truth));
  }
  return e;
}

}  // namespace

TEST(ReconstructAm, DissipationFormulaMatchesTheOrbitsEnergyBalance) {
  // hysteresis law: the departure branch more adhesive (A_H,b > A_H,a) and softer: the orbits dissipate
  const im::ForceLaw law(im::DmtLaw(1.0, 0.5, 10.0, 1e-19, 2e-19, 0.165));
  const Synthetic s = synthetic(law, 6.0, 12.0, 25);
  const sp::AmSettings set(k, f0, Q, A0);
  double e_max = 0.0;
  for (double e : s.contact_dissipation) e_max = std::max(e_max, e);
  ASSERT_GT(e_max, 1e-20);
  for (std::size_t i = 0; i < s.curve.separation.size(); ++i) {
    // the first-harmonic balance is exact for the energy: drive work and viscous loss involve only the first
    // harmonic; bound 1 % of the largest dissipation (the orbit's harmonics, solver tolerances)
    EXPECT_NEAR(sp::dissipated_energy(s.curve.amplitude[i], s.curve.phase[i], set), s.contact_dissipation[i],
                0.01 * e_max)
        << "l = " << s.curve.separation[i];
  }
}

TEST(ReconstructAm, ConservativeDmtForceFromExactOrbits) {
  const im::ForceLaw law(im::DmtLaw(1.0, 1.0, 10.0, 1e-19, 1e-19, 0.165));
  const Synthetic s = synthetic(law, 6.0, 12.0, 40);
  const sp::AmSettings set(k, f0, Q, A0);
  for (auto method : {sp::AmMethod::payam, sp::AmMethod::hoelscher}) {
    sp::AmOptions o;
    o.method = method;
    o.round_trip_points = 20;
    const auto r = sp::reconstruct_am(s.curve, set, o);
    double f_max = 0.0;
    const double e = max_force_error(r, law, f_max);
    // bound: 5 % of the largest attraction probed (measured 2–3 %: the first-harmonic balance, D = l − A)
    EXPECT_LT(e, 0.05 * f_max) << sp::to_string(method);
    EXPECT_TRUE(std::isnan(r.contact_gap)) << "a conservative law: no branch difference";
    // round trip: the law back through exact orbits reproduces the curve
    EXPECT_LT(r.rms_amplitude_ratio, 0.01) << sp::to_string(method);
    EXPECT_LT(r.rms_phase, 0.02) << sp::to_string(method);
  }
}

TEST(ReconstructAm, HysteresisLawDissipationBecomesABranchDifference) {
  const im::ForceLaw law(im::DmtLaw(1.0, 0.5, 10.0, 1e-19, 2e-19, 0.165));
  const Synthetic s = synthetic(law, 6.0, 12.0, 40);
  const sp::AmSettings set(k, f0, Q, A0);
  sp::AmOptions o;
  o.round_trip_points = 20;
  const auto r = sp::reconstruct_am(s.curve, set, o);
  double f_max = 0.0;
  const double e = max_force_error(r, law, f_max);
  EXPECT_LT(e, 0.05 * f_max);
  ASSERT_TRUE(std::isfinite(r.contact_gap));
  // the branches differ only near the surface (where the measured dissipation exceeds its threshold), and the law
  // dissipates what was measured: the round trip's phase
  EXPECT_LT(r.contact_gap, 3e-9);
  EXPECT_LT(r.rms_amplitude_ratio, 0.01);
  EXPECT_LT(r.rms_phase, 0.02);
}

TEST(ReconstructAm, NoisyCurveStaysWithinItsBoundAndSaysSo) {
  // instrument noise on the exact-orbit curve (fixed seed): 5 pm in amplitude, 0.05° in phase
  const im::ForceLaw law(im::DmtLaw(1.0, 1.0, 10.0, 1e-19, 1e-19, 0.165));
  Synthetic s = synthetic(law, 6.0, 12.0, 40);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> da(0.0, 5e-12), dp(0.0, 0.05 * std::numbers::pi / 180.0);
  for (double& a : s.curve.amplitude) a += da(rng);
  for (double& p : s.curve.phase) p += dp(rng);
  const sp::AmSettings set(k, f0, Q, A0);
  sp::AmOptions o;
  o.round_trip_points = 10;
  const auto r = sp::reconstruct_am(s.curve, set, o);
  double f_max = 0.0;
  const double e = max_force_error(r, law, f_max);
  std::printf("noisy AM: max force error %.3g of %.3g nN, rms A/A0 %.3g, rms phase %.3g rad\n", e * 1e9,
              f_max * 1e9, r.rms_amplitude_ratio, r.rms_phase);
  EXPECT_LT(e, NOISY_BOUND * f_max);
  EXPECT_LT(r.rms_phase, 0.02);
  bool noted = false;
  for (const auto& n : r.notes) noted = noted || n.find("noisy data") != std::string::npos;
  EXPECT_TRUE(noted) << "the result must say the data are noisy";
}

TEST(ReconstructAm, ExponentialTailContinuesTheLaw) {
  // the curve stops at l = 9 nm, where the van der Waals attraction is still felt: the exponential tail continues
  // the law beyond the last D (20 points over 10 λ), the zero tail ends it there
  const im::ForceLaw law(im::DmtLaw(1.0, 1.0, 10.0, 1e-19, 1e-19, 0.165));
  const Synthetic s = synthetic(law, 6.0, 9.0, 30);
  const sp::AmSettings set(k, f0, Q, A0);
  sp::AmOptions zero, expo;
  zero.round_trip = expo.round_trip = false;
  expo.tail = sp::TailModel::exponential;
  const auto rz = sp::reconstruct_am(s.curve, set, zero), re = sp::reconstruct_am(s.curve, set, expo);
  EXPECT_EQ(rz.law.approach_gap.size(), rz.gap.size());
  ASSERT_EQ(re.law.approach_gap.size(), re.gap.size() + 20);
  EXPECT_GT(re.law.approach_gap.back(), re.gap.back() * 1e9);
  EXPECT_LT(re.law.approach_force.back(), 0.0);  // still attractive, decaying
  EXPECT_GT(re.law.approach_force.back(), re.law.approach_force[re.gap.size() - 1]);
}

TEST(ReconstructAm, BadInputNamesTheParameter) {
  sp::AmCurve c{{1e-9, 2e-9, 3e-9, 4e-9, 5e-9}, {1e-9, 2e-9, 3e-9, 4e-9, 5e-9}, {2.0, 1.9, 1.8, 1.7, 1.6}};
  const sp::AmSettings set(k, f0, Q, A0);
  auto bad = c;
  bad.phase[2] = 3.5;
  try {
    sp::reconstruct_am(bad, set);
    FAIL();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "phase");
    EXPECT_NE(std::string(e.what()).find("phase[2]"), std::string::npos);
  }
  bad = c;
  bad.amplitude[1] = 0.0;
  EXPECT_THROW(sp::reconstruct_am(bad, set), afmkit::InvalidParameter);
  bad = c;
  bad.separation[3] = 1.5e-9;
  EXPECT_THROW(sp::reconstruct_am(bad, set), afmkit::InvalidParameter);
  EXPECT_THROW(sp::AmSettings(k, f0, Q, -1e-9), afmkit::InvalidParameter);
}

TEST(ReconstructAm, KatanInvertsTheFrequencyOfTheEquivalentOscillator) {
  // Katan, van Es & Oosterkamp (2009): the AM curve is the FM curve of the oscillator whose frequency balances the
  // in-phase force, (ω/ω0)² = 1 + (A0/(Q A)) cos φ at the resonance drive: Ω = √(1 + (A0/(Q A)) cos φ) − 1, not
  // its first-order part (A0/(2 Q A)) cos φ (the two differ by (A0 cos φ/(Q A))²/8). Low Q makes it visible.
  const double q = 5.0;
  sp::AmCurve c;
  for (int i = 0; i < 20; ++i) {
    c.separation.push_back((4.0 + 0.5 * i) * 1e-9);
    c.amplitude.push_back((6.0 + 0.2 * i) * 1e-9);
    c.phase.push_back(std::numbers::pi / 2 + 0.6 * std::exp(-0.3 * i));  // attractive: lag above 90°
  }
  const sp::AmSettings set(k, f0, q, A0);
  sp::AmOptions o;
  o.method = sp::AmMethod::katan;
  o.round_trip = false;
  const auto r = sp::reconstruct_am(c, set, o);
  ASSERT_EQ(r.omega.size(), c.separation.size());
  for (std::size_t i = 0; i < r.omega.size(); ++i) {
    const double x = A0 * std::cos(c.phase[i]) / (q * c.amplitude[i]);
    EXPECT_NEAR(r.omega[i], std::sqrt(1.0 + x) - 1.0, 1e-15) << i;
  }
  // payam and hoelscher invert the first-order Ω (linear in the virial)
  o.method = sp::AmMethod::payam;
  const auto p = sp::reconstruct_am(c, set, o);
  for (std::size_t i = 0; i < p.omega.size(); ++i)
    EXPECT_NEAR(p.omega[i], A0 * std::cos(c.phase[i]) / (2.0 * q * c.amplitude[i]), 1e-15) << i;
  // no equivalent oscillator: 1 + (A0/(Q A)) cos φ ≤ 0 is refused, naming the phase and the index
  auto bad = c;
  bad.amplitude[3] = 0.1e-9;
  bad.phase[3] = 3.0;
  o.method = sp::AmMethod::katan;
  try {
    sp::reconstruct_am(bad, set, o);
    FAIL();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "phase");
    EXPECT_NE(std::string(e.what()).find("phase[3]"), std::string::npos);
  }
}
