// Edge cases of the impact solvers (issue 6): nearly elastic impacts (e -> 1, seed-1 eqs. 2, 3, 6 and
// ext. E0), laws that would create energy (K_b > K_a), extreme inputs, and the streamed history.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/impact.hpp"

using namespace afmkit::impact;
using afmkit::InvalidParameter;

namespace {

using ld = long double;
constexpr double eps = std::numeric_limits<double>::epsilon();
const double deficits[] = {1e-3, 1e-6, 1e-9, 1e-12};  // 1 − e

double rel(double value, ld reference) { return static_cast<double>(std::fabs((value - reference) / reference)); }

/// Independent reference in long double: arc-by-arc geometry of the relative motion
///   μ d̈ = μ g − (F + K d) (d < 0),  μ d̈ = μ g (d ≥ 0),
/// branch a until ḋ = 0, branch b after (seed-1 eq. 4). Each contact arc is a circle of radius R about the
/// equilibrium c = (μ g − F)/K in the (d, ḋ/ω) plane; free flight keeps ḋ² − 2 g d. Returns ḋ(t_f) > 0 and d(t̄).
struct Reference {
  ld exit_rate, minimum_gap;
};
Reference reference(ld ka, ld kb, ld fa, ld fb, ld mu, ld g, ld d0, ld v0) {
  ld d = d0, v2 = v0 * v0;
  if (d >= 0) {  // free flight to the contact edge
    v2 -= 2 * g * d;
    d = 0;
  }
  const ld ca = (mu * g - fa) / ka;
  const ld minimum = ca - std::sqrt((d - ca) * (d - ca) + v2 * mu / ka);
  const ld cb = (mu * g - fb) / kb;
  const ld top = std::min<ld>(d0, 0);
  ld exit2 = kb / mu * ((cb - minimum) * (cb - minimum) - (top - cb) * (top - cb));
  if (d0 > 0) exit2 += 2 * g * d0;
  return {std::sqrt(exit2), minimum};
}

}  // namespace

// Defect 1: nearly elastic impacts. Closed form e = √(K_b/K_a), ΔE = (1 − e²) μ v²/2 = (K_a − K_b)/K_a · μ v²/2
// (seed-1 ext. E0 and eq. 3), evaluated in long double from the stored K_a, K_b (K_a − K_b is exact).
TEST(NearlyElastic, ClosedFormKeepsRelativeAccuracyOfOneMinusEAndTheLoss) {
  static_assert(LDBL_MANT_DIG >= 64, "the reference needs extended precision");
  for (double deficit : deficits) {
    const double ka = 7.0, kb = PiecewiseLinearLaw::departure_stiffness_for_restitution(ka, 1.0 - deficit);
    const double m1 = 0.3, m2 = 2.5, speed = 1.7;
    const auto problem = ImpactProblem::head_on(m1, m2, speed, 0.4, PiecewiseLinearLaw::linear_hysteresis(ka, kb));
    const ImpactResult r = simulate_impact(problem);
    ASSERT_EQ(r.outcome, ImpactOutcome::separated) << deficit;
    const ld v = problem.initial_gap_rate(), mu = static_cast<ld>(m1) * m2 / (static_cast<ld>(m1) + m2);
    const ld x = (static_cast<ld>(ka) - kb) / ka;  // 1 − e²
    const ld e = std::sqrt(static_cast<ld>(kb) / ka), loss = x * mu * v * v / 2;
    EXPECT_LT(rel(r.restitution, e), 2 * eps) << deficit;
    EXPECT_LT(rel(r.restitution_deficit, x / (1 + e)), 1e-14) << deficit;
    EXPECT_LT(rel(r.kinetic_energy_loss, loss), 1e-14) << deficit;
    EXPECT_LT(rel(r.energy_loss_area, loss), 1e-14) << deficit;         // eq. (6)
    EXPECT_LT(rel(r.energy_loss_restitution, loss), 1e-14) << deficit;  // eq. (3)
    EXPECT_LT(std::abs(r.energy_balance_residual), 8 * eps * 0.5 * static_cast<double>(mu * v * v)) << deficit;
    // K_b from e: K_a − K_b carries only the rounding of K_b (half an ulp of K_a), not that of e².
    const double target = (1.0 - (1.0 - deficit)) * (2.0 - deficit);  // 1 − e² for the given e (1 − e exact)
    EXPECT_LE(std::abs((ka - kb) / ka - target), std::nextafter(ka, 2 * ka) - ka) << deficit;
  }
}

// Defect 1, simulated path: adhesion (eq. 26), constant external forces, start inside or outside the contact,
// against the long-double arc geometry above (independent of the library's energy balance).
TEST(NearlyElastic, ClosedFormWithAdhesionAndForcesMatchesLongDoubleArcs) {
  for (double d0 : {0.3, -0.02}) {
    for (double deficit : deficits) {
      const double ka = 12.0, kb = ka * (1.0 - 2.0 * deficit), fa = 0.25, fb = 0.25 * (1.0 + deficit);
      const double m1 = 1.5, m2 = 0.4, f1 = 0.1, f2 = -0.05;
      const Body b1{m1, -0.1, 0.6}, b2{m2, -0.1 + d0, -1.1};
      ExternalForces ext;
      ext.on_body1 = f1;
      ext.on_body2 = f2;
      const ImpactProblem problem(b1, b2, PiecewiseLinearLaw(ka, kb, fa, fb), ext);
      const ImpactResult r = simulate_impact(problem);
      ASSERT_EQ(r.outcome, ImpactOutcome::separated);
      const ld mu = static_cast<ld>(m1) * m2 / (static_cast<ld>(m1) + m2);
      const ld g = static_cast<ld>(f2) / m2 - static_cast<ld>(f1) / m1;
      const ld v0 = static_cast<ld>(b2.velocity) - b1.velocity;
      const Reference ref = reference(ka, kb, fa, fb, mu, g, d0, v0);
      const ld loss = mu / 2 * (v0 * v0 - ref.exit_rate * ref.exit_rate);
      // long-double cancellation in the reference: ~LDBL_EPSILON/(1 − e) relative
      const double tol = 1e-13 + 1e3 * LDBL_EPSILON / deficit;
      EXPECT_LT(rel(r.minimum_gap, ref.minimum_gap), 1e-14) << d0 << " " << deficit;
      EXPECT_LT(rel(r.departure_gap_rate, ref.exit_rate), 1e-15) << d0 << " " << deficit;
      EXPECT_LT(rel(r.restitution_deficit, 1 + ref.exit_rate / v0), tol) << d0 << " " << deficit;
      EXPECT_LT(rel(r.energy_loss_area, loss), tol) << d0 << " " << deficit;
      // simulated relative-motion loss (kinetic_energy_loss also holds the centre-of-mass part, changed by
      // the external forces): ½μ(v0² − v_f²)
      EXPECT_LT(rel(r.energy_loss_restitution, loss), tol) << d0 << " " << deficit;
    }
  }
}

// Defect 1, integrator: its d(t̄) has a relative error ~ the tolerance; the loss must keep that relative
// accuracy as e -> 1 (the integrated ḋ(t_f) alone would give tolerance/(1 − e)).
TEST(NearlyElastic, IntegratorLossStaysRelativelyAccurate) {
  for (double deficit : deficits) {
    const double ka = 7.0, kb = PiecewiseLinearLaw::departure_stiffness_for_restitution(ka, 1.0 - deficit);
    const auto problem = ImpactProblem::head_on(0.3, 2.5, 1.7, 0.4, PiecewiseLinearLaw::linear_hysteresis(ka, kb));
    const ImpactResult r = simulate_impact(problem, {.method = ImpactMethod::integrator});
    ASSERT_EQ(r.method, "integrator");
    const ld mu = 0.3L * 2.5L / 2.8L, v = problem.initial_gap_rate();
    const ld x = (static_cast<ld>(ka) - kb) / ka, loss = x * mu * v * v / 2;
    EXPECT_LT(rel(r.kinetic_energy_loss, loss), 1e-8) << deficit;
    EXPECT_LT(rel(r.restitution_deficit, x / (1 + std::sqrt(1 - x))), 1e-8) << deficit;
    EXPECT_LT(rel(r.energy_loss_area, loss), 1e-8) << deficit;
    // the raw integrated state obeys eq. (6) to the integration tolerance (absolute, in units of the KE)
    EXPECT_LT(std::abs(r.energy_balance_residual), 1e-8 * r.kinetic_energy_before) << deficit;
  }
}

// Defect 1, eq. (6) for the other laws: DMT in closed form (differences of the branch parameters) and the
// quadrature of custom laws, converged relative to the loss or the rounding floor of H_a − H_b.
TEST(NearlyElastic, Eq6AreaForDmtAndCustomLaws) {
  for (double deficit : deficits) {
    const double ea = 1.0, eb = 1.0 - deficit, r_tip = 10.0, a0 = 0.165, dmin = -0.7;
    const DmtLaw dmt(ea, eb, r_tip, 6.4e-20, 6.4e-20, a0);
    // ∫_{dmin}^{a0} (4/3)(E*_a − E*_b)√R (a0 − ξ)^{3/2} dξ = (8/15)(E*_a − E*_b)√R (a0 − dmin)^{5/2}; vdW cancels
    const ld expected = 8.0L / 15 * (static_cast<ld>(ea) - eb) * std::sqrt(static_cast<ld>(r_tip)) *
                        std::pow(static_cast<ld>(a0) - dmin, 2.5L);
    EXPECT_LT(rel(hysteresis_energy_loss(dmt, dmin, 2.0), expected), 1e-14) << deficit;

    const double ka = 9.0, kb = ka * (1.0 - 2.0 * deficit);
    CustomLaw custom{[ka](double d) { return d < 0 ? -ka * d : 0.0; }, [kb](double d) { return d < 0 ? -kb * d : 0.0; },
                     {0.0}, "custom_linear"};
    const ld area = (static_cast<ld>(ka) - kb) / 2 * dmin * dmin;
    // H_a − H_b is a difference of two values known to ε|H|: relative floor ~ ε(K_a + K_b)/(K_a − K_b)
    const double floor = 1e-9 + 4 * eps * (ka + kb) / (ka - kb);
    double got = 0;
    ASSERT_NO_THROW(got = hysteresis_energy_loss(ForceLaw(custom), dmin, 0.5)) << deficit;
    EXPECT_LT(rel(got, area), floor) << deficit;
  }
}

// Defect 2: e = 1 exactly (K_b = K_a) is an ordinary impact without loss.
TEST(ElasticLimit, EqualStiffnessesGiveExactlyElasticImpact) {
  for (auto method : {ImpactMethod::closed_form, ImpactMethod::integrator}) {
    const auto r = simulate_impact(ImpactProblem::head_on(1.0, 3.0, 2.0, 0.5, PiecewiseLinearLaw::linear_hysteresis(50, 50)),
                                   {.method = method});
    ASSERT_EQ(r.outcome, ImpactOutcome::separated);
    EXPECT_EQ(r.energy_loss_area, 0.0);
    EXPECT_EQ(r.restitution, 1.0);
    EXPECT_EQ(r.restitution_deficit, 0.0);
    EXPECT_EQ(r.energy_loss_restitution, 0.0);
    EXPECT_NEAR(r.kinetic_energy_loss, 0.0, 4 * eps * r.kinetic_energy_before);
  }
  EXPECT_EQ(PiecewiseLinearLaw::departure_stiffness_for_restitution(50.0, 1.0), 50.0);
}

// Defect 2: a law that creates energy is rejected unless it opts in.
TEST(EnergyGain, StiffnessAboveApproachIsRejectedUnlessAllowed) {
  try {
    ImpactProblem::head_on(1, 1, 1, 0.5, PiecewiseLinearLaw::linear_hysteresis(50, 60));
    FAIL() << "K_b > K_a accepted";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "departure_stiffness");
    const std::string what = e.what();
    EXPECT_NE(what.find("departure_stiffness = 60 must be <= approach_stiffness = 50"), std::string::npos) << what;
    EXPECT_NE(what.find("allow_energy_gain"), std::string::npos) << what;
  }
  // attractive law too (adhesion does not excuse K_b > K_a); scaled laws report the user's coefficients
  EXPECT_THROW(ImpactProblem::head_on(1, 1, 1, 0.5, ForceLaw(PiecewiseLinearLaw(5, 6, 0.1, 0.3)).scaled(3.0)),
               InvalidParameter);
  // opt-in: e = √(K_b/K_a) > 1 and a negative loss −½(K_b − K_a)δ², δ = v√(μ/K_a)
  const auto r = simulate_impact(ImpactProblem::head_on(1, 1, 1, 0.5, PiecewiseLinearLaw(50, 60, 0, 0, true)));
  ASSERT_EQ(r.outcome, ImpactOutcome::separated);
  EXPECT_NEAR(r.restitution, std::sqrt(60.0 / 50.0), 1e-15);
  const double delta2 = 0.5 / 50.0;
  EXPECT_NEAR(r.kinetic_energy_loss, -0.5 * 10.0 * delta2, 1e-15);
  EXPECT_NEAR(r.energy_loss_area, -0.5 * 10.0 * delta2, 1e-15);
  EXPECT_LT(r.restitution_deficit, 0.0);
}

TEST(EnergyGain, RestitutionRangeAndDmtConditions) {
  for (double e : {0.0, -0.5, 1.5, std::nan(""), std::numeric_limits<double>::infinity()}) {
    try {
      PiecewiseLinearLaw::departure_stiffness_for_restitution(10.0, e);
      FAIL() << e;
    } catch (const InvalidParameter& ex) {
      EXPECT_EQ(ex.parameter(), "restitution");
      EXPECT_NE(std::string(ex.what()).find("(0, 1]"), std::string::npos) << ex.what();
    }
  }
  EXPECT_DOUBLE_EQ(PiecewiseLinearLaw::departure_stiffness_for_restitution(10.0, 1.5, true), 22.5);
  EXPECT_THROW(PiecewiseLinearLaw::departure_stiffness_for_restitution(10.0, 0.0, true), InvalidParameter);

  auto expect_rejected = [](const DmtLaw& law, const char* name) {
    try {
      ImpactProblem::head_on(3e-10, 1e-11, 3e6, 2.0, law);
      FAIL() << name;
    } catch (const InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), name);
    }
  };
  expect_rejected(DmtLaw(1.0, 1.2, 10, 6.4e-20, 6.4e-20, 0.165), "departure_modulus");
  expect_rejected(DmtLaw(1.0, 0.8, 10, 6.4e-20, 1e-20, 0.165), "departure_hamaker");
  const auto gain = simulate_impact(ImpactProblem::head_on(3e-10, 1e-11, 3e6, 2.0,
                                                           DmtLaw(1.0, 1.2, 10, 6.4e-20, 6.4e-20, 0.165, true)));
  ASSERT_EQ(gain.outcome, ImpactOutcome::separated);
  EXPECT_GT(gain.restitution, 1.0);
  EXPECT_LT(gain.energy_loss_area, 0.0);
  EXPECT_NEAR(gain.energy_balance_residual, 0.0, 1e-8 * gain.kinetic_energy_before);
}

// Every extreme input is an InvalidParameter naming what to change, never a crash, hang or NaN result.
TEST(ExtremeInputs, OutOfRangeScalesAreInvalidParameters) {
  const auto law = PiecewiseLinearLaw::linear_hysteresis(10, 8);
  auto param_of = [](auto&& make) -> std::string {
    try {
      make();
    } catch (const InvalidParameter& e) {
      return e.parameter();
    }
    return "(accepted)";
  };
  EXPECT_EQ(param_of([&] { ImpactProblem::head_on(1e308, 1e308, 1, 1, law); }), "mass1");          // m1 + m2 = inf
  EXPECT_EQ(param_of([&] { ImpactProblem::head_on(1e-320, 1, 1, 1, law); }), "mass1");            // μ subnormal
  EXPECT_EQ(param_of([&] { ImpactProblem::head_on(1, 1, 1e-170, 1, law); }), "relative_velocity");  // ½μv² = 0
  EXPECT_EQ(param_of([&] { ImpactProblem::head_on(1e10, 1e10, 1e150, 1, law); }), "relative_velocity");
  EXPECT_EQ(param_of([&] { ImpactProblem::head_on(1, 1, std::nan(""), 1, law); }), "approach_speed");
  EXPECT_EQ(param_of([&] { ImpactProblem::head_on(1, 1, 1, std::numeric_limits<double>::infinity(), law); }), "gap");
  EXPECT_EQ(param_of([&] { ImpactProblem(Body{1, 0, 1}, Body{1, 1, 1}, law); }), "relative_velocity");  // zero
  EXPECT_EQ(param_of([&] {
              simulate_impact(ImpactProblem::head_on(1e-300, 1e-300, 1e100, 1, PiecewiseLinearLaw::linear_hysteresis(1e300, 1e300)));
            }),
            "approach_stiffness");
  EXPECT_EQ(param_of([&] { simulate_impact(ImpactProblem::head_on(1e-10, 1e-10, 1e-140, 1e300, law)); }), "parameters");
  // tiny and huge but representable scales work and keep e = √(K_b/K_a)
  for (auto [m, v, k] : {std::tuple{1e-150, 1e-60, 1e-100}, std::tuple{1e120, 1e60, 1e140}}) {
    const auto r = simulate_impact(ImpactProblem::head_on(m, 2 * m, v, 0.0, PiecewiseLinearLaw::linear_hysteresis(k, 0.64 * k)));
    EXPECT_NEAR(r.restitution, 0.8, 1e-15) << m;
  }
}

// Defect 3: the history can be streamed (memory independent of history_points) and equals the stored one.
TEST(History, StreamedSamplesEqualStoredHistory) {
  const auto problem = ImpactProblem::head_on(1, 2, 1.5, 0.3, PiecewiseLinearLaw(10, 8, 0.2, 0.4));
  for (auto method : {ImpactMethod::closed_form, ImpactMethod::integrator}) {
    ImpactOptions options;
    options.method = method;
    options.history_points = 301;
    const ImpactResult stored = simulate_impact(problem, options);
    std::vector<ImpactSample> streamed;
    options.on_sample = [&streamed](const ImpactSample& s) { streamed.push_back(s); };
    const ImpactResult r = simulate_impact(problem, options);
    EXPECT_TRUE(r.history.empty());
    ASSERT_EQ(streamed.size(), stored.history.size());
    ASSERT_GE(streamed.size(), 301u);
    for (std::size_t i = 0; i < streamed.size(); ++i) {
      EXPECT_EQ(streamed[i].time, stored.history[i].time);
      EXPECT_EQ(streamed[i].gap, stored.history[i].gap);
      EXPECT_EQ(streamed[i].force, stored.history[i].force);
      if (i) {
        EXPECT_LE(streamed[i - 1].time, streamed[i].time);
      }
    }
    EXPECT_EQ(streamed.front().time, 0.0);
    EXPECT_EQ(streamed.back().time, r.end_time);
    // uniform grid k t_f/300 present
    int uniform = 0;
    for (const auto& s : streamed) {
      const double k = s.time / r.end_time * 300.0;
      if (std::abs(k - std::round(k)) < 1e-9) ++uniform;
    }
    EXPECT_GE(uniform, 301);
  }
}

TEST(History, StoredHistoryLargerThanMemoryIsRefusedBeforeWork) {
  std::ifstream in("/proc/meminfo");
  double avail_kib = -1;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("MemAvailable:", 0) == 0) std::istringstream(line.substr(13)) >> avail_kib;
  if (avail_kib < 0) GTEST_SKIP() << "no MemAvailable";
  const long points = 1'000'000'000;  // 1e9 samples of 72 bytes
  if (avail_kib * 1024 > 1e9 * sizeof(ImpactSample)) GTEST_SKIP() << "machine has more memory than the test needs";
  try {
    simulate_impact(ImpactProblem::head_on(1, 1, 1, 0.5, PiecewiseLinearLaw::linear_hysteresis(10, 8)),
                    {.history_points = points});
    FAIL() << "accepted";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "history_points");
    EXPECT_NE(std::string(e.what()).find("MemAvailable"), std::string::npos) << e.what();
  }
}
