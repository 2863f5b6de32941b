// The control loop as users state it (units.hpp, settings.hpp): Ω/T <-> rad/s/s conversions, the loop built from
// settings against one built directly from the constructors with hand-converted values, and validation that names
// the parameter.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <string>

#include "afmkit/control/settings.hpp"
#include "afmkit/control/units.hpp"
#include "afmkit/core/error.hpp"
#include "test_helpers.hpp"

using namespace afmkit::control;

namespace {

// Δ(s) of two loops agree at scattered points (relative, scaled by the rotation frequency).
void expect_same_loop(const LoopSpec& a, const LoopSpec& b, double omega) {
  EXPECT_DOUBLE_EQ(a.plant_rate, b.plant_rate);
  EXPECT_DOUBLE_EQ(a.delay, b.delay);
  EXPECT_DOUBLE_EQ(a.rotation_frequency(), b.rotation_frequency());
  EXPECT_DOUBLE_EQ(a.gain(), b.gain());
  for (std::complex<double> s : afmkit::control::testing::random_points(7, 12)) {
    s *= omega;
    const std::complex<double> da = characteristic(a, s), db = characteristic(b, s);
    EXPECT_LE(afmkit::control::testing::rel_err(da, db), 1e-13) << s;
  }
}

std::string parameter_of(const ControlSettings& s) {
  try {
    (void)loop_from(s);
  } catch (const afmkit::InvalidParameter& e) {
    return e.parameter();
  }
  return "";
}

}  // namespace

TEST(RotationUnits, ConvertsBothWaysAndRoundTrips) {
  for (double omega : {1.0, 314.159265, 2.0 * std::numbers::pi * 1e4, 1e-3}) {
    const RotationUnits u(omega);
    EXPECT_DOUBLE_EQ(u.rotation_frequency(), omega);
    EXPECT_DOUBLE_EQ(u.period() * omega, 2.0 * std::numbers::pi);
    EXPECT_DOUBLE_EQ(u.rate(20.0), 20.0 * omega);     // γ = 20 Ω
    EXPECT_DOUBLE_EQ(u.delay(0.25), 0.25 * 2.0 * std::numbers::pi / omega);  // τ = T/4
    for (double x : {-3.5, 0.0, 0.1, 0.294, 17.0}) {
      EXPECT_NEAR(u.in_omega(u.rate(x)), x, 1e-15 * (1.0 + std::abs(x)));
      EXPECT_NEAR(u.in_periods(u.delay(x)), x, 1e-15 * (1.0 + std::abs(x)));
    }
    const std::complex<double> s(-0.2 * omega, 3.0 * omega);
    EXPECT_NEAR(std::abs(u.in_omega(s) - std::complex<double>(-0.2, 3.0)), 0.0, 1e-15);
  }
}

TEST(RotationUnits, RejectsANonPositiveOrNonFiniteFrequencyNamingIt) {
  for (double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    try {
      RotationUnits u(bad);
      ADD_FAILURE() << bad;
    } catch (const afmkit::InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), "rotation_frequency");
      EXPECT_NE(std::string(e.what()).find("rotation_frequency"), std::string::npos);
    }
  }
}

TEST(ControlSettings, BankLoopEqualsTheLoopBuiltDirectly) {
  ControlSettings s;
  s.rotation_frequency = 314.159265;
  s.harmonics = 7;
  s.alpha = 0.12;
  s.beta = -0.08;
  s.rejected = {1, 3};
  s.gain = 15.0;
  s.plant = PlantKind::FirstOrder;
  s.plant_rate = 18.0;
  s.delay = 0.2;
  const double w = s.rotation_frequency, T = 2.0 * std::numbers::pi / w;
  const LoopSpec direct(OscillatorBank::with_couplings(w, 7, 0.12 * w, -0.08 * w, 15.0 * w, {1, 3}),
                        PlantKind::FirstOrder, 18.0 * w, 0.2 * T);
  expect_same_loop(loop_from(s), direct, w);
}

TEST(ControlSettings, DefaultsFollowThePlantAndTheDelay) {
  ControlSettings s;  // gain, model_rate, model_delay not given
  s.plant_rate = 12.0;
  s.delay = 0.3;
  EXPECT_EQ(s.gain_value(), 12.0);
  EXPECT_EQ(s.model_rate_value(), 12.0);
  EXPECT_EQ(s.model_delay_value(), 0.3);
  EXPECT_EQ(s.model_plant_value(), s.plant);
  const ControlSettingsSi si = to_si(s);
  EXPECT_DOUBLE_EQ(si.gain, 12.0);
  EXPECT_DOUBLE_EQ(si.delay, 0.3 * 2.0 * std::numbers::pi);
  EXPECT_DOUBLE_EQ(si.model_delay, si.delay);
}

TEST(ControlSettings, SingleInfiniteAndSmithLoopsEqualTheLoopsBuiltDirectly) {
  const double w = 50.0, T = 2.0 * std::numbers::pi / w;
  ControlSettings s;
  s.rotation_frequency = w;
  s.delay = 0.15;

  s.controller = ControllerKind::Single;
  s.a = 0.4;
  s.b = 0.1;
  s.gain = 3.0;
  s.plant_rate = 5.0;
  expect_same_loop(loop_from(s), LoopSpec(OscillatorBank::single(w, 0.4 * w, 0.1 * w, 3.0 * w), PlantKind::Static,
                                          5.0 * w, 0.15 * T), w);

  s.controller = ControllerKind::Infinite;
  s.gain.reset();
  expect_same_loop(loop_from(s), LoopSpec(InfiniteBank(w, 0.1 * w, -0.1 * w, 5.0 * w), PlantKind::Static, 5.0 * w,
                                          0.15 * T), w);

  s.controller = ControllerKind::Smith;
  s.smith_bank = ControllerKind::Bank;
  s.harmonics = 4;
  s.model_plant = PlantKind::FirstOrder;
  s.model_rate = 6.0;
  s.model_delay = 0.1;
  s.smith_structure = SmithPredictor::Structure::Classic;
  const SmithPredictor sp(OscillatorBank::with_couplings(w, 4, 0.1 * w, -0.1 * w, 5.0 * w), PlantKind::FirstOrder,
                          6.0 * w, 0.1 * T, SmithPredictor::Structure::Classic);
  expect_same_loop(loop_from(s), LoopSpec(sp, PlantKind::Static, 5.0 * w, 0.15 * T), w);
  const Controller controller = controller_from(s);
  const auto& built = std::get<SmithPredictor>(controller);
  EXPECT_DOUBLE_EQ(built.model_delay, 0.1 * T);
  EXPECT_DOUBLE_EQ(built.model_rate, 6.0 * w);
}

TEST(ControlSettings, ValidationNamesTheParameter) {
  const auto with = [](auto change) {
    ControlSettings s;
    change(s);
    return s;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.rotation_frequency = 0.0; })), "rotation_frequency");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.harmonics = 0; })), "harmonics");
  EXPECT_EQ(parameter_of(with([&](ControlSettings& s) { s.alpha = nan; })), "alpha");
  // finite in units of Ω but not in rad/s
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) {
              s.rotation_frequency = 1e3;
              s.beta = 1e307;
            })),
            "beta");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.gain = -1.0; })), "gain");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.plant_rate = 0.0; })), "plant_rate");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.delay = -0.1; })), "delay");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) {
              s.rotation_frequency = 1e-3;
              s.delay = 1e306;  // ×T = 6e309 s
            })),
            "delay");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.model_delay = -1.0; })), "model_delay");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.model_rate = 0.0; })), "model_rate");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.rejected = {1, 11}; })), "rejected");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.rejected = {2, 2}; })), "rejected");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) { s.rejected = {}; })), "rejected");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) {
              s.controller = ControllerKind::Infinite;
              s.rejected = {2};
            })),
            "rejected");
  EXPECT_EQ(parameter_of(with([](ControlSettings& s) {
              s.controller = ControllerKind::Smith;
              s.smith_bank = ControllerKind::Smith;
            })),
            "smith_bank");
  EXPECT_EQ(parameter_of(ControlSettings{}), "");
  // the message gives the allowed range
  try {
    (void)loop_from(with([](ControlSettings& s) { s.rejected = {5}; s.harmonics = 3; }));
    ADD_FAILURE();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_NE(std::string(e.what()).find("rejected = 5 is out of range: must be an integer in [1, 3]"),
              std::string::npos) << e.what();
  }
}

TEST(ControlSettings, NamesRoundTrip) {
  for (ControllerKind k : {ControllerKind::Single, ControllerKind::Bank, ControllerKind::Infinite, ControllerKind::Smith})
    EXPECT_EQ(controller_kind_from(to_string(k)), k);
  for (PlantKind k : {PlantKind::Static, PlantKind::FirstOrder}) EXPECT_EQ(plant_kind_from(to_string(k)), k);
  try {
    (void)controller_kind_from("pid", "smith_bank");
    ADD_FAILURE();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "smith_bank");
  }
}

TEST(DescribeInRotationUnits, StatesEveryValueInOmegaAndT) {
  ControlSettings s;
  s.rotation_frequency = 314.159265;
  s.delay = 0.25;
  const std::string text = describe_in_rotation_units(loop_from(s));
  for (const char* part : {"bank N=10", "alpha=0.1 Omega", "beta=-0.1 Omega", "K=20 Omega", "gamma=20 Omega",
                           "tau=0.25 T", "Omega = 314.159 rad/s"})
    EXPECT_NE(text.find(part), std::string::npos) << part << " not in: " << text;
  s.controller = ControllerKind::Smith;
  s.model_delay = 0.2;
  const std::string smith = describe_in_rotation_units(loop_from(s));
  EXPECT_NE(smith.find("tau_hat=0.2 T"), std::string::npos) << smith;
  // a bank with general couplings (not eq. 20) is described by its own couplings
  const double w = 2.0;
  const LoopSpec general(OscillatorBank(w, 0.2, {0.6, 0.3}, {0.4, 0.8}, 4.0), PlantKind::Static, 4.0, 0.0);
  const std::string g = describe_in_rotation_units(general);
  EXPECT_NE(g.find("a0=0.1 Omega a1=0.3 Omega b1=0.2 Omega"), std::string::npos) << g;
}
