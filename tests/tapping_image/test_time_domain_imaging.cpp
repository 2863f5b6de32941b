// AM-AFM imaging with Z feedback, exact time-domain engine (docs/theory-tapping.md#time-domain-imaging), against
// independent expectations: a flat sample holds the set-point and images zero height; a step is imaged with its
// height as the quasi-static engine images it, within the bound of the loop's settling (derived below); bad options
// name their parameter. (The regime switch inside the bistable window: test_quasi_static_imaging.cpp, on its sweep.)
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/force_law.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/tapping/image/cycle_integrals.hpp"
#include "afmkit/tapping/image/quasi_static.hpp"
#include "afmkit/tapping/image/time_domain.hpp"
#include "afmkit/tapping/units.hpp"
#include "image_fixtures.hpp"

namespace afmkit::tapping::image {
namespace {

// k = 40 N/m, f0 = 300 kHz, Q = 100 (τ_c = 2Q/ω0 = 106 µs, 32 cycles), A0 = 10 nm at resonance, DMT + vdW (the law's
// defaults); one repulsive branch at A_sp = 0.8 A0. Lengths of the map in nm.
constexpr double kTdimgF0 = 300e3, kTdimgQ = 100.0, kTdimgA0 = 10.0, kTdimgSetpoint = 0.8;
const PhysicalCantilever& tdimg_cantilever() {
  static const PhysicalCantilever pc(40.0, 300.0, kTdimgQ, kTdimgA0, 1.0);
  return pc;
}
TappingModel tdimg_model() { return test::dmt_defaults_model(tdimg_cantilever()); }
const OrbitMap& tdimg_map() {
  static const OrbitMap m = [] {
    OrbitMapOptions o;
    o.separation_min = 0.0;
    o.separation_max = 12.0;
    o.points = 32;
    o.sweep.transient.max_periods = 1000;
    return OrbitMap::build(tdimg_model(), o);
  }();
  return m;
}

/// A raster of `pixels` × `lines` over 1 µm with `cycles` drive cycles per pixel; the feedback at a fifth of the
/// drive frequency (5 cycles per update), K_i = 8000 1/s.
RasterSpec tdimg_raster(long pixels, long lines, double cycles) {
  RasterSpec r;
  r.pixels = pixels;
  r.lines = lines;
  r.width = r.height = 1e-6;
  r.tip_speed = r.width / static_cast<double>(pixels) / (cycles / kTdimgF0);
  return r;
}
FeedbackSpec tdimg_feedback() {
  FeedbackSpec f;
  f.setpoint = kTdimgSetpoint;
  f.integral_gain = 8000.0;
  f.update_rate = kTdimgF0 / 5.0;
  f.lockin_bandwidth = 5e3;
  return f;
}
scan::Surface tdimg_surface(scan::HeightMap map) { return scan::Surface(std::move(map), scan::Tilt(0.0, 0.0)); }
scan::Grid tdimg_grid(double size, long n) { return {n, n, size, size, -0.5 * size, -0.5 * size}; }

TimeDomainEngine tdimg_engine(long lockin_cycles = 1) {
  TimeDomainOptions o;
  o.lockin_cycles = lockin_cycles;
  o.lockin_bandwidth = tdimg_feedback().lockin_bandwidth;
  return TimeDomainEngine(tdimg_model(), tdimg_map(), tdimg_cantilever().scales(), o);
}

TEST(TimeDomainImaging, AFlatSampleHoldsTheSetPointAndImagesZeroHeight) {
  const scan::Surface s = tdimg_surface(scan::flat(tdimg_grid(1e-6, 16)));
  TimeDomainEngine engine = tdimg_engine(2);
  const ImagingResult r = scan_image(engine, s, tdimg_raster(8, 8, 20.0), tdimg_feedback());
  EXPECT_TRUE(engine.engaged_by_shooting());
  EXPECT_EQ(engine.cycles(), 8 * 8 * 2 * 20);
  // engaged where the periodic orbit's amplitude is the set-point: within the map's grid step of its linear guess
  const OrbitMap::Engaged e = tdimg_map().engage(kTdimgSetpoint * kTdimgA0);
  EXPECT_NEAR(r.engaged_separation, e.separation * 1e-9, 12.0 / 31.0 * 1e-9);
  // the set-point held: the orbit is periodic, the lock-in reads it to the cycles' tolerance ε (1e-8 relative): the
  // orbit shot at 1e-10, stepped at ε, moves by the local error of the cycles it remembers (Q/π = 32 cycles: < 100 ε;
  // measured 16 ε)
  const double a_sp = kTdimgSetpoint * kTdimgA0 * 1e-9;
  const double eps = TimeDomainOptions{}.cycle_tolerance;
  for (const ImageChannels* c : {&r.trace, &r.retrace}) {
    for (double v : c->error.data()) EXPECT_LT(std::abs(v), 100.0 * eps * a_sp);
    for (double z : c->height.data()) EXPECT_NEAR(z, r.engaged_separation, 1e-6 * a_sp);
    for (double v : c->regime.data()) EXPECT_EQ(v, 2.0);  // repulsive
    for (double v : c->peak_force.data()) EXPECT_GT(v, 0.0);
  }
  const ImagingMetrics m = imaging_metrics(r);
  EXPECT_LT(m.trace_height_rms_error, 1e-6 * a_sp);
  EXPECT_EQ(m.switches_per_line, 0.0);
}

TEST(TimeDomainImaging, AStepIsImagedAsTheQuasiStaticEngineImagesIt) {
  // one step up of 1 nm at x = 0 (terraces 0.6 µm wide, the sample map's pixel 2 nm), on the repulsive branch
  const double height = 1e-9;
  const scan::Surface s = tdimg_surface(scan::steps(tdimg_grid(1.2e-6, 600), {0.6e-6, height, 0.0}));
  const long pixels = 16;
  const double cycles = 80.0;
  const RasterSpec raster = tdimg_raster(pixels, 1, cycles);
  FeedbackSpec f = tdimg_feedback();
  f.integral_gain = 4000.0;
  TimeDomainEngine td = tdimg_engine();
  const ImagingResult r = scan_image(td, s, raster, f);
  const double tau_c = 2.0 * kTdimgQ / (2.0 * std::numbers::pi * kTdimgF0);
  QuasiStaticEngine qs(tdimg_map(), tdimg_cantilever().scales(), tau_c, f.lockin_bandwidth);
  const ImagingResult q = scan_image(qs, s, raster, f);
  // The bound. Both engines hold A = A_sp on each terrace once settled, at the same separation on both terraces
  // (the map's interpolation moves the quasi-static engine's separation by the same offset on both: it cancels in
  // the step); what differs is how they settle after the edge. The loop's time constant is τ_L = 1/(K_i S), S the
  // slope dA/dl at the set-point (from the map); the cantilever (τ_c) and the lock-in (τ_li) delay it. The right
  // quarter starts t_s = (pixels/4) · cycles · T after the edge (the left one as long after the engagement or the
  // line's turn): each engine's residual there is below h e^{−(t_s − τ_c − τ_li)/τ_L}, their difference below twice
  // that.
  const OrbitMap& m = tdimg_map();
  const OrbitMap::Engaged e = m.engage(kTdimgSetpoint * kTdimgA0);
  const double dl = 0.25;  // nm
  const double slope = (m.at(e.branch, e.separation + dl).amplitude - m.at(e.branch, e.separation - dl).amplitude) /
                       (2.0 * dl);
  const double tau_loop = 1.0 / (f.integral_gain * slope);
  const double t_s = static_cast<double>(pixels / 4) * cycles / kTdimgF0;
  const double tau_li = 1.0 / (2.0 * std::numbers::pi * f.lockin_bandwidth);
  const double bound = 2.0 * height * std::exp(-(t_s - tau_c - tau_li) / tau_loop);
  ASSERT_LT(bound, 0.1 * height);  // the case resolves the step
  for (const auto& [t, qq] : {std::pair{&r.trace, &q.trace}, std::pair{&r.retrace, &q.retrace}}) {
    const double td_step = test::right_minus_left_quarter(t->height);
    const double qs_step = test::right_minus_left_quarter(qq->height);
    EXPECT_NEAR(td_step, qs_step, bound);
    EXPECT_NEAR(td_step, height, bound);
  }
  for (double v : r.trace.regime.data()) EXPECT_EQ(v, 2.0);
}

TEST(TimeDomainImaging, CyclesRunInPiecesStartFromTheStepTheLastOneEndedWith) {
  // the engine runs the motion cycle by cycle: each piece starting from the step the last one ended with
  // (SimulationOptions::initial_step = SimulationStats::next_step) takes about as many steps as one run over all of
  // them (at most two more a piece: the clipped last step, the step after it), where starting afresh grows again
  // from 1e-3 of a period (fewer steps in all).
  // From rest (the steps are the largest, a 24th of a period: 24 of them end a rounding below the period's end,
  // where the remainder once was refused as a step underflow) and from the free orbit's amplitude (in contact at
  // separation 7 nm, A0 = 10 nm: two events a cycle).
  TappingModel model = tdimg_model();
  model.separation = 7.0;
  const TappingSystem sys(model);
  SimulationOptions o;
  o.integrator = Integrator::adaptive;
  const double period = model.period(), omega = model.drive.frequency;
  const int pieces = 20;
  for (const TipState start : {TipState{}, TipState{0.0, kTdimgA0 * omega}}) {
    const SimulationResult whole = simulate(sys, 0.0, start, pieces * period, o);
    TipState carried = start, fresh = start;
    long carried_steps = 0, fresh_steps = 0, events = 0;
    double next = 0.0;
    for (int k = 0; k < pieces; ++k) {
      SimulationOptions c = o;
      c.initial_step = next;
      const SimulationResult r = simulate(sys, k * period, carried, (k + 1) * period, c);
      carried = r.state;
      carried_steps += r.stats.steps;
      events += r.stats.events;
      next = r.stats.next_step;
      EXPECT_GT(next, 0.0);
      const SimulationResult f = simulate(sys, k * period, fresh, (k + 1) * period, o);
      fresh = f.state;
      fresh_steps += f.stats.steps;
    }
    EXPECT_EQ(events > 0, start.velocity > 0.0);
    EXPECT_LE(carried_steps, whole.stats.steps + 2 * pieces);
    EXPECT_LT(carried_steps, fresh_steps);
    // the same motion to the tolerance (1e-10 relative of the amplitude, kept over 20 periods)
    EXPECT_NEAR(carried.position, whole.state.position, 1e-7 * kTdimgA0);
    EXPECT_NEAR(fresh.position, whole.state.position, 1e-7 * kTdimgA0);
  }
  o.initial_step = -1.0;
  try {
    o.validate();
    ADD_FAILURE() << "initial_step < 0 accepted";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "initial_step");
  }
}

TEST(TimeDomainImaging, CycleIntegralsUseTheStepsOwnStagesAndMatchTheDrivenOscillator) {
  // Far from the sample (separation 1e6 nm: the vdW force 3e-12 of the amplitude) the motion from the steady state
  // x = Re(Z e^{iωt}), Z = Γ/(ω_n² − ω² + icω), is the linear oscillator's: over one period ∫ x e^{−iωt} dt = T Z/2
  // and ∫ ẋ² dt = ω²|Z|² T/2. Every step of DOP853 offers its own stages (weights summing to the step); the segments
  // cut by an event (in contact, separation 7 nm: two a cycle) do not, and are integrated on the dense output.
  struct TdimgStageCount final : TrajectoryObserver {
    CycleIntegrals integrals;
    long whole = 0, cut = 0;
    double weights = 0.0, length = 0.0;
    explicit TdimgStageCount(double period) : integrals(period) {}
    void on_segment(const TappingSystem& system, const Segment& segment) override {
      struct Sum final : StageVisitor {
        double w = 0.0;
        void node(double, double weight, const TipState&) override { w += weight; }
      } sum;
      if (segment.stage_quadrature(sum)) {
        ++whole;
        weights += sum.w;
        length += segment.t_end() - segment.t_begin();
      } else {
        ++cut;
      }
      integrals.on_segment(system, segment);
    }
  };
  TappingModel model = tdimg_model();
  model.separation = 1e6;
  TappingSystem sys(model);
  SimulationOptions o;
  o.integrator = Integrator::adaptive;
  o.relative_tolerance = 1e-8;
  o.absolute_tolerance = 1e-10;
  o.max_step_fraction = TimeDomainEngine::kCycleMaxStepFraction;
  const double w = model.drive.frequency, period = model.period(), c = sys.damping(), k = sys.stiffness();
  const std::complex<double> z = model.drive.amplitude / std::complex<double>(k - w * w, c * w);
  const TipState start{z.real(), -w * z.imag()};
  TdimgStageCount free(period);
  const SimulationResult r = simulate(sys, 0.0, start, period, o, &free);
  EXPECT_EQ(r.stats.events, 0);
  EXPECT_EQ(free.cut, 0);
  EXPECT_EQ(free.whole, r.stats.steps);
  EXPECT_NEAR(free.weights, period, 1e-13 * period);
  EXPECT_NEAR(free.length, period, 1e-13 * period);
  const std::complex<double> expected = 0.5 * period * z;
  EXPECT_LT(std::abs(free.integrals.first_harmonic - expected), 1e-8 * std::abs(expected));  // measured 1.3e-9
  const double square = 0.5 * period * w * w * std::norm(z);
  EXPECT_NEAR(free.integrals.velocity_square, square, 1e-8 * square);  // measured 3.0e-9

  sys.set_separation(7.0);
  TdimgStageCount contact(period);
  const SimulationResult e = simulate(sys, 0.0, start, 3.0 * period, o, &contact);
  EXPECT_GT(e.stats.events, 0);
  EXPECT_EQ(contact.cut, e.stats.events);
  EXPECT_EQ(contact.whole + contact.cut, e.stats.steps);
  EXPECT_NEAR(contact.weights, contact.length, 1e-12 * period);
}

TEST(TimeDomainImaging, BadLockInOptionsNameTheirParameter) {
  const auto tdimg_name_of = [](const TimeDomainOptions& o) {
    try {
      o.validate();
    } catch (const InvalidParameter& e) {
      return e.parameter();
    }
    return std::string("none");
  };
  TimeDomainOptions o;
  EXPECT_EQ(tdimg_name_of(o), "none");
  o.lockin_cycles = 0;
  EXPECT_EQ(tdimg_name_of(o), "lockin_cycles");
  o = {};
  o.lockin_bandwidth = -1.0;
  EXPECT_EQ(tdimg_name_of(o), "lockin_bandwidth");
  o = {};
  o.cycle_tolerance = 0.0;
  EXPECT_EQ(tdimg_name_of(o), "cycle_tolerance");
}

TEST(TimeDomainImaging, LiftedOffTheSampleTheLockInReadsTheFreeEnvelopeAndTheRegimeIsFree) {
  // a piecewise-linear hysteresis law (the closed-form flow; no force out of contact): engaged in contact, then Z
  // lifted so far that the tip never touches again. The motion is then the linear oscillator's, x = x_f + Re(V e^{λt}),
  // λ = −ω0/(2Q) + iω_d, ω_d = ω0 √(1 − 1/(4Q²)): at resonance the lock-in's X + iY = conj((2/T) ∫ x e^{−iωt} dt)
  // relaxes to the free one X_f = i A0 (φ = 90°) as
  //   X_k − X_f = (X_1 − X_f) e^{−(k − 1) T/τ_c} e^{i(ω − ω_d)(k − 1) T},   τ_c = 2Q/ω0
  // from the first cycle after the lift on (no output filter, a one-cycle window: each reading is one cycle's).
  const PhysicalCantilever& pc = tdimg_cantilever();
  const TappingModel model(pc.cantilever(), pc.drive(),
                           pc.normalised_law(impact::ForceLaw(impact::PiecewiseLinearLaw::linear_hysteresis(50.0, 40.0))),
                           20.0);
  OrbitMapOptions mo;
  mo.separation_min = 0.0;
  mo.separation_max = 12.0;
  mo.points = 24;
  const OrbitMap map = OrbitMap::build(model, mo);
  // the closed-form flow (exact), and the adaptive integrator at a looser tolerance (the by-parts balance of the
  // force's first harmonic is an identity of the integrated motion: a cycle without force stays below the free
  // threshold 1e-9 Γ)
  for (const double rtol : {0.0, 1e-7}) {
  SCOPED_TRACE(rtol == 0.0 ? "closed form" : "adaptive, relative tolerance 1e-7");
  TimeDomainOptions o;
  o.lockin_bandwidth = 0.0;
  if (rtol > 0.0) {
    o.shooting.simulation.integrator = Integrator::adaptive;
    o.shooting.simulation.relative_tolerance = rtol;
    o.shooting.simulation.absolute_tolerance = 1e-2 * rtol;
    o.cycle_tolerance = rtol;
  }
  TimeDomainEngine engine(model, map, pc.scales(), o);
  const double a0 = kTdimgA0 * 1e-9, a_sp = 0.8 * a0;
  const double l = engine.engage(a_sp);
  const scan::Surface s = tdimg_surface(scan::flat(tdimg_grid(1e-6, 8)));
  const double period = 1.0 / kTdimgF0, tau_c = 2.0 * kTdimgQ / (2.0 * std::numbers::pi * kTdimgF0);
  // still engaged: in contact, repulsive, at the set-point
  TipReading r = engine.advance(s, l, 0.0, 0.0, 0.0, period);
  EXPECT_EQ(r.regime, 2);
  EXPECT_NEAR(r.amplitude, a_sp, 1e-6 * a_sp);
  const std::complex<double> xf(0.0, a0);
  // lifted by 5 nm: l + 5 nm > A0, no contact again
  const double z = l + 5e-9;
  const double omega = 2.0 * std::numbers::pi * kTdimgF0;
  const double omega_d = omega * std::sqrt(1.0 - 1.0 / (4.0 * kTdimgQ * kTdimgQ));
  std::complex<double> x1;
  double worst = 0.0;
  for (int k = 1; k <= 100; ++k) {
    r = engine.advance(s, z, 0.0, 0.0, 0.0, period);
    EXPECT_EQ(r.regime, 0) << "cycle " << k;
    EXPECT_EQ(r.peak_force, 0.0);
    EXPECT_LT(std::abs(r.power), 1e-9 * 0.5 * 40.0 * a0 * a0 / period);  // of the energy ½ k A0² per cycle
    const std::complex<double> x(r.in_phase, r.quadrature);
    if (k == 1) x1 = x;
    const double t = (k - 1) * period;
    const std::complex<double> expected = xf + (x1 - xf) * std::exp(std::complex<double>(-t / tau_c, (omega - omega_d) * t));
    worst = std::max(worst, std::abs(x - expected));
  }
  EXPECT_GT(std::abs(x1 - xf), 0.1 * a0);  // far from the free state at the start
  // Bound: a one-cycle demodulation of a decaying motion keeps a little of its counter-rotating part, (αT/4π)|V| =
  // |X_1 − X_f|/(4Q); it decays alike but turns the other way, so it departs from the formula by at most
  // |X_1 − X_f|/(4Q) · 2(ω − ω_d) t over the run (the closed-form flow and the quadrature are exact to ~1e-12)
  const double bound = std::abs(x1 - xf) / (4.0 * kTdimgQ) * 2.0 * (omega - omega_d) * 100.0 * period +
                       (rtol > 0.0 ? 10.0 * rtol : 1e-9) * a0;
  EXPECT_LT(worst, bound);
  }
}

}  // namespace
}  // namespace afmkit::tapping::image
