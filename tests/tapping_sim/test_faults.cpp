// Faults inside the numerics reach the caller as exceptions, never as a crash or a silent non-finite number:
// exceptions thrown inside OpenMP loops are carried out of them, a diverging motion is a NumericalFailure, and
// every law built from parameters refuses to create energy without its opt-in.
#include <gtest/gtest.h>

#include <omp.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/parallel.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/simulation.hpp"

using namespace afmkit;

TEST(Faults, AnExceptionInsideAParallelLoopIsRethrownAfterIt) {
  ExceptionCollector errors;
  int done = 0;
#pragma omp parallel for reduction(+ : done)
  for (int i = 0; i < 64; ++i) {
    errors.run([&] {
      if (i == 17) throw InvalidParameter("x", "x = 17 is out of range");
      ++done;
    });
  }
  EXPECT_TRUE(errors.failed());
  EXPECT_EQ(done, 63);  // the other iterations ran
  EXPECT_THROW(errors.rethrow(), InvalidParameter);
}

namespace {
tapping::TappingModel gaining_model(double l) {
  // K_a = 0 < K_b = 8 with the opt-in: every touch adds energy, the motion grows without bound
  impact::LawArguments a;
  a.values = {{"approach_stiffness", 0.0}, {"departure_stiffness", 8.0}};
  a.allow_energy_gain = true;
  const impact::ForceLaw law = impact::LawRegistry::builtin().build("hysteresis", a);
  return {tapping::Cantilever(1.0, 100.0), tapping::Drive(0.2, 1.0), law, l};
}
}  // namespace

TEST(Faults, ADivergingMotionIsANumericalFailureNotInfinity) {
  const auto model = gaining_model(10.0);
  EXPECT_THROW(tapping::simulate(model, 0.0, tapping::free_response_state(model), 5000 * model.period()),
               NumericalFailure);
}

TEST(Faults, TheOrbitSearchOfAGainingLawEndsCleanly) {
  // formerly an InvalidParameter("position", nan) escaped an OpenMP loop of the search: std::terminate
  const auto model = gaining_model(8.0);
  tapping::OrbitSearchOptions o;
  o.parallel = true;
  try {
    const auto r = tapping::find_orbits(model, o);
    for (const auto& f : r.orbits) EXPECT_TRUE(std::isfinite(f.metrics.amplitude));
  } catch (const NumericalFailure&) {
    SUCCEED();
  }
}

TEST(Faults, EveryLawBuiltFromParametersRefusesToCreateEnergyWithoutItsOptIn) {
  const auto& registry = impact::LawRegistry::builtin();
  impact::LawArguments a;
  a.values = {{"approach_stiffness", 5.0}, {"departure_stiffness", 8.0}};
  EXPECT_THROW(registry.build("hysteresis", a), InvalidParameter);
  impact::LawArguments d;
  d.values = {{"effective_modulus", 1.0}, {"departure_modulus", 5.0}};
  EXPECT_THROW(registry.build("dmt", d), InvalidParameter);
  EXPECT_THROW(registry.build("hertz", d), InvalidParameter);
  d.allow_energy_gain = true;
  EXPECT_NO_THROW(registry.build("dmt", d));
}
