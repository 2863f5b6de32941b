// The fast evaluator used for Newton tracking and argument-principle counts (src/control/spectra, private)
// against loop.hpp's characteristic function Δ(s) and its derivative, for every kind of loop.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "../../src/control/spectra/fast_characteristic.hpp"
#include "afmkit/control/loop.hpp"

using namespace afmkit::control;
using cplx = std::complex<double>;

TEST(FastCharacteristic, EqualsLoopCharacteristicAndDerivative) {
  const double w = 1.3, g = 15.0, t = 2.0 * std::numbers::pi / w;
  const std::vector<LoopSpec> loops{
      LoopSpec(OscillatorBank::single(w, 0.4, -0.2, 12.0), PlantKind::Static, g, 0.2 * t),
      LoopSpec(OscillatorBank::with_couplings(w, 7, 0.2, -0.1, 18.0, {1, 3}), PlantKind::FirstOrder, g, 0.3 * t),
      LoopSpec(OscillatorBank(w, 0.3, {0.1, -0.4, 0.2}, {0.5, 0.1, -0.3}, 9.0, {2}), PlantKind::Static, g, 0.7 * t),
      LoopSpec(InfiniteBank(w, 0.15, -0.05, 14.0), PlantKind::Static, g, 0.1 * t),
      LoopSpec(InfiniteBank(w, 0.6, 0.3, 14.0), PlantKind::FirstOrder, g, 0.25 * t),
      LoopSpec(SmithPredictor(OscillatorBank::with_couplings(w, 4, 0.1, -0.1, 15.0), PlantKind::FirstOrder, 0.8 * g,
                              0.6 * t, SmithPredictor::Structure::Periodic),
               PlantKind::FirstOrder, g, 0.5 * t),
      LoopSpec(SmithPredictor(InfiniteBank(w, 0.1, -0.1, 15.0), PlantKind::Static, 1.1 * g, 0.3 * t,
                              SmithPredictor::Structure::Classic),
               PlantKind::Static, g, 0.35 * t)};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> re(-1.5, 1.5), im(-12.0, 12.0);
  for (const auto& loop : loops) {
    const spectra_detail::FastCharacteristic f(loop);
    for (int i = 0; i < 40; ++i) {
      const cplx s(re(rng) * w, im(rng) * w);
      cplx v, d;
      f.entire(s, v, d);
      const cplx v_ref = characteristic(loop, s), d_ref = characteristic_derivative(loop, s);
      EXPECT_LT(std::abs(v - v_ref), 1e-11 * (std::abs(v_ref) + std::abs(d_ref) * w)) << loop.describe() << " " << s;
      EXPECT_LT(std::abs(d - d_ref), 1e-10 * (std::abs(d_ref) + std::abs(v_ref) / w)) << loop.describe() << " " << s;
      // Newton step of the entire function and the split X + Y e^{−iντ} on the imaginary axis
      EXPECT_LT(std::abs(f.newton_step(s) - v_ref / d_ref), 1e-9 * (std::abs(v_ref / d_ref) + 1e-3));
    }
    for (double nu : {0.37 * w, 1.71 * w, 4.2 * w}) {
      cplx x, y;
      f.crossing_parts(nu, x, y);
      cplx v, d;
      f.entire(cplx(0.0, nu), v, d);
      const cplx q = v / (x + y * std::exp(cplx(0.0, -nu * loop.delay)));  // the normaliser Q(iν), τ-independent
      const LoopSpec other = loop.with_delay(loop.delay + 0.3 * t);
      const cplx v2 = characteristic(other, cplx(0.0, nu));
      EXPECT_LT(std::abs(q * (x + y * std::exp(cplx(0.0, -nu * other.delay))) - v2), 1e-10 * std::abs(v2));
    }
  }
}

// Large banks high on the imaginary axis: the product Q = Π (1 + s²/(k²Ω²)) first grows (k < |s|/Ω) and then
// shrinks (k > |s|/Ω); it used to be rescaled only downwards and underflowed to a denormal at N = 1500,
// s = 1412.85i (every count of `control roots` above N ≈ 1400 failed "root on the boundary"). Phase and
// logarithmic derivative against the scaled evaluation of loop.hpp.
TEST(FastCharacteristic, NoUnderflowOfTheNormaliserAtLargeN) {
  const int n = 1500;
  const LoopSpec loop(OscillatorBank::with_couplings(1.0, n, 0.1, -0.1, 20.0), PlantKind::Static, 20.0,
                      0.1 * 2.0 * std::numbers::pi);
  const spectra_detail::FastCharacteristic f(loop);
  for (const cplx s : {cplx(0.0, 1412.85), cplx(-0.06, 1499.3), cplx(0.0, 1700.2), cplx(150.0, -1805.0)}) {
    cplx v, d;
    f.entire(s, v, d);
    ASSERT_TRUE(std::isnormal(std::abs(v))) << s << " " << v;
    const ScaledCharacteristic ref = characteristic_scaled(loop, s);
    EXPECT_LT(std::abs(std::arg(v / ref.value)), 1e-9) << s;
    EXPECT_LT(std::abs(d / v - ref.derivative / ref.value), 1e-9 * std::abs(ref.derivative / ref.value)) << s;
  }
}
