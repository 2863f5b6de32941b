// The double C core (afmkit_embed_core_double, symbols afmkit_embed_d_*) against afmkit::control::RealtimeFilter.
// test_embed links afmkit_embed_core_double, whose PUBLIC definition AFMKIT_EMBED_DOUBLE already reaches this file;
// defined here too so that the file states its precision.
#ifndef AFMKIT_EMBED_DOUBLE
#define AFMKIT_EMBED_DOUBLE 1
#endif
#include "afmkit/embed/afmkit_embed.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/embed/design.hpp"
#include "afmkit/embed/test_vectors.hpp"
#include "embed_support.hpp"

namespace {
using namespace afmkit::embed;

static_assert(sizeof(afmkit_embed_real) == sizeof(double));

struct DoubleCore {
  std::vector<double> pair, circle, real, state;
  afmkit_embed_coefficients c{};
  afmkit_embed_filter f{};
  explicit DoubleCore(const ExportedDesign& d)
      : pair(d.pair_coefficients()), circle(d.circle_coefficients()), real(d.real_coefficients()) {
    c = {AFMKIT_EMBED_MAGIC, AFMKIT_EMBED_VERSION, AFMKIT_EMBED_PRECISION_BITS, static_cast<uint32_t>(d.pairs()),
         static_cast<uint32_t>(d.circles()), static_cast<uint32_t>(d.reals()), d.input_limit(),
         pair.empty() ? nullptr : pair.data(), circle.empty() ? nullptr : circle.data(),
         real.empty() ? nullptr : real.data()};
    state.resize(afmkit_embed_state_size(&c));
    EXPECT_EQ(afmkit_embed_init(&f, &c, state.data(), state.size()), AFMKIT_EMBED_OK);
  }
};

// Deterministic input: the disturbance plus a pseudo-random part (LCG), so that every mode is excited.
double input(long long n, const embed_test::Disturbance& d, std::uint64_t& lcg) {
  lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
  return d.at(n) + 0.3 * (static_cast<double>(lcg >> 11) * 0x1.0p-53 - 0.5);
}

// Closed loop m = d + u/K around each (static plant, one sample of delay): bounded signals, as on the instrument.
// Open loop the rejected oscillator is driven at resonance and grows linearly (u ~ 1e7 after 1e6 samples); there the
// agreement is checked relative to the peak with 1e-11 (the phase of the undamped mode: ε = 2 sin(φ/2) rounded).
TEST(EmbedDoubleCore, EqualsRealtimeFilterOnALongRun) {
  for (int n_harm : {1, 10, 40}) {
    const ExportedDesign d(embed_test::reference_spec(Precision::Double, n_harm));
    DoubleCore core(d), open(d);
    afmkit::control::RealtimeFilter ref(d.spec().bank(), d.spec().sample_rate), ref_open = ref;
    const embed_test::Disturbance dist(n_harm);
    const double gain = d.spec().gain;
    std::uint64_t lcg = 1;
    double worst = 0.0, peak = 0.0, worst_open = 0.0, peak_open = 0.0, ua = 0.0, ub = 0.0;
    for (long long n = 0; n < 1000000; ++n) {
      const double x = input(n, dist, lcg);
      ua = afmkit_embed_step(&core.f, x + ua / gain);
      ub = ref.step(x + ub / gain);
      worst = std::max(worst, std::abs(ua - ub));
      peak = std::max(peak, std::abs(ub));
      const double oa = afmkit_embed_step(&open.f, x), ob = ref_open.step(x);
      worst_open = std::max(worst_open, std::abs(oa - ob));
      peak_open = std::max(peak_open, std::abs(ob));
    }
    std::printf("double core vs RealtimeFilter, N = %d, 1e6 samples: max |du| / max |u| = %.3g closed loop, %.3g "
                "open loop (u up to %.3g)\n", n_harm, worst / peak, worst_open / peak_open, peak_open);
    EXPECT_LE(worst, 1e-12 * peak) << "N = " << n_harm;
    EXPECT_LE(worst_open, 1e-11 * peak_open) << "N = " << n_harm;
    EXPECT_GT(peak, 1.0);
  }
}

TEST(EmbedDoubleCore, SkipRuleMatchesRealtimeFilter) {
  ExportSpec s = embed_test::reference_spec(Precision::Double, 5);
  s.input_limit = 10.0;
  const ExportedDesign d(s);
  DoubleCore core(d);
  afmkit::control::RealtimeFilter ref(d.spec().bank(), d.spec().sample_rate);
  ref.set_input_limit(10.0);
  const embed_test::Disturbance dist(5);
  std::uint64_t lcg = 7;
  double worst = 0.0, peak = 0.0, ua = 0.0, ub = 0.0;
  const double inf = std::numeric_limits<double>::infinity(), gain = d.spec().gain;
  for (long long n = 0; n < 20000; ++n) {
    const double x = input(n, dist, lcg);
    double ma = x + ua / gain, mb = x + ub / gain;
    if (n % 97 == 13) ma = mb = std::nan("");
    if (n % 101 == 50) ma = mb = n % 2 ? inf : -inf;
    if (n % 103 == 70) ma = mb = 10.5;   // above the limit
    if (n % 107 == 80) ma = mb = -10.0;  // at the limit: accepted
    const double held = core.f.held;
    ua = afmkit_embed_step(&core.f, ma);
    ub = ref.step(mb);
    if (!(std::abs(ma) <= 10.0)) {
      EXPECT_EQ(ua, held);
    }
    worst = std::max(worst, std::abs(ua - ub));
    peak = std::max(peak, std::abs(ub));
  }
  EXPECT_LE(worst, 1e-12 * peak);
  EXPECT_EQ(core.f.skipped, ref.skipped_samples());
  EXPECT_GT(core.f.skipped, 500u);
}

TEST(EmbedDoubleCore, ExactSizes) {
  const ExportedDesign d(embed_test::reference_spec(Precision::Double, 10));
  const CoreFootprint fp = d.footprint();
  EXPECT_EQ(fp.coefficient_struct, sizeof(afmkit_embed_coefficients));
  EXPECT_EQ(fp.filter_struct, sizeof(afmkit_embed_filter));
  EXPECT_EQ(fp.state, sizeof(double) * 21);
  EXPECT_EQ(fp.coefficient_arrays, sizeof(double) * (AFMKIT_EMBED_PAIR_STRIDE * d.pairs() +
                                                     AFMKIT_EMBED_CIRCLE_STRIDE * d.circles() +
                                                     AFMKIT_EMBED_REAL_STRIDE * d.reals()));
}

TEST(EmbedDoubleCore, RefusesAFloatCoefficientSet) {
  const ExportedDesign d(embed_test::reference_spec(Precision::Double, 2));
  DoubleCore core(d);
  afmkit_embed_coefficients c = core.c;
  c.precision = 32;
  afmkit_embed_filter f;
  EXPECT_EQ(afmkit_embed_init(&f, &c, core.state.data(), core.state.size()), AFMKIT_EMBED_ERR_MAGIC);
}

TEST(EmbedDoubleCore, PassesItsOwnTestVectors) {
  const ExportedDesign d(embed_test::reference_spec(Precision::Double, 10));
  const TestVectors tv = make_test_vectors(d, 100000);
  const double worst = run_core_closed_loop(d, tv);
  std::printf("double core (host build) vs RealtimeFilter, closed loop: max |m - expected| = %.3g (tolerance %.3g)\n",
              worst, tv.tolerance);
  EXPECT_LE(worst, tv.tolerance);
}

}  // namespace
