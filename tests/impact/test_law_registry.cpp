// LawRegistry: the one place a law is built from named parameters.
#include <gtest/gtest.h>

#include <cmath>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"

using namespace afmkit;
using namespace afmkit::impact;

namespace {
LawArguments args(std::map<std::string, double> v) {
  LawArguments a;
  a.values = std::move(v);
  return a;
}
std::string parameter_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InvalidParameter& e) {
    return e.parameter() + ": " + e.what();
  }
  return "no error";
}
// an exponential repulsion, as a user would add it
class ExponentialLaw final : public ForceLawModel {
 public:
  ExponentialLaw(double f0, double length) : f0_(f0), length_(length) {}
  std::string name() const override { return "exponential"; }
  double approach(double d) const override { return f0_ * std::exp(-d / length_); }
  double departure(double d) const override { return approach(d); }
  std::vector<double> switching_gaps() const override { return {}; }
  bool branch_dependent(int) const override { return false; }

 private:
  double f0_, length_;
};
}  // namespace

TEST(LawRegistry, BuiltinLawsAreAllBuildableWithDefaults) {
  const auto r = LawRegistry::builtin();
  for (const auto& name : r.names()) {
    if (r.find(name).needs_force_curve || r.find(name).needs_object) continue;
    SCOPED_TRACE(name);
    const ForceLaw law = r.build(name, {});
    // a piecewise-linear law is named by what it is (attractive with F_a = F_b = 0 is the hysteresis law (11))
    if (!r.find(name).piecewise_linear) {
      EXPECT_EQ(law.name(), name);
    }
    EXPECT_NO_THROW(law.require_dissipative());
    EXPECT_TRUE(std::isfinite(law.approach(-0.5)));
  }
  for (const char* n : {"linear", "hysteresis", "attractive", "hertz", "dmt", "jkr", "lennard_jones", "kelvin_voigt",
                        "table"})
    EXPECT_NO_THROW(r.find(n));
}

TEST(LawRegistry, ValuesReachTheLawAndDepartureKeysFollowTheirApproachKeys) {
  const auto r = LawRegistry::builtin();
  // one modulus given: no hysteresis at all (the departure modulus follows it), in every command
  const ForceLaw dmt = r.build("dmt", args({{"effective_modulus", 50.0}}));
  const DmtLaw reference(50.0, 50.0, 10.0, 6.4e-20, 6.4e-20, 0.165);
  for (double d : {-1.0, 0.0, 0.5}) {
    EXPECT_DOUBLE_EQ(dmt.approach(d), reference.approach(d));
    EXPECT_DOUBLE_EQ(dmt.departure(d), reference.approach(d));
  }
  EXPECT_EQ(dmt.hysteresis_area(-1.0, 1.0), 0.0);
  const ForceLaw h = r.build("hysteresis", args({{"approach_stiffness", 9.0}, {"restitution", 0.5}}));
  ASSERT_NE(h.piecewise_linear(), nullptr);
  EXPECT_DOUBLE_EQ(h.piecewise_linear()->departure_stiffness, 9.0 * 0.25);
}

TEST(LawRegistry, ErrorsNameTheParameterAndWhatIsAllowed) {
  const auto r = LawRegistry::builtin();
  EXPECT_EQ(parameter_of([&] { r.find("magnetic"); }).substr(0, 5), "law: ");
  EXPECT_NE(parameter_of([&] { r.find("magnetic"); }).find("known laws: linear, hysteresis"), std::string::npos);
  const std::string foreign = parameter_of([&] { r.build("hertz", args({{"hamaker", 1e-19}})); });
  EXPECT_EQ(foreign.substr(0, 9), "hamaker: ");
  EXPECT_NE(foreign.find("does not apply to law = hertz (it is a parameter of law dmt, jkr"), std::string::npos);
  const std::string range = parameter_of([&] { r.build("dmt", args({{"tip_radius", -1.0}})); });
  EXPECT_NE(range.find("tip_radius = -1 is out of range: must be > 0 nm"), std::string::npos);
  EXPECT_EQ(parameter_of([&] { r.build("dmt", args({{"tip_radius", NAN}})); }).substr(0, 12), "tip_radius: ");
  EXPECT_EQ(parameter_of([&] { r.build("table", {}); }).substr(0, 13), "force_curve: ");
  EXPECT_EQ(parameter_of([&] {
              r.build("hysteresis", args({{"restitution", 0.5}, {"departure_stiffness", 3.0}}));
            }).substr(0, 13),
            "restitution: ");
  EXPECT_EQ(parameter_of([&] { r.build("nonsense_key_law", {}); }).substr(0, 5), "law: ");
  EXPECT_EQ(parameter_of([&] { r.build("dmt", args({{"no_such_key", 1.0}})); }).substr(0, 13), "no_such_key: ");
}

TEST(LawRegistry, AUserLawIsOneClassAndOneRegistrationLine) {
  auto r = LawRegistry::builtin();
  r.add({"exponential", "exponential repulsion", {"repulsion_force", "decay_length"}, false, false,
         [](const auto& value, const auto&) {
           return make_law<ExponentialLaw>(value("repulsion_force"), value("decay_length"));
         }},
        {{"repulsion_force", "nN", 5.0, "F0", 0.0, INFINITY, true, "", false, ""},
         {"decay_length", "nm", 0.5, "λ", 0.0, INFINITY, true, "", false, ""}});
  const ForceLaw law = r.build("exponential", args({{"decay_length", 2.0}}));
  EXPECT_DOUBLE_EQ(law.approach(1.0), 5.0 * std::exp(-0.5));
  EXPECT_EQ(r.laws_using("tip_radius").size(), 5u);
  EXPECT_THROW(r.build("exponential", args({{"decay_length", 0.0}})), InvalidParameter);
  // a duplicate name, a key redeclared with another unit, or an undeclared key are refused
  EXPECT_THROW(r.add({"dmt", "again", {}, false, false, [](const auto&, const auto&) { return ForceLaw(DmtLaw(1, 1, 1, 0, 0, 1)); }}),
               InvalidParameter);
  EXPECT_THROW(r.add({"other", "x", {"tip_radius"}, false, false,
                      [](const auto&, const auto&) { return ForceLaw(DmtLaw(1, 1, 1, 0, 0, 1)); }},
                     {{"tip_radius", "m", 10.0, "R", 0.0, INFINITY, true, "", false, ""}}),
               InvalidParameter);
  EXPECT_THROW(r.add({"third", "x", {"undeclared"}, false, false,
                      [](const auto&, const auto&) { return ForceLaw(DmtLaw(1, 1, 1, 0, 0, 1)); }}),
               InvalidParameter);
}
