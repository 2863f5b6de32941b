// FM-AFM forward model (include/afmkit/tapping/fm.hpp) against independent computations: the exact linear
// oscillator, the small-amplitude limit Δf/f0 = −k_ts/(2k), Giessibl's first-order formula (independent
// Gauss–Chebyshev quadrature), the hysteresis area, the far field, and an independent RK4 simulation.
#include <cmath>
#include <complex>
#include <numbers>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "afmkit/tapping/fm.hpp"
#include "afmkit/tapping/units.hpp"
#include "../counting_stop.hpp"

namespace afmkit::tapping {
namespace {

using std::numbers::pi;

impact::ForceLaw conservative(std::function<double(double)> h, std::vector<double> gaps = {}) {
  return impact::ForceLaw(impact::CustomLaw{h, h, std::move(gaps), "test"});
}

// (a) a linear force law H(d) = H0 + g (d − d0) everywhere: the FM orbit is the linear oscillator of stiffness
// ω_n² − g, exactly at its resonance: ω = √(1 − g), Γ/Γ_free = ω, no dissipation.
TEST(FmOrbit, LinearForceGradientIsExact) {
  for (double g : {-0.05, 0.03}) {
    const FmSetting s(Cantilever(1.0, 100.0), conservative([g](double d) { return 0.2 + g * (d - 3.0); }), 1.0);
    const auto o = try_solve_fm(s, 4.0, free_fm_state(s));
    ASSERT_TRUE(o) << "g = " << g;
    const double w = std::sqrt(1.0 - g);
    EXPECT_NEAR(o->state.frequency, w, 1e-9) << "g = " << g;
    EXPECT_NEAR(o->frequency_shift(), w - 1.0, 1e-9);
    EXPECT_NEAR(o->drive_ratio(), w, 1e-8);
    EXPECT_NEAR(o->metrics.amplitude, 1.0, 1e-9);
    EXPECT_NEAR(o->metrics.phase, pi / 2, 1e-9);
    EXPECT_NEAR(o->metrics.offset, 0.2 / (1.0 - g) + g * (4.0 - 3.0) / (1.0 - g), 1e-8);  // static deflection
    EXPECT_NEAR(o->tip_dissipation(), 0.0, 1e-9 * o->metrics.viscous_dissipation);
    EXPECT_NEAR(o->metrics.drive_work, pi * o->state.drive * 1.0, 1e-9);  // W = π Γ A
  }
}

// (a) small amplitude on a smooth law: Δω/ω_n → −g(d̄)/2 with g = dH/dd at the mean gap (plus O(g²), O(A²)).
TEST(FmOrbit, SmallAmplitudeLimitIsTheForceGradient) {
  const double f0 = 0.02, lambda = 1.0;
  const auto h = [=](double d) { return -f0 * std::exp(-d / lambda); };
  double previous = 1.0;
  for (double a : {0.1, 0.03, 0.01}) {
    const FmSetting s(Cantilever(1.0, 300.0), conservative(h), a);
    const auto o = try_solve_fm(s, 0.5, free_fm_state(s));
    ASSERT_TRUE(o) << "A = " << a;
    const double mean_gap = 0.5 + o->metrics.offset;
    const double g = (f0 / lambda) * std::exp(-mean_gap / lambda);
    const double limit = std::sqrt(1.0 - g) - 1.0;  // the linearised oscillator at the mean gap
    const double error = std::abs(o->frequency_shift() / limit - 1.0);
    EXPECT_LT(error, 2.0 * a * a / (lambda * lambda)) << "A = " << a;  // curvature of the gradient: O(A²/λ²)
    EXPECT_LT(error, previous) << "A = " << a;
    previous = error;
    EXPECT_NEAR(o->frequency_shift(), -g / 2, 0.05 * g) << "−k_ts/(2k) to first order";
  }
}

/// Giessibl (2001) first order: Δω/ω_n = −(1/(π A)) ∫_{−1}^{1} H(z + A(1 + u)) u / √(1 − u²) du, with H = F/k (model
/// units), z = closest gap. Gauss–Chebyshev quadrature of the first kind (independent of the engine).
double giessibl(const impact::ForceLaw& law, double z, double a) {
  const int n = 40000;
  double sum = 0.0;
  for (int j = 1; j <= n; ++j) {
    const double u = std::cos((2.0 * j - 1.0) * pi / (2.0 * n));
    sum += law.approach(z + a * (1.0 + u)) * u;
  }
  return -(1.0 / (pi * a)) * (pi / n) * sum;
}

// (b) large amplitude: the first-order formula on a Lennard-Jones law; its error shrinks with the perturbation
// parameter (Δf/f0 ∝ 1/k at fixed force): a stiffer cantilever makes it 10× smaller.
TEST(FmOrbit, LargeAmplitudeMatchesGiessibl) {
  const impact::ForceLaw physical = impact::LawRegistry::builtin().build("lennard_jones", {});
  double error_soft = 0.0;
  for (double k : {4.0, 40.0}) {
    const PhysicalCantilever pc(k, 300.0, 1000.0, 5.0, 1.0);
    const FmSetting s(pc.cantilever(), pc.normalised_law(physical), 5.0);
    FmSweepOptions options;
    const auto r = sweep_fm(s, {9.0, 7.0, 6.0, 5.6}, options);  // approach to a closest gap of ~0.6 nm
    ASSERT_EQ(r.converged(), 4) << "k = " << k;
    const FmOrbit& o = *r.points.back().orbit;
    const double predicted = giessibl(s.law, o.metrics.min_gap, 5.0);
    const double error = std::abs(o.frequency_shift() / predicted - 1.0);
    EXPECT_LT(std::abs(predicted), 0.05) << "weak perturbation";
    EXPECT_NEAR(o.tip_dissipation(), 0.0, 1e-7 * o.metrics.viscous_dissipation) << "conservative law";
    if (k == 4.0) {
      error_soft = error;
      EXPECT_LT(error, 0.1);
    } else {
      EXPECT_LT(error, error_soft / 4.0) << "first-order error should shrink ~ like 1/k";
    }
  }
}

// (c) hysteresis law (seed eq. 11): the tip–sample force takes the area between the branches over the visited
// range, ∫_{d_min}^{0} (H_a − H_b) dd = (K_a − K_b) d_min² / 2.
TEST(FmOrbit, HysteresisDissipatesTheAreaBetweenBranches) {
  const double ka = 10.0, kb = 8.0;
  const FmSetting s(Cantilever(1.0, 100.0), impact::ForceLaw(impact::PiecewiseLinearLaw(ka, kb, 0.0, 0.0)), 1.0);
  FmSweepOptions options;
  const auto r = sweep_fm(s, {1.5, 0.97, 0.93, 0.9}, options);
  ASSERT_EQ(r.converged(), 4);
  const FmOrbit& far = *r.points.front().orbit;
  EXPECT_NEAR(far.frequency_shift(), 0.0, 1e-12) << "d) no contact: the free FM orbit";
  EXPECT_NEAR(far.drive_ratio(), 1.0, 1e-10);
  for (std::size_t i = 1; i < r.points.size(); ++i) {
    const FmOrbit& o = *r.points[i].orbit;
    const double dmin = o.metrics.min_gap;
    ASSERT_LT(dmin, 0.0);
    const double area = 0.5 * (ka - kb) * dmin * dmin;
    EXPECT_NEAR(o.tip_dissipation(), area, 1e-7 * area + 1e-12) << "l = " << o.separation;
    // the energy balance of the orbit: drive work − viscous loss (Q times the residual relative to the viscous loss)
    EXPECT_NEAR(o.metrics.drive_work - o.metrics.viscous_dissipation, area, 1e-7 * area + 1e-12);
    EXPECT_GT(o.frequency_shift(), 0.0) << "repulsive contact stiffens";
    EXPECT_GT(o.drive_ratio(), 1.0);
  }
}

// (d) far from a long-range law Δf → 0 and the drive → the free drive (vdW tail ~ 1/d²: Δf ~ 1/l^{3/2}).
TEST(FmOrbit, FarFieldIsFree) {
  const impact::ForceLaw physical = impact::LawRegistry::builtin().build("dmt", {});
  const PhysicalCantilever pc(40.0, 300.0, 1000.0, 2.0, 1.0);
  const FmSetting s(pc.cantilever(), pc.normalised_law(physical), 2.0);
  const auto r = sweep_fm(s, {400.0, 100.0, 20.0, 5.0});
  ASSERT_EQ(r.converged(), 4);
  double previous = 0.0;
  for (const FmPoint& p : r.points) {
    const double shift = std::abs(p.orbit->frequency_shift());
    EXPECT_GT(shift, previous) << "l = " << p.separation;
    previous = shift;
  }
  EXPECT_LT(std::abs(r.points.front().orbit->frequency_shift()), 1e-7);
  EXPECT_NEAR(r.points.front().orbit->drive_ratio(), 1.0, 1e-6);
}

// (e) the orbit checked by an independent simulation: classical RK4 of ẍ = Γcos ωt − ẋ/Q − x + H(x + l) with
// the found (x(0), ẋ(0), ω, Γ) returns to its start after 2π/ω, and its first harmonic is A sin ωt.
TEST(FmOrbit, IndependentSimulationOfTheOrbit) {
  const double q = 50.0, l = 1.2, a = 1.0;
  const auto h = [](double d) { return 0.3 * std::exp(-2.0 * d) - 0.1 * std::exp(-d); };  // repulsive + attractive
  const FmSetting s(Cantilever(1.0, q), conservative(h), a);
  const auto o = try_solve_fm(s, l, free_fm_state(s));
  ASSERT_TRUE(o);
  const double w = o->state.frequency, gamma = o->state.drive, period = 2 * pi / w;
  auto f = [&](double t, double x, double v) { return gamma * std::cos(w * t) - v / q - x + h(x + l); };
  const int n = 20000;
  const double dt = period / n;
  double x = o->state.initial.position, v = o->state.initial.velocity, t = 0.0, c = 0.0, si = 0.0;
  for (int i = 0; i < n; ++i) {
    c += x * std::cos(w * t) * dt;  // rectangle rule on a periodic integrand: spectrally accurate
    si += x * std::sin(w * t) * dt;
    const double k1x = v, k1v = f(t, x, v);
    const double k2x = v + 0.5 * dt * k1v, k2v = f(t + 0.5 * dt, x + 0.5 * dt * k1x, v + 0.5 * dt * k1v);
    const double k3x = v + 0.5 * dt * k2v, k3v = f(t + 0.5 * dt, x + 0.5 * dt * k2x, v + 0.5 * dt * k2v);
    const double k4x = v + dt * k3v, k4v = f(t + dt, x + dt * k3x, v + dt * k3v);
    x += dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    t += dt;
  }
  EXPECT_NEAR(x, o->state.initial.position, 1e-8);
  EXPECT_NEAR(v, o->state.initial.velocity, 1e-8);
  EXPECT_NEAR(2.0 / period * c, 0.0, 1e-8) << "drive 90° ahead of the deflection";
  EXPECT_NEAR(2.0 / period * si, a, 1e-8) << "first-harmonic amplitude A";
  EXPECT_GT(std::abs(o->frequency_shift()), 1e-3) << "a real interaction";
}

// (e) the self-excited system, simulated independently (classical RK4) with an instrument's loops closed cycle by
// cycle: the drive Γ_k cos θ(t) runs at θ̇ = ω_k; after each cycle the first harmonic of x over that cycle gives the
// phase lag φ and amplitude a; the PLL moves ω_k against φ − π/2 and the amplitude controller scales Γ_k by
// (A/a)^γ. Started from the free values at the separation, the loops settle on Newton's FM orbit.
TEST(FmOrbit, SelfExcitedSimulationSettlesOnTheOrbit) {
  const double q = 50.0, l = 1.2, a = 1.0;
  const auto h = [](double d) { return 0.3 * std::exp(-2.0 * d) - 0.1 * std::exp(-d); };
  const FmSetting s(Cantilever(1.0, q), conservative(h), a);
  const auto o = try_solve_fm(s, l, free_fm_state(s));
  ASSERT_TRUE(o);
  double w = 1.0, gamma = a / q, x = 0.0, v = a, theta = 0.0;
  const int steps = 400;
  auto f = [&](double th, double xx, double vv) { return gamma * std::cos(th) - vv / q - xx + h(xx + l); };
  for (int cycle = 0; cycle < 3000; ++cycle) {
    const double dt = 2 * pi / w / steps;
    std::complex<double> c1 = 0.0;
    for (int i = 0; i < steps; ++i) {
      c1 += x * std::exp(std::complex<double>(0.0, -theta)) * dt;
      const double dth = w * dt;
      const double k1x = v, k1v = f(theta, x, v);
      const double k2x = v + 0.5 * dt * k1v, k2v = f(theta + 0.5 * dth, x + 0.5 * dt * k1x, v + 0.5 * dt * k1v);
      const double k3x = v + 0.5 * dt * k2v, k3v = f(theta + 0.5 * dth, x + 0.5 * dt * k2x, v + 0.5 * dt * k2v);
      const double k4x = v + dt * k3v, k4v = f(theta + dth, x + dt * k3x, v + dt * k3v);
      x += dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
      v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      theta += dth;
    }
    theta = std::remainder(theta, 2 * pi);
    c1 *= w / pi;                                   // (2/T) ∫ x e^{−iθ} dt
    const double lag = -std::arg(c1);               // x ≈ a cos(θ − φ)
    w -= 0.3 * (lag - pi / 2) / (2 * q);            // dφ/dω ≈ 2Q/ω_n near resonance
    gamma *= std::pow(a / std::abs(c1), 0.3);
  }
  EXPECT_NEAR(w, o->state.frequency, 1e-7 * std::abs(o->frequency_shift()) + 1e-9);
  EXPECT_NEAR(gamma, o->state.drive, 1e-6 * o->state.drive);
  EXPECT_GT(std::abs(o->frequency_shift()), 1e-3);
}

// (c) a smooth hysteresis law (JKR-like adhesion: DMT approach, retract with a pull-off neck): the dissipation per
// cycle is the area between the branches over the gaps visited, by an independent Simpson quadrature. The orbit
// leaves the range where the branches differ, so this holds for velocity-sign and contact-aware branch switching.
TEST(FmOrbit, AdhesionHysteresisDissipatesTheAreaBetweenBranches) {
  const impact::ForceLaw physical = impact::LawRegistry::builtin().build("jkr", {});
  const PhysicalCantilever pc(40.0, 300.0, 1000.0, 5.0, 1.0);
  const FmSetting s(pc.cantilever(), pc.normalised_law(physical), 5.0);
  const auto r = sweep_fm(s, {10.0, 7.0, 5.5, 5.0, 4.5});
  ASSERT_EQ(r.converged(), 5);
  for (const FmPoint& p : r.points) {
    const FmOrbit& o = *p.orbit;
    const double lo = o.metrics.min_gap, hi = o.separation + 2.0 * o.metrics.offset - lo;  // ≈ upper turning point
    const int n = 200000;  // Simpson over [lo, hi]
    const double step = (hi - lo) / n;
    double area = 0.0;
    for (int i = 0; i <= n; ++i) {
      const double d = lo + i * step;
      const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      area += w * (s.law.approach(d) - s.law.departure(d));
    }
    area *= step / 3.0;
    const double viscous = o.metrics.viscous_dissipation;
    EXPECT_NEAR(o.tip_dissipation(), area, 2e-4 * std::abs(area) + 1e-9 * viscous) << "l = " << p.separation;
    EXPECT_NEAR(o.metrics.drive_work - viscous, area, 2e-4 * std::abs(area) + (1e-9 + 1e3 * o.residual) * viscous)
        << "energy balance: Q times the residual";
  }
  EXPECT_GT(r.points.back().orbit->tip_dissipation(), 1e-3 * r.points.back().orbit->metrics.viscous_dissipation);
}

// The turning-point axis: solving for the separation at a given gap of closest approach inverts the solve at a
// given separation (same orbit both ways).
TEST(FmOrbit, MinGapAxisInvertsTheSeparationAxis) {
  const impact::ForceLaw physical = impact::LawRegistry::builtin().build("dmt", {});
  const PhysicalCantilever pc(40.0, 300.0, 1000.0, 5.0, 1.0);
  const FmSetting s(pc.cantilever(), pc.normalised_law(physical), 5.0);
  const auto at_l = sweep_fm(s, {9.0, 7.0, 5.2});
  ASSERT_EQ(at_l.converged(), 3);
  const FmOrbit& o = *at_l.points.back().orbit;
  FmSweepOptions options;
  options.axis = FmAxis::min_gap;
  const auto at_z = sweep_fm(s, {4.0, 2.0, o.metrics.min_gap}, options);
  ASSERT_EQ(at_z.converged(), 3);
  const FmOrbit& p = *at_z.points.back().orbit;
  EXPECT_NEAR(p.metrics.min_gap, o.metrics.min_gap, 1e-8);
  EXPECT_NEAR(p.separation, 5.2, 1e-7);
  EXPECT_NEAR(p.frequency_shift(), o.frequency_shift(), 1e-6 * std::abs(o.frequency_shift()));
  EXPECT_NEAR(p.drive_ratio(), o.drive_ratio(), 1e-8);
}

// A steep stretch of the Lennard-Jones wall (Δf/f0 from −6e-4 to +0.2 within 0.25 nm of separation): Newton from
// the previous separation fails, the branch is followed in the turning-point gap instead, and lands on the orbit a
// fine approach reaches (not a jump: no fold in l there).
TEST(FmOrbit, SteepStretchIsFollowedInTheTurningPointGap) {
  const impact::ForceLaw physical = impact::LawRegistry::builtin().build("lennard_jones", {});
  const PhysicalCantilever pc(40.0, 300.0, 1000.0, 5.0, 1.0);
  const FmSetting s(pc.cantilever(), pc.normalised_law(physical), 5.0);
  FmSweepOptions no_bisection;
  no_bisection.max_bisections = 0;
  const auto coarse = sweep_fm(s, {5.25, 5.0}, no_bisection);
  ASSERT_EQ(coarse.converged(), 2);
  EXPECT_FALSE(coarse.points.back().jumped);
  std::vector<double> fine;
  for (double l = 5.25; l > 4.999; l -= 0.01) fine.push_back(l);
  const auto reference = sweep_fm(s, fine);
  ASSERT_EQ(reference.converged(), static_cast<long>(fine.size()));
  const FmOrbit& a = *coarse.points.back().orbit;
  const FmOrbit& b = *reference.points.back().orbit;
  EXPECT_NEAR(b.separation, 5.0, 1e-12);
  EXPECT_NEAR(a.frequency_shift(), b.frequency_shift(), 1e-6 * std::abs(b.frequency_shift()));
  EXPECT_GT(a.frequency_shift(), 0.1) << "on the repulsive wall";
  FmSweepOptions stuck = no_bisection;
  stuck.jumps = false;
  stuck.fm.shooting.max_iterations = 10;
  EXPECT_EQ(sweep_fm(s, {5.25, 5.0}, stuck).points.back().status, FmStatus::no_orbit)
      << "without the turning-point walk this step is out of Newton's reach (the test exercises the walk)";
}

// The sweep stops on request (once per target and per sub-step), and reports progress once per target.
TEST(FmOrbit, SweepIsCancellableAndReportsProgress) {
  const FmSetting s(Cantilever(1.0, 100.0), impact::ForceLaw(impact::PiecewiseLinearLaw(10, 8, 0, 0)), 1.0);
  long progress = 0;
  FmSweepOptions options;
  options.progress = [&](long n) { progress += n; };
  EXPECT_EQ(sweep_fm(s, {2.0, 1.5, 1.0, 0.9}, options).converged(), 4);
  EXPECT_EQ(progress, 4);
  afmkit_test::CountingStop stop(3);
  options.cancellation = stop.cancellation();
  EXPECT_THROW(sweep_fm(s, {2.0, 1.5, 1.0, 0.9, 0.8}, options), Cancelled);
  EXPECT_EQ(stop.calls.load(), 3);
}

// The Jacobian kept along the approach (Broyden-updated) gives the orbits Newton finds with a fresh difference
// Jacobian at every separation, for about a third of the one-period simulations.
TEST(FmOrbit, KeptJacobianGivesTheSameOrbitsForFewerSimulations) {
  const impact::ForceLaw physical = impact::LawRegistry::builtin().build("dmt", {});
  const PhysicalCantilever pc(40.0, 300.0, 1000.0, 5.0, 1.0);
  const FmSetting s(pc.cantilever(), pc.normalised_law(physical), 5.0);
  std::vector<double> approach;
  for (double l = 8.0; l > 3.9; l -= 0.1) approach.push_back(l);
  const auto kept = sweep_fm(s, approach);
  ASSERT_EQ(kept.converged(), static_cast<long>(approach.size()));
  long fresh_evaluations = 0;
  FmState previous = free_fm_state(s);
  for (std::size_t i = 0; i < approach.size(); ++i) {
    const auto o = try_solve_fm(s, approach[i], previous);  // no Jacobian kept: differences at every solve
    ASSERT_TRUE(o) << "l = " << approach[i];
    fresh_evaluations += o->evaluations;
    previous = o->state;
    const FmOrbit& k = *kept.points[i].orbit;
    // both converged to residuals ≤ 1e-9 (DOP853's floor): Δω to a few relative_tolerance (1e-10, the integrator's
    // phase accuracy); the drive, set by the energy balance, to about Q × the periodicity residual
    EXPECT_NEAR(k.frequency_shift(), o->frequency_shift(), 5e-10);
    EXPECT_NEAR(k.drive_ratio(), o->drive_ratio(), 1000.0 * 1e-9);
  }
  EXPECT_LT(3 * kept.evaluations, 2 * fresh_evaluations) << kept.evaluations << " vs " << fresh_evaluations;
  EXPECT_LT(kept.evaluations, 4 * static_cast<long>(approach.size()));
}

// A fold of the FM branch in l: a short-range attraction (λ = 0.1 against A = 3) pulls the mean deflection down
// faster than the turning point moves (dx̄/dz > 1), so l(z) is S-shaped — its minimum l ≈ 3.041 near z = 0.05, its
// maximum l ≈ 3.073 near z = 0 (mapped on the turning-point axis). Approaching below the fold, the orbit jumps to
// the branch beyond it, as the loops of an instrument would: the row is marked jumped, and it is the orbit the
// turning-point axis finds at its gap.
TEST(FmOrbit, ApproachJumpsPastAFoldOfTheBranch) {
  const auto h = [](double d) { return -5.0 * std::exp(-d / 0.1) + 20.0 * std::exp(-d / 0.02); };
  const FmSetting s(Cantilever(1.0, 300.0), conservative(h), 3.0);
  FmSweepOptions on_gap;
  on_gap.axis = FmAxis::min_gap;
  std::vector<double> gaps;
  for (double z = 0.2; z > -0.035; z -= 0.01) gaps.push_back(z);
  const auto curve = sweep_fm(s, gaps, on_gap);
  ASSERT_EQ(curve.converged(), static_cast<long>(gaps.size()));
  double l_min = 1e9, l_max_after = -1e9;
  bool turned = false;
  for (std::size_t i = 1; i < curve.points.size(); ++i) {
    const double l = curve.points[i].orbit->separation, before = curve.points[i - 1].orbit->separation;
    if (l > before) turned = true;
    if (!turned) l_min = std::min(l_min, l);
    else l_max_after = std::max(l_max_after, l);
  }
  ASSERT_TRUE(turned) << "l(z) has a fold";
  ASSERT_LT(l_min, 3.045);
  ASSERT_GT(l_max_after, 3.06);

  const auto approach = sweep_fm(s, {3.2, 3.1, 3.06, 3.05, 3.045, 3.03});
  ASSERT_EQ(approach.converged(), 6);
  for (std::size_t i = 0; i + 1 < approach.points.size(); ++i) EXPECT_FALSE(approach.points[i].jumped);
  const FmPoint& jump = approach.points.back();
  EXPECT_TRUE(jump.jumped);
  EXPECT_NEAR(jump.orbit->separation, 3.03, 1e-12);
  EXPECT_LT(jump.orbit->metrics.min_gap, 0.0) << "beyond the fold's gaps";
  EXPECT_GT(approach.points[4].orbit->metrics.min_gap, 0.04) << "before it: still on the first branch";
  // the turning-point axis at the jumped orbit's gap finds the same orbit
  const auto check = try_solve_fm_at_gap(s, jump.orbit->metrics.min_gap, 3.03, jump.orbit->state);
  ASSERT_TRUE(check);
  EXPECT_NEAR(check->separation, 3.03, 1e-8);
  EXPECT_NEAR(check->frequency_shift(), jump.orbit->frequency_shift(), 1e-8);
  FmSweepOptions no_jumps;
  no_jumps.jumps = false;
  no_jumps.max_bisections = 1;
  no_jumps.fm.shooting.max_iterations = 10;
  EXPECT_EQ(sweep_fm(s, {3.2, 3.1, 3.06, 3.05, 3.045, 3.03}, no_jumps).points.back().status, FmStatus::no_orbit)
      << "the branch followed in l ends at the fold";
}

TEST(FmOrbit, RejectsBadSettings) {
  EXPECT_THROW(FmSetting(Cantilever(1.0, 100.0), impact::PiecewiseLinearLaw(10, 8, 0, 0), 0.0), InvalidParameter);
  FmOptions o;
  o.difference_step = -1.0;
  EXPECT_THROW(o.validate(), InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
