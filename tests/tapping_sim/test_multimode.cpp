// A cantilever with more than one eigenmode (modes.hpp, docs/theory-tapping.md#more-than-one-eigenmode): the
// single-mode results reproduced when the higher modes are removed or made rigid, the free response against the
// linear closed form (Σ_d F_{i,d} L_i(iω_d) e^{iω_d t}, independent of the integrator), the energy balance of every
// mode, the Euler–Bernoulli constants against their defining equations and the literature, and bad input.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/modal_response.hpp"
#include "afmkit/tapping/observer.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/simulation.hpp"
#include "afmkit/tapping/units.hpp"
#include "fixtures.hpp"

namespace afmkit::tapping {
namespace {

/// A DMT + vdW cantilever in physical units made normalised (k = 40 N/m, f0 = 300 kHz, A = 20 nm; a dissipative
/// law: E*_b < E*_a, larger departure Hamaker constant).
TappingModel multimode_dmt_single(double q = 30.0, double separation = 14.0) {
  const PhysicalCantilever pc(40.0, 300.0, q, 20.0, 1.0);
  return {pc.cantilever(), pc.drive(), pc.normalised_law(impact::ForceLaw(impact::DmtLaw(1.0, 0.8, 10.0, 6.4e-20,
                                                                                          1e-19, 0.165))),
          separation};
}

SimulationOptions multimode_tight() {
  SimulationOptions o;
  o.integrator = Integrator::adaptive;
  o.relative_tolerance = 1e-12;
  o.absolute_tolerance = 1e-13;
  return o;
}

TEST(MultiMode, OneModeIsTheSingleModeModelBitForBit) {
  // the higher modes removed: the same model, the same system, the same bits (closed-form law and DMT)
  for (const TappingModel& single : {testing::attractive_model(9.5), multimode_dmt_single()}) {
    const MultiModeModel multi = MultiModeModel::from_single(single);
    ASSERT_TRUE(multi.single_mode());
    const TipState start = free_response_state(single);
    EventRecorder a, b;
    const auto r1 = simulate(single, 0.0, start, 12 * single.period(), {}, &a);
    const auto r2 = simulate(multi, 0.0, start, 12 * single.period(), {}, &b);
    ASSERT_GT(r1.stats.impacts, 0);
    EXPECT_EQ(r1.state.position, r2.state.position);
    EXPECT_EQ(r1.state.velocity, r2.state.velocity);
    ASSERT_EQ(a.events().size(), b.events().size());
    for (std::size_t i = 0; i < a.events().size(); ++i) EXPECT_EQ(a.events()[i].time, b.events()[i].time);
  }
}

TEST(MultiMode, RigidHigherModesReproduceTheSingleModeTrajectory) {
  // k_2/k_1 → ∞ (1e12): the second mode takes no part, but the run goes through the modal equations (state
  // x, ẋ, q_2, q̇_2; the scan step of the faster mode): the single-mode trajectory to the integration tolerance
  for (const TappingModel& single : {testing::attractive_model(9.5), multimode_dmt_single()}) {
    const Cantilever& c = single.cantilever;
    std::vector<Eigenmode> modes = {Eigenmode(c.natural_frequency, c.quality_factor, 1.0, 1.0),
                                    Eigenmode::from_ratios(c, 6.2669, 1e12, 200.0, 1.0)};
    const MultiModeModel multi(modes, {single.drive}, Excitation::direct, Medium{}, single.law, single.separation);
    ASSERT_FALSE(multi.single_mode());
    const TipState start = free_response_state(single);
    const double t_end = 15 * single.period();
    const auto r1 = simulate(single, 0.0, start, t_end, multimode_tight());
    const auto r2 = simulate(multi, 0.0, start, t_end, multimode_tight());
    ASSERT_GT(r1.stats.impacts, 5);
    EXPECT_EQ(r1.stats.impacts, r2.stats.impacts);
    const double scale = single.free_amplitude();
    EXPECT_NEAR(r2.state.position, r1.state.position, 1e-8 * scale);
    EXPECT_NEAR(r2.state.velocity, r1.state.velocity, 1e-8 * scale * c.natural_frequency);
    EXPECT_LT(std::abs(r2.state.modal[0]), 1e-9 * scale);  // the rigid mode stays at rest
  }
}

/// Two Euler–Bernoulli modes driven at ω_1 and 6ω_1 (commensurate: the lock-in windows are whole periods of both).
MultiModeModel multimode_free(Excitation excitation, Medium medium) {
  const Cantilever c(1.0, 50.0);
  const auto modes = euler_bernoulli_modes(c, 2);
  const double wa = 1.0, wb = 6.0;
  return {modes,
          {Drive(drive_for_mode_amplitude(modes, excitation, medium, 0, wa, 1.0), wa),
           Drive(drive_for_mode_amplitude(modes, excitation, medium, 1, wb, 0.1), wb)},
          excitation,
          medium,
          impact::ForceLaw(impact::PiecewiseLinearLaw(10.0, 8.0)),
          1e3};  // far from the sample: no tip force
}

TEST(MultiMode, FreeTwoModeResponseEqualsTheLinearClosedForm) {
  Medium liquid;
  liquid.added_mass_ratio = 2.0;
  liquid.fluid_quality_factor = 3.0;
  for (const auto& [excitation, medium] : {std::pair{Excitation::direct, Medium{}},
                                           std::pair{Excitation::base, Medium{}}, std::pair{Excitation::base, liquid}}) {
    const MultiModeModel m = multimode_free(excitation, medium);
    const double t_end = 8 * m.drives[0].period();
    ModalLockIn lock(m, t_end, 4);
    const auto r = simulate(m, 0.0, free_steady_state(m, 0.0), t_end, multimode_tight(), &lock);
    // closed form at t_end, written out here: q_i = Re Σ_d F_{i,d} L_i(iω_d) e^{iω_d t}, x = y_b + Σ q_i
    double x = 0.0, q2 = 0.0;
    for (int d = 0; d < 2; ++d) {
      const double w = m.drives[d].frequency;
      const std::complex<double> e = std::polar(1.0, w * t_end);
      for (int i = 0; i < 2; ++i) {
        const double wi = m.modes[i].natural_frequency / std::sqrt(1.0 + medium.added_mass_ratio);
        const double qi = 1.0 / (1.0 / (m.modes[i].quality_factor * std::sqrt(1.0 + medium.added_mass_ratio)) +
                                 (m.frequency(0) / wi) / medium.fluid_quality_factor);
        const std::complex<double> L = 1.0 / std::complex<double>(wi * wi - w * w, wi / qi * w);
        const double gain = excitation == Excitation::direct ? m.modes[i].mass_ratio
                                                             : m.modes[i].participation * w * w;
        const std::complex<double> c = gain * m.drives[d].amplitude / (1.0 + medium.added_mass_ratio) * L;
        x += (c * e).real();
        if (i == 1) q2 += (c * e).real();
        if (d == i) {  // the lock-in of mode i at its own drive
          const ModalHarmonic h = lock.mode(i, d);  // A e^{−iφ} against c (no wrap of the phase near ±π)
          EXPECT_NEAR(std::abs(std::polar(h.amplitude, -h.phase) - c), 0.0, 1e-8 * std::abs(c));
        }
      }
      if (excitation == Excitation::base) x += m.drives[d].amplitude * e.real();
    }
    EXPECT_NEAR(r.state.position, x, 1e-9);
    EXPECT_NEAR(r.state.modal[0], q2, 1e-9);
    EXPECT_EQ(r.stats.impacts, 0);
    // free amplitudes as asked of drive_for_mode_amplitude
    EXPECT_NEAR(lock.mode(0, 0).amplitude, 1.0, 1e-8);
    EXPECT_NEAR(lock.mode(1, 1).amplitude, 0.1, 1e-9);
  }
}

TEST(MultiMode, EnergyBalanceOfEveryModeInTapping) {
  // drive work − damping loss + tip–sample work = change of the stored energy, mode by mode (not a periodic orbit:
  // the change is measured from the states, the works by quadrature of the trajectory)
  const TappingModel single = multimode_dmt_single(30.0, 14.0);
  const Cantilever& c = single.cantilever;
  auto modes = euler_bernoulli_modes(c, 3);
  const double wb = modes[1].natural_frequency;
  const MultiModeModel m(modes,
                         {single.drive, Drive(drive_for_mode_amplitude(modes, Excitation::direct, {}, 1, wb, 1.0), wb)},
                         Excitation::direct, Medium{}, single.law, single.separation);
  ModalResponseOptions o;
  o.settle_periods = 10;
  o.lockin_periods = 4;
  o.simulation = multimode_tight();
  const ModalResponse r = modal_response(m, 0.0, free_steady_state(m, 0.0), o);
  ASSERT_GT(r.stats.impacts, 0);
  double tip_total = 0.0;
  for (int i = 0; i < 3; ++i) {
    const ModeEnergy& e = r.energy[i];
    const double scale = std::max({std::abs(e.drive_work), e.damping_loss, std::abs(e.tip_work)});
    ASSERT_GT(scale, 0.0);
    EXPECT_NEAR(e.residual(), 0.0, 1e-7 * scale) << "mode " << i + 1;
    EXPECT_NE(e.tip_work, 0.0) << "mode " << i + 1;  // the tip force acts on every mode
    tip_total += e.tip_work;
  }
  EXPECT_LT(tip_total, 0.0);  // a dissipative law takes energy from the cantilever
}

TEST(MultiMode, StickingHoldsTheTipWhileTheModesMoveOnAndBalancesTheirEnergy) {
  // the repulsive–attractive law (26) with adhesion holds the tip at rest in contact (seed-1 eq. 4, both branches
  // pushing back onto ẋ = 0); with two modes the tip stays put while the modes exchange energy through the
  // holding force, which does no work on the tip but works on each mode
  const TappingModel single = testing::make_model(10, 8, 0.5, 1.0, 9.0);
  const auto modes = euler_bernoulli_modes(single.cantilever, 2);
  const MultiModeModel m(modes, {single.drive}, Excitation::base, Medium{}, single.law, single.separation);
  ModalResponseOptions o;
  o.settle_periods = 10;
  o.lockin_periods = 10;
  o.simulation = multimode_tight();
  const ModalResponse r = modal_response(m, 0.0, free_steady_state(m, 0.0), o);
  ASSERT_GT(r.stats.sticking_count, 0);
  EXPECT_GT(r.stats.sticking_duration, 0.0);
  for (int i = 0; i < 2; ++i) {
    const ModeEnergy& e = r.energy[i];
    const double scale = std::max({std::abs(e.drive_work), e.damping_loss, std::abs(e.tip_work)});
    EXPECT_NEAR(e.residual(), 0.0, 1e-7 * scale) << "mode " << i + 1;
  }
}

TEST(MultiMode, SecondModePhaseMovesWithTheSeparation) {
  // bimodal AM-AFM: far away the second mode's phase is its free phase at resonance (π/2); in tapping it shifts
  const TappingModel single = multimode_dmt_single(20.0, 30.0);
  auto modes = euler_bernoulli_modes(single.cantilever, 2);
  const double wb = modes[1].natural_frequency;
  const MultiModeModel m(modes,
                         {single.drive, Drive(drive_for_mode_amplitude(modes, Excitation::direct, {}, 1, wb, 0.5), wb)},
                         Excitation::direct, Medium{}, single.law, 30.0);
  ModalResponseOptions o;
  o.settle_periods = 40;
  o.lockin_periods = 10;
  const auto sweep = modal_sweep(m, {30.0, 15.0}, o);
  ASSERT_EQ(sweep.size(), 2u);
  EXPECT_NEAR(sweep[0].mode[1][1].phase, std::numbers::pi / 2, 1e-3);
  EXPECT_NEAR(sweep[0].mode[1][1].amplitude, 0.5, 1e-3);
  EXPECT_GT(sweep[1].stats.impacts, 0);
  EXPECT_GT(std::abs(sweep[1].mode[1][1].phase - std::numbers::pi / 2), 0.01);
}

TEST(MultiMode, ShootingFindsTheFreeOrbitAndTheSettledTappingOrbit) {
  ModalShootingOptions o;
  o.simulation = multimode_tight();
  // free, drives at ω_1 and 6ω_1 (common period 2π): the closed form, from a perturbed guess
  const MultiModeModel free = multimode_free(Excitation::direct, Medium{});
  EXPECT_NEAR(common_period(free), 2 * std::numbers::pi, 1e-12);
  TipState guess = free_steady_state(free, 0.0);
  guess.position += 0.05;
  guess.modal[0] += 0.01;
  const ModalOrbit orbit = modal_periodic_orbit(free, 0.0, guess, o);
  ASSERT_TRUE(orbit.converged);
  const TipState exact = free_steady_state(free, 0.0);
  EXPECT_NEAR(orbit.state.position, exact.position, 1e-8);
  EXPECT_NEAR(orbit.state.velocity, exact.velocity, 1e-8);
  EXPECT_NEAR(orbit.state.modal[0], exact.modal[0], 1e-8);
  EXPECT_NEAR(orbit.state.modal[1], exact.modal[1], 1e-8);
  // tapping at low Q: a long transient settles on the orbit Newton finds from a 1 % perturbation of it
  const TappingModel single = multimode_dmt_single(5.0, 14.0);
  const auto modes = euler_bernoulli_modes(single.cantilever, 2);
  const MultiModeModel m(modes,
                         {single.drive, Drive(drive_for_mode_amplitude(modes, Excitation::direct, {}, 1, 6.0, 0.5), 6.0)},
                         Excitation::direct, Medium{}, single.law, single.separation);
  const double t0 = 60 * common_period(m);
  const auto settled = simulate(m, 0.0, free_steady_state(m, 0.0), t0, o.simulation);
  ASSERT_GT(settled.stats.impacts, 0);
  TipState start = settled.state;
  start.position *= 1.01;
  start.modal[0] *= 1.01;
  const ModalOrbit tapping = modal_periodic_orbit(m, t0, start, o);
  ASSERT_TRUE(tapping.converged);
  EXPECT_NEAR(tapping.state.position, settled.state.position, 1e-7 * single.free_amplitude());
  EXPECT_NEAR(tapping.state.modal[0], settled.state.modal[0], 1e-7 * single.free_amplitude());
  // over one period of the orbit every mode's stored energy returns: drive work = damping loss − tip–sample work
  ModalLockIn period(m, t0 + tapping.period, 1);
  simulate(m, t0, tapping.state, t0 + tapping.period, o.simulation, &period);
  for (int i = 0; i < 2; ++i) {
    const ModeEnergy& e = period.energy(i);
    const double scale = std::max({std::abs(e.drive_work), e.damping_loss, std::abs(e.tip_work)});
    EXPECT_NEAR(e.energy_change, 0.0, 1e-6 * scale) << "mode " << i + 1;
    EXPECT_NEAR(e.drive_work, e.damping_loss - e.tip_work, 1e-6 * scale) << "mode " << i + 1;
  }
  // incommensurate drives have no period
  const MultiModeModel odd(modes, {single.drive, Drive(1.0, std::sqrt(37.0))}, Excitation::direct, Medium{},
                           single.law, single.separation);
  EXPECT_THROW(common_period(odd), InvalidParameter);
}

TEST(MultiMode, EulerBernoulliConstants) {
  for (int i = 1; i <= 3; ++i) {
    const double l = euler_bernoulli_eigenvalue(i);
    EXPECT_NEAR(1.0 + std::cos(l) * std::cosh(l), 0.0, 1e-9 * std::cosh(l));  // the frequency equation
  }
  // tip-normalised participation factors of the clamped-free beam (Melcher, Hu, Raman 2007, Table I: 1.566, 0.867,
  // 0.509 in magnitude)
  EXPECT_NEAR(euler_bernoulli_participation(1), 1.566, 1e-3);
  EXPECT_NEAR(euler_bernoulli_participation(2), -0.867, 1e-3);
  EXPECT_NEAR(euler_bernoulli_participation(3), 0.509, 1e-3);
  const auto modes = euler_bernoulli_modes(Cantilever(2.0, 100.0), 3);
  EXPECT_NEAR(modes[1].natural_frequency / 2.0, 6.2669, 1e-4);
  EXPECT_NEAR(modes[2].natural_frequency / 2.0, 17.5475, 1e-4);
  EXPECT_DOUBLE_EQ(modes[1].mass_ratio, 1.0);  // equal modal masses of the uniform beam: k_i/k_1 = (ω_i/ω_1)²
  EXPECT_NEAR(modes[1].quality_factor, 100.0 * 6.2669, 1e-2);
}

TEST(MultiMode, RejectsBadInput) {
  const TappingModel single = testing::repulsive_model();
  const auto law = single.law;
  const auto four = std::vector<Eigenmode>(4, Eigenmode(1.0, 10.0, 1.0, 1.0));
  EXPECT_THROW(MultiModeModel(four, {single.drive}, Excitation::direct, {}, law, 10.0), InvalidParameter);
  const auto two = euler_bernoulli_modes(single.cantilever, 2);
  EXPECT_THROW(MultiModeModel(two, {single.drive, single.drive, single.drive}, Excitation::direct, {}, law, 10.0),
               InvalidParameter);
  EXPECT_THROW(MultiModeModel(two, {}, Excitation::direct, {}, law, 10.0), InvalidParameter);
  Medium bad;
  bad.added_mass_ratio = -1.0;
  EXPECT_THROW(MultiModeModel(two, {single.drive}, Excitation::direct, bad, law, 10.0), InvalidParameter);
  EXPECT_THROW(Eigenmode(1.0, 0.0, 1.0, 1.0), InvalidParameter);
  EXPECT_THROW(euler_bernoulli_modes(single.cantilever, 4), InvalidParameter);
  EXPECT_THROW(euler_bernoulli_modes(single.cantilever, 3, {10.0}), InvalidParameter);
  const MultiModeModel m(two, {single.drive}, Excitation::direct, {}, law, 10.0);
  SimulationOptions sens;
  sens.sensitivity = true;
  EXPECT_THROW(simulate(m, 0.0, {}, 1.0, sens), InvalidParameter);
  SimulationOptions closed;
  closed.integrator = Integrator::closed_form;
  EXPECT_THROW(simulate(m, 0.0, {}, 1.0, closed), InvalidParameter);
  TipState nan_state;
  nan_state.modal[0] = std::nan("");
  EXPECT_THROW(simulate(m, 0.0, nan_state, 1.0), InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
