// The float32 C core (afmkit_embed_core): rejection and pass-through in the closed loop, no drift of the undamped
// (magic-circle) modes over 10⁹ samples while the naive coupled form drifts, skip rule, test vectors.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

// This file tests the float core: test_embed also links afmkit_embed_core_double, whose PUBLIC compile definition
// AFMKIT_EMBED_DOUBLE reaches every file of the program, so it is undone here before the C header is included.
#undef AFMKIT_EMBED_DOUBLE
#include "afmkit/embed/afmkit_embed.h"  // float
#include <Eigen/Dense>

#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/embed/c_header.hpp"
#include "afmkit/embed/test_vectors.hpp"
#include "embed_support.hpp"

namespace {
using namespace afmkit::embed;
using embed_test::kSamplesPerTurn;

struct FloatCore {
  std::vector<float> pair, circle, real, state;
  afmkit_embed_coefficients c{};
  afmkit_embed_filter f{};
  explicit FloatCore(const ExportedDesign& d) {
    for (double x : d.pair_coefficients()) pair.push_back(static_cast<float>(x));
    for (double x : d.circle_coefficients()) circle.push_back(static_cast<float>(x));
    for (double x : d.real_coefficients()) real.push_back(static_cast<float>(x));
    c = {AFMKIT_EMBED_MAGIC, AFMKIT_EMBED_VERSION, AFMKIT_EMBED_PRECISION_BITS, static_cast<uint32_t>(d.pairs()),
         static_cast<uint32_t>(d.circles()), static_cast<uint32_t>(d.reals()), static_cast<float>(d.input_limit()),
         pair.empty() ? nullptr : pair.data(), circle.empty() ? nullptr : circle.data(),
         real.empty() ? nullptr : real.data()};
    state.resize(afmkit_embed_state_size(&c));
    EXPECT_EQ(afmkit_embed_init(&f, &c, state.data(), state.size()), AFMKIT_EMBED_OK);
  }
};

TEST(EmbedFloatCore, ExactSizesAndFootprint) {
  // the footprint the exporter checks against target_memory is the C types' own sizeof
  const ExportedDesign d(embed_test::reference_spec(Precision::Float));
  const CoreFootprint fp = d.footprint();
  EXPECT_EQ(fp.coefficient_struct, sizeof(afmkit_embed_coefficients));
  EXPECT_EQ(fp.filter_struct, sizeof(afmkit_embed_filter));
  EXPECT_EQ(fp.coefficient_arrays, sizeof(float) * (AFMKIT_EMBED_PAIR_STRIDE * d.pairs() +
                                                    AFMKIT_EMBED_CIRCLE_STRIDE * d.circles() +
                                                    AFMKIT_EMBED_REAL_STRIDE * d.reals()));
  EXPECT_EQ(fp.state, sizeof(float) * 21);  // 2N + 1 numbers, N = 10
  EXPECT_EQ(d.circles(), 1);                // harmonic 1 rejected: one undamped pair
  EXPECT_EQ(2 * (d.pairs() + d.circles()) + d.reals(), 21);
}

// Closed loop m_n = d_n + u_{n−1}/K (static plant γ = K, one sample of delay), 10⁷ samples = 10⁵ turns.
// Reference for harmonic k (independent of the time-domain run): the sampled loop in the frequency domain,
//   M_k = D_k / (1 − z⁻¹ G(z)/K),  z = e^{ikΩh},  G(z) = C (zI − Φ)⁻¹ Γ
// with the double filter's dense Φ, Γ, C (RealtimeFilter::transition_matrix etc.). For k = 1 the undamped pole at z
// makes G infinite: M_1 = 0. The zero-order-hold form is not exactly transparent at the kept harmonics
// (|M_k/D_k − 1| ≈ 1e-3 k Ω h, a property of the sampled controller, not of float): the float core is compared with
// M_k, and the sampled controller's own deviation from D_k is printed.
TEST(EmbedFloatCore, ClosedLoopRejectsFirstHarmonicAndKeepsTheOthers) {
  const int n_harm = 10;
  const ExportedDesign d(embed_test::reference_spec(Precision::Float, n_harm));
  FloatCore core(d);
  const embed_test::Disturbance dist(n_harm);
  const long long total = 10000000, tail = 1000LL * kSamplesPerTurn;  // measure over the last 1000 turns
  const double gain = d.spec().gain;
  std::vector<double> m_tail;
  m_tail.reserve(static_cast<std::size_t>(tail));
  float u = 0.0f;
  for (long long n = 0; n < total; ++n) {
    const double m = dist.at(n) + u / gain;
    if (n >= total - tail) m_tail.push_back(m);
    u = afmkit_embed_step(&core.f, static_cast<float>(m));
  }
  ASSERT_EQ(total % kSamplesPerTurn, 0);
  const afmkit::control::RealtimeFilter ref(d.spec().bank(), d.spec().sample_rate);
  const Eigen::MatrixXcd phi = ref.transition_matrix().cast<std::complex<double>>();
  const Eigen::VectorXcd gamma = ref.input_vector().cast<std::complex<double>>();
  const Eigen::RowVectorXcd out = ref.output_vector().cast<std::complex<double>>();
  const double h = 1.0 / d.spec().sample_rate, omega = d.spec().rotation_frequency;
  const double first = std::abs(embed_test::harmonic(m_tail, 1));
  const double rejection_db = -20.0 * std::log10(first / std::abs(dist.d[0]));
  double worst_rel = 0.0, zoh_dev = 0.0;
  for (int k = 2; k <= n_harm; ++k) {
    const std::complex<double> z = std::polar(1.0, k * omega * h);
    const Eigen::MatrixXcd zi = z * Eigen::MatrixXcd::Identity(phi.rows(), phi.cols()) - phi;
    const std::complex<double> g = out * zi.partialPivLu().solve(gamma);
    const std::complex<double> want = dist.d[static_cast<std::size_t>(k - 1)] / (1.0 - g / (z * gain));
    worst_rel = std::max(worst_rel, std::abs(embed_test::harmonic(m_tail, k) - want) / std::abs(want));
    zoh_dev = std::max(zoh_dev, std::abs(want / dist.d[static_cast<std::size_t>(k - 1)] - 1.0));
  }
  const double offset_err = std::abs(embed_test::harmonic(m_tail, 0).real() - dist.offset);
  std::printf("float core, 1e7 samples: first harmonic %.3g (rejection %.1f dB), harmonics 2..%d max rel error vs the "
              "sampled loop %.3g (the zero-order-hold controller itself: max |M_k/D_k - 1| = %.3g), offset error "
              "%.3g\n", first, rejection_db, n_harm, worst_rel, zoh_dev, offset_err);
  EXPECT_GE(rejection_db, 100.0);
  EXPECT_LE(worst_rel, 1e-5);
  EXPECT_LE(offset_err, 1e-5 * dist.offset);
  EXPECT_EQ(core.f.skipped, 0u);
}

// Pure undamped modes: magic circles with ε = fl(2 sin(φ/2)), φ = 2πk/100 (harmonic k at 100 samples per turn),
// Invariant of the map [[1, −ε], [ε, 1 − ε²]]: I = y1² + y2² − ε y1 y2 (exact for any ε; positive definite for
// |ε| < 2), i.e. the squared amplitude in these coordinates.
struct Circle {
  float eps;
  float coefficients[7];
  afmkit_embed_coefficients c;
  float state[2];
  afmkit_embed_filter f;
  double i0 = 0.0;
  explicit Circle(int k)
      : eps(static_cast<float>(2.0 * std::sin(std::numbers::pi * k / kSamplesPerTurn))),
        coefficients{eps, 1.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f},
        c{AFMKIT_EMBED_MAGIC, AFMKIT_EMBED_VERSION, AFMKIT_EMBED_PRECISION_BITS, 0, 1, 0, 1e15f, nullptr,
          coefficients, nullptr},
        state{0.0f, 0.0f} {
    EXPECT_EQ(afmkit_embed_init(&f, &c, state, 2), AFMKIT_EMBED_OK);
    (void)afmkit_embed_step(&f, 1.0f);  // excite: y = (1, 0) after the first sample
    i0 = invariant();
  }
  double invariant() const {
    const double y1 = state[0], y2 = state[1];
    return y1 * y1 + y2 * y2 - static_cast<double>(eps) * y1 * y2;
  }
};

// 10⁹ samples of zero input, the invariant checked every 10⁶. Under the sanitizers (which look for memory errors
// and undefined behaviour in the step, not for drift: a property of the arithmetic, tested in Release) 10⁷.
#ifdef AFMKIT_TEST_SANITIZED
constexpr int kDriftBlocks = 10;
#else
constexpr int kDriftBlocks = 1000;
#endif

double invariant_drift(int k) {
  Circle c(k);
  double worst = 0.0;
  for (int block = 0; block < kDriftBlocks; ++block) {
    for (int j = 0; j < 1000000; ++j) (void)afmkit_embed_step(&c.f, 0.0f);
    worst = std::max(worst, std::abs(c.invariant() / c.i0 - 1.0));
  }
  std::printf("magic circle, harmonic %d, %d x 1e6 float samples: max relative change of the invariant %.3g\n", k,
              kDriftBlocks, worst);
  return worst;
}

TEST(EmbedFloatCore, UndampedHarmonic1DoesNotDriftOver1e9Samples) {
  EXPECT_LE(invariant_drift(1), 1e-5);  // stated bound (docs/embedding.md)
}

TEST(EmbedFloatCore, UndampedHarmonic3DoesNotDriftOver1e9Samples) {
  EXPECT_LE(invariant_drift(3), 1e-5);
}

// The same rotation in the coupled form q ← [[c, −s], [s, c]] q with c = fl(cos φ), s = fl(sin φ) (what a naive
// port would do): |c + is| ≠ 1 in float, so the amplitude drifts exponentially. 10⁸ samples suffice to show it
// for harmonics 8 (decays) and 12 (grows) at 100 samples per turn (at some other angles, harmonic 1 here, the float
// products happen to round back onto the same amplitude; the lead measured the drift at other angles).
TEST(EmbedFloatCore, NaiveCoupledFormWouldDrift) {
  for (int k : {8, 12}) {
    const double phi = 2.0 * std::numbers::pi * k / kSamplesPerTurn;
    const float c = static_cast<float>(std::cos(phi)), s = static_cast<float>(std::sin(phi));
    float q1 = 1.0f, q2 = 0.0f;
    for (long long n = 0; n < 100000000LL; ++n) {
      const float a = c * q1 - s * q2, b = c * q2 + s * q1;
      q1 = a;
      q2 = b;
    }
    const double amplitude = std::hypot(static_cast<double>(q1), static_cast<double>(q2));
    std::printf("naive coupled form, harmonic %d: amplitude after 1e8 float samples %.3g (start 1)\n", k, amplitude);
    EXPECT_GT(std::abs(std::log(amplitude)), 0.05) << "k = " << k;  // > 5 % drift (the circle: < 1e-5 over 1e9)
  }
}

TEST(EmbedFloatCore, SkipRuleHoldsOutputAndCoasts) {
  const ExportedDesign d(embed_test::reference_spec(Precision::Float, 3));
  FloatCore a(d), b(d);
  const embed_test::Disturbance dist(3);
  // a: garbage samples at n = 500 (NaN), 501 (+inf), 502 (−inf), 503 (above the limit); b: the same with those
  // samples replaced by the core's own coasting input, computed by the test from the state and the coast weights
  const float bad[4] = {std::nanf(""), INFINITY, -INFINITY, 2.0f * static_cast<float>(d.input_limit())};
  float ua = 0, ub = 0;
  for (int n = 0; n < 2000; ++n) {
    float m = static_cast<float>(dist.at(n) + ua / d.spec().gain);
    if (n >= 500 && n < 504) {
      const float held = a.f.held;
      ua = afmkit_embed_step(&a.f, bad[n - 500]);
      EXPECT_EQ(ua, held) << "n = " << n;
      // coasting input m = Σ e·q over b's state (pairs: e1, e2 at 6, 7; circles: 5, 6; reals: 3)
      double coast = 0.0;
      std::size_t i = 0;
      for (int j = 0; j < d.pairs(); ++j, i += 2)
        coast += b.pair[8 * j + 6] * b.state[i] + b.pair[8 * j + 7] * b.state[i + 1];
      for (int j = 0; j < d.circles(); ++j, i += 2)
        coast += b.circle[7 * j + 5] * b.state[i] + b.circle[7 * j + 6] * b.state[i + 1];
      for (int j = 0; j < d.reals(); ++j, ++i) coast += b.real[4 * j + 3] * b.state[i];
      (void)afmkit_embed_step(&b.f, static_cast<float>(coast));
      b.f.held = held;  // b took the coasting sample as a real one; its output is not used
      ub = held;
      continue;
    }
    ua = afmkit_embed_step(&a.f, m);
    ub = afmkit_embed_step(&b.f, m);
    EXPECT_NEAR(ua, ub, 1e-4f * (1.0f + std::abs(ub))) << "n = " << n;
  }
  EXPECT_EQ(a.f.skipped, 4u);
  for (float x : a.state) EXPECT_TRUE(std::isfinite(x));
  // the limit itself is accepted
  (void)afmkit_embed_step(&a.f, static_cast<float>(d.input_limit()));
  EXPECT_EQ(a.f.skipped, 4u);
  afmkit_embed_reset(&a.f);
  EXPECT_EQ(a.f.skipped, 0u);
  EXPECT_EQ(a.f.held, 0.0f);
  for (float x : a.state) EXPECT_EQ(x, 0.0f);
}

TEST(EmbedFloatCore, StepBlockEqualsStep) {
  const ExportedDesign d(embed_test::reference_spec(Precision::Float, 4));
  FloatCore a(d), b(d);
  std::vector<float> in(777), out(777);
  for (std::size_t n = 0; n < in.size(); ++n) in[n] = static_cast<float>(embed_test::Disturbance(4).at(n));
  in[100] = NAN;
  afmkit_embed_step_block(&a.f, in.data(), out.data(), in.size());
  for (std::size_t n = 0; n < in.size(); ++n) EXPECT_EQ(out[n], afmkit_embed_step(&b.f, in[n]));
  afmkit_embed_step_block(&a.f, in.data(), in.data(), in.size());  // in place
  EXPECT_EQ(a.f.skipped, 2u);
}

TEST(EmbedFloatCore, InitErrors) {
  const ExportedDesign d(embed_test::reference_spec(Precision::Float, 2));
  FloatCore ok(d);
  afmkit_embed_coefficients c = ok.c;
  std::vector<float> state(ok.state.size());
  afmkit_embed_filter f;
  EXPECT_EQ(afmkit_embed_init(nullptr, &c, state.data(), state.size()), AFMKIT_EMBED_ERR_NULL);
  EXPECT_EQ(afmkit_embed_init(&f, nullptr, state.data(), state.size()), AFMKIT_EMBED_ERR_NULL);
  EXPECT_EQ(afmkit_embed_init(&f, &c, nullptr, state.size()), AFMKIT_EMBED_ERR_NULL);
  EXPECT_EQ(afmkit_embed_init(&f, &c, state.data(), state.size() - 1), AFMKIT_EMBED_ERR_STATE_SIZE);
  EXPECT_EQ(afmkit_embed_state_size(&c), 5u);
  EXPECT_EQ(afmkit_embed_state_size(nullptr), 0u);
  auto with = [&](auto change) {
    afmkit_embed_coefficients x = ok.c;
    change(x);
    return afmkit_embed_init(&f, &x, state.data(), state.size());
  };
  EXPECT_EQ(with([](auto& x) { x.magic = 0; }), AFMKIT_EMBED_ERR_MAGIC);
  EXPECT_EQ(with([](auto& x) { x.version = 2; }), AFMKIT_EMBED_ERR_MAGIC);
  EXPECT_EQ(with([](auto& x) { x.precision = 64; }), AFMKIT_EMBED_ERR_MAGIC);  // a double set to the float core
  EXPECT_EQ(with([](auto& x) { x.circle = nullptr; }), AFMKIT_EMBED_ERR_COEFFICIENTS);
  EXPECT_EQ(with([](auto& x) { x.pairs = x.circles = x.reals = 0; }), AFMKIT_EMBED_ERR_COEFFICIENTS);
  EXPECT_EQ(with([](auto& x) { x.input_limit = 0.0f; }), AFMKIT_EMBED_ERR_VALUE);
  EXPECT_EQ(with([](auto& x) { x.input_limit = INFINITY; }), AFMKIT_EMBED_ERR_VALUE);
  std::vector<float> bad = ok.circle;
  bad[1] = NAN;
  EXPECT_EQ(with([&](auto& x) { x.circle = bad.data(); }), AFMKIT_EMBED_ERR_VALUE);
  bad = ok.circle;
  bad[0] = 2.0f;  // |ε| ≥ 2: the magic circle would not rotate
  EXPECT_EQ(with([&](auto& x) { x.circle = bad.data(); }), AFMKIT_EMBED_ERR_VALUE);
  std::vector<float> pair = ok.pair;
  pair[0] = 1.0f;  // |c + is| ≥ 1: not a damped pair
  EXPECT_EQ(with([&](auto& x) { x.pair = pair.data(); }), AFMKIT_EMBED_ERR_VALUE);
  EXPECT_EQ(afmkit_embed_init(&f, &ok.c, state.data(), state.size()), AFMKIT_EMBED_OK);
}

TEST(EmbedFloatCore, PassesItsOwnTestVectors) {
  const ExportedDesign d(embed_test::reference_spec(Precision::Float, 10));
  const TestVectors tv = make_test_vectors(d, 200000);
  const double worst = run_core_closed_loop(d, tv);
  std::printf("float core vs double RealtimeFilter, closed loop, 2e5 samples: max |m - expected| = %.3g (tolerance "
              "%.3g)\n", worst, tv.tolerance);
  EXPECT_LE(worst, tv.tolerance);
  EXPECT_GT(worst, 0.0);  // float really differs from double (the comparison is not vacuous)
}

}  // namespace
