#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string_view>

#include "afmkit/core/error.hpp"
#include "afmkit/io/params.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

using afmkit::InputError;
using afmkit::InvalidParameter;
using afmkit::io::ParamSet;
using afmkit::io::Range;

namespace {
ParamSet make() {
  ParamSet p;
  p.real("quality_factor", 100.0, "Q", Range::positive())
      .unit("dimensionless")
      .integer("points", 10, "number of points", 1, 1000)
      .text("law", "hysteresis", "force law", {"linear", "hysteresis"})
      .flag("verbose", false, "talk")
      .reals("amplitudes", {1.0, 0.5}, "harmonic amplitudes", Range::non_negative())
      .unit("nm");
  return p;
}
}  // namespace

TEST(ParamSet, TomlValuesAreRead) {
  auto p = make();
  p.load_toml_text("quality_factor = 400\npoints = 3\nlaw = 'linear'\nverbose = true\namplitudes = [1, 2, 3]\n", "t.toml");
  EXPECT_DOUBLE_EQ(p.real("quality_factor"), 400.0);
  EXPECT_EQ(p.integer("points"), 3);
  EXPECT_EQ(p.text("law"), "linear");
  EXPECT_TRUE(p.flag("verbose"));
  EXPECT_EQ(p.reals("amplitudes").size(), 3u);
  EXPECT_TRUE(p.was_set("points"));
}

TEST(ParamSet, UnknownKeyIsRejectedWithItsName) {
  auto p = make();
  try {
    p.load_toml_text("qualty_factor = 4\n", "t.toml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("qualty_factor"), std::string::npos);
  }
}

TEST(ParamSet, MalformedTomlNamesFileAndLine) {
  auto p = make();
  try {
    p.load_toml_text("quality_factor = = 4\n", "bad.toml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.toml:1"), std::string::npos);
  }
}

TEST(ParamSet, OutOfRangeNamesParameterAndRange) {
  auto p = make();
  try {
    p.set_from_string("quality_factor", "-1");
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "quality_factor");
    EXPECT_NE(std::string(e.what()).find("> 0"), std::string::npos);
  }
  EXPECT_THROW(p.set_from_string("quality_factor", "nan"), InvalidParameter);
  EXPECT_THROW(p.set_from_string("quality_factor", "inf"), InvalidParameter);
  EXPECT_THROW(p.set_from_string("quality_factor", "12abc"), InvalidParameter);
  EXPECT_THROW(p.set_from_string("points", "0"), InvalidParameter);
  EXPECT_THROW(p.set_from_string("points", "2.5"), InvalidParameter);
  EXPECT_THROW(p.set_from_string("law", "dmt2"), InvalidParameter);
  EXPECT_THROW(p.set_from_string("amplitudes", "1,-2"), InvalidParameter);
  EXPECT_THROW(p.load_toml_text("quality_factor = 'high'\n", "t.toml"), InvalidParameter);
  EXPECT_THROW(p.load_toml_text("quality_factor = nan\n", "t.toml"), InvalidParameter);
}


// Found by fuzz_io_params: a huge float for an integer key made toml++ cast it to an integer before checking its
// range (undefined behaviour). A float with an exact integer value is accepted (as "1e7" on the command line);
// any other float, or one beyond 2^63, is "must be an integer" naming the key.
TEST(ParamSet, FloatForAnIntegerKey) {
  auto p = make();
  p.load_toml_text("points = 1e2\n", "t.toml");
  EXPECT_EQ(p.integer("points"), 100);
  for (const char* text : {"points = 7.77e113\n", "points = 3.5\n", "points = nan\n", "points = -inf\n",
                           "points = 9.3e18\n"}) {
    auto q = make();
    try {
      q.load_toml_text(text, "t.toml");
      FAIL() << text;
    } catch (const InvalidParameter& e) {
      EXPECT_NE(std::string(e.what()).find("points"), std::string::npos) << text;
      EXPECT_NE(std::string(e.what()).find("integer"), std::string::npos) << text;
    }
  }
}

TEST(ParamSet, EveryNumberCarriesItsUnitIntoHelpAndSidecar) {
  auto p = make();
  CLI::App app;
  p.add_options(app);
  const std::string help = app.help();
  EXPECT_NE(help.find("[unit: dimensionless; default 100"), std::string::npos) << help;
  EXPECT_NE(help.find("[unit: count; default 10"), std::string::npos) << help;  // integers count things
  EXPECT_NE(help.find("[unit: nm; default 1,0.5"), std::string::npos) << help;
  const nlohmann::json units = p.units_json();
  EXPECT_EQ(units["quality_factor"], "dimensionless");
  EXPECT_EQ(units["amplitudes"], "nm");
  EXPECT_FALSE(units.contains("law"));  // names and flags have no unit
  EXPECT_EQ(p.unit_of("points"), "count");
}

TEST(ParamSet, ANumberWithoutAUnitIsAProgrammingError) {
  ParamSet p;
  p.real("separation", 1.0, "separation", Range::any());
  CLI::App app;
  EXPECT_THROW(p.add_options(app), std::logic_error);
  ParamSet q;
  q.text("law", "hysteresis", "force law");
  EXPECT_THROW(q.unit("nm"), std::logic_error);  // a name has no unit
}

// ---------------------------------------------------------------- the records hold what a run used (issue 24 §2)
namespace {
ParamSet law_like() {
  ParamSet p;
  p.real("hamaker", 6.4e-20, "A_H", Range::non_negative())
      .unit("J")
      .real("departure_hamaker", 6.4e-20, "A_H departing", Range::non_negative())
      .unit("J")
      .follows("hamaker")
      .real("stiffness", 8.0, "K_b", Range::non_negative())
      .unit("N/m")
      .real("restitution", 1.0, "e, instead of stiffness", Range::positive())
      .unit("dimensionless")
      .only_if_given({"stiffness"});
  return p;
}
}  // namespace

TEST(ParamSetRecords, AFollowerNotGivenTakesAndRecordsTheFollowedValue) {
  ParamSet p = law_like();
  p.set_from_string("hamaker", "1e-19");
  EXPECT_EQ(p.real("departure_hamaker"), 1e-19);
  EXPECT_FALSE(p.was_set("departure_hamaker"));
  EXPECT_EQ(p.to_json()["departure_hamaker"].get<double>(), 1e-19);  // not the declared 6.4e-20
  EXPECT_EQ(std::get<double>(p.value("departure_hamaker")), 1e-19);
  // given, it keeps its own value
  p.set_from_string("departure_hamaker", "2e-19");
  EXPECT_EQ(p.to_json()["departure_hamaker"].get<double>(), 2e-19);
  EXPECT_EQ(p.to_json()["hamaker"].get<double>(), 1e-19);
}

TEST(ParamSetRecords, FollowsShowsTheKeyInHelpAndRefusesAnUndeclaredOrOtherKind) {
  ParamSet p = law_like();
  for (const auto& d : p.describe())
    if (d.key == "departure_hamaker") {
      EXPECT_EQ(d.default_text, "= hamaker");
    }
  ParamSet q;
  q.real("a", 1.0, "a").unit("m");
  EXPECT_THROW(q.follows("nothing"), std::logic_error);
  q.text("t", "x", "t");
  EXPECT_THROW(q.follows("a"), std::logic_error);  // a text cannot follow a number
}

TEST(ParamSetRecords, AnAlternativeIsRecordedOnlyWhenGivenAndThenReplacesItsKey) {
  ParamSet p = law_like();
  p.resolve();
  nlohmann::json j = p.to_json();
  EXPECT_FALSE(j.contains("restitution"));  // not used: a replay must not give it
  EXPECT_TRUE(j.contains("stiffness"));
  p.set_from_string("restitution", "0.5");
  j = p.to_json();
  EXPECT_EQ(j["restitution"].get<double>(), 0.5);
  EXPECT_FALSE(j.contains("stiffness"));  // the run used e, not the declared K_b
  EXPECT_FALSE(p.units_json().contains("stiffness"));
}

TEST(ParamSetRecords, OnlyTheKeysOfTheUnitSystemAndLawInUseAreRecorded) {
  ParamSet p;
  p.text("units", "normalised", "unit system", {"normalised", "physical"})
      .text("law", "hysteresis", "force law", {"hysteresis", "dmt", "hertz"})
      .real("separation", 10.0, "l")
      .unit("L")
      .group("Model in normalised units", "units", "normalised")
      .real("natural_frequency", 1.0, "ω_n", Range::positive())
      .unit("rad/t")
      .group("Model in physical units", "units", "physical")
      .real("spring_constant", 40.0, "k", Range::positive())
      .unit("N/m")
      .group("Law")
      .real("hamaker", 6.4e-20, "A_H", Range::non_negative())
      .unit("J")
      .real("tip_radius", 10.0, "R", Range::positive())
      .unit("nm");
  p.applies_when("hamaker", "law", {"dmt"}).applies_when("tip_radius", "law", {"dmt", "hertz"});
  p.resolve();
  nlohmann::json j = p.to_json();
  EXPECT_TRUE(j.contains("separation") && j.contains("natural_frequency") && j.contains("law"));
  EXPECT_FALSE(j.contains("spring_constant"));  // the other unit system
  EXPECT_FALSE(j.contains("hamaker"));          // laws the run did not use
  EXPECT_FALSE(j.contains("tip_radius"));
  EXPECT_FALSE(p.units_json().contains("hamaker"));
  p.set_from_string("units", "physical");
  p.set_from_string("law", "hertz");
  j = p.to_json();
  EXPECT_FALSE(j.contains("natural_frequency"));
  EXPECT_EQ(j["spring_constant"].get<double>(), 40.0);
  EXPECT_EQ(j["tip_radius"].get<double>(), 10.0);
  EXPECT_FALSE(j.contains("hamaker"));
  EXPECT_EQ(p.units_json()["tip_radius"], "nm");
  // still readable (a command decides whether a foreign key given is an error); a condition on an undeclared key
  // or on a number is a programming error
  EXPECT_EQ(p.real("natural_frequency"), 1.0);
  EXPECT_THROW(p.applies_when("nothing", "law", {"dmt"}), std::logic_error);
  EXPECT_THROW(p.applies_when("hamaker", "separation", {"1"}), std::logic_error);
}

TEST(ParamSetRecords, ARunsJsonSidecarLoadsAsItsParameters) {
  ParamSet p = law_like();
  p.load_toml_text(R"({"program": "afmkit", "parameters": {"hamaker": 1e-19, "stiffness": 3}, "results": {}})",
                   "run.csv.json");
  EXPECT_EQ(p.real("hamaker"), 1e-19);
  EXPECT_EQ(p.real("stiffness"), 3.0);  // an integer for a real, as in TOML
  EXPECT_TRUE(p.was_set("hamaker"));
  EXPECT_EQ(p.real("departure_hamaker"), 1e-19);  // not given: follows, as in the run
  // the record of one set, given to another, gives the same record
  ParamSet q = law_like();
  q.load_toml_text(nlohmann::json{{"parameters", p.to_json()}}.dump(2), "again.json");
  EXPECT_EQ(q.to_json(), p.to_json());
  // not a sidecar, malformed, a wrong type, an unknown key: named with the file
  EXPECT_THROW(law_like().load_toml_text(R"({"hamaker": 1})", "x.json"), InputError);
  EXPECT_THROW(law_like().load_toml_text(R"({"parameters": {"hamaker": 1e-19)", "x.json"), InputError);
  EXPECT_THROW(law_like().load_toml_text(R"({"parameters": {"hamaker": "x"}})", "x.json"), InvalidParameter);
  EXPECT_THROW(law_like().load_toml_text(R"({"parameters": {"hamaker": null}})", "x.json"), InvalidParameter);
  EXPECT_THROW(law_like().load_toml_text(R"({"parameters": {"nothing": 1}})", "x.json"), InputError);
  // an integer beyond the 64-bit range is refused, never wrapped into range
  ParamSet n;
  n.integer("seed", 1, "seed", 0, 100);
  try {
    n.load_toml_text(R"({"parameters": {"seed": 18446744073709551615}})", "x.json");
    FAIL() << "accepted";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "seed");
    EXPECT_EQ(std::string(e.what()).find("-1"), std::string::npos) << e.what();  // not read as 2^64 - 1 -> -1
  }
  EXPECT_EQ(n.integer("seed"), 1);
}

TEST(ParamSetRecords, RecordUsedReplacesTheDefaultInTheRecordWithoutCountingAsGiven) {
  ParamSet p = law_like();
  p.record_used("stiffness", 3.25);
  EXPECT_EQ(p.real("stiffness"), 3.25);
  EXPECT_FALSE(p.was_set("stiffness"));
  EXPECT_EQ(p.to_json()["stiffness"].get<double>(), 3.25);
  // a recorded value of a follower is its own
  p.record_used("departure_hamaker", 5e-20);
  p.set_from_string("hamaker", "1e-19");
  EXPECT_EQ(p.to_json()["departure_hamaker"].get<double>(), 5e-20);
  EXPECT_THROW(p.record_used("stiffness", -1.0), InvalidParameter);  // validated as a given value
  EXPECT_THROW(p.record_used("stiffness", std::string("x")), std::logic_error);
}

TEST(ParamSetRecords, AFollowedChainResolvesToTheFirstGivenValue) {
  ParamSet p;
  p.real("a", 1.0, "a").unit("m").real("b", 2.0, "b").unit("m").follows("a").real("c", 3.0, "c").unit("m").follows("b");
  p.set_from_string("a", "7");
  EXPECT_EQ(p.real("c"), 7.0);
  p.set_from_string("b", "5");
  EXPECT_EQ(p.real("c"), 5.0);
  EXPECT_EQ(p.to_json()["c"].get<double>(), 5.0);
}

TEST(ParamSetResetValues, GivesTheDeclaredValuesAgainKeepingTheDeclarations) {
  const ParamSet declared = make();
  ParamSet p = declared;
  CLI::App app;
  p.add_options(app);
  app.parse(std::vector<std::string>{"20", "--points"});  // CLI11 takes the arguments in reverse order
  p.set_config_path("missing.toml");
  p.set_value("quality_factor", 5.0);
  p.set_value("law", std::string("linear"));
  p.record_used("amplitudes", std::vector<double>{2.0});
  p.reset_values(declared);
  EXPECT_NO_THROW(p.resolve());  // neither the config file nor the flag given before
  EXPECT_EQ(p.real("quality_factor"), 100.0);
  EXPECT_EQ(p.integer("points"), 10);
  EXPECT_EQ(p.text("law"), "hysteresis");
  EXPECT_EQ(p.reals("amplitudes"), (std::vector<double>{1.0, 0.5}));
  EXPECT_FALSE(p.was_set("quality_factor"));
  EXPECT_EQ(p.to_json(), declared.to_json());
  EXPECT_EQ(p.unit_of("amplitudes"), "nm");  // declarations kept
  EXPECT_THROW(p.set_value("quality_factor", -1.0), InvalidParameter);
  ParamSet other;
  other.real("quality_factor", 1.0, "Q");
  EXPECT_THROW(p.reset_values(other), std::logic_error);
}

// resolve() checks every value without looking each up in declaration order (the Python module resolves a reset
// set per call); a set with values refused still reports the first in declaration order, not in the keys' order.
TEST(ParamSetResolve, ReportsTheFirstValueRefusedInDeclarationOrder) {
  ParamSet p;
  p.real("zeta", -1.0, "declared first, refused", Range::positive()).unit("dimensionless");
  p.real("middle", 1.0, "accepted", Range::positive()).unit("dimensionless");
  p.real("alpha", -2.0, "declared last, refused", Range::positive()).unit("dimensionless");
  try {
    p.resolve();
    FAIL() << "refused values accepted";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "zeta");
  }
  p.set_value("zeta", 1.0);
  try {
    p.resolve();
    FAIL() << "a refused value accepted";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "alpha");
  }
  p.set_value("alpha", 2.0);
  EXPECT_NO_THROW(p.resolve());
  // the record lists the keys in order, each value as used
  EXPECT_EQ(p.to_json().dump(), R"({"alpha":2.0,"middle":1.0,"zeta":1.0})");
}

// The keys are found through a hash index of positions (never pointers): a copy, a moved-to set and an assigned set
// answer from their own values, also after the original is changed or destroyed, and after more keys are declared.
TEST(ParamSetIndex, CopiesAndMovesAnswerFromTheirOwnValues) {
  auto original = std::make_unique<ParamSet>(make());
  for (int i = 0; i < 40; ++i)  // enough keys to grow the index several times
    original->real(fmt::format("extra_parameter_number_{}", i), i, "extra").unit("m");
  ParamSet copy = *original;
  ParamSet assigned;
  assigned.real("something_else", 1.0, "x").unit("m");
  assigned = *original;
  original->set_value("quality_factor", 5.0);
  original->set_value("extra_parameter_number_17", -3.0);
  original->set_value("law", std::string("linear"));
  EXPECT_EQ(copy.real("quality_factor"), 100.0);
  EXPECT_EQ(assigned.real("extra_parameter_number_17"), 17.0);
  original.reset();  // destroyed: the copies keep answering
  for (int i = 0; i < 40; ++i) {
    const std::string key = fmt::format("extra_parameter_number_{}", i);
    EXPECT_EQ(copy.real(key), i) << key;
    EXPECT_EQ(assigned.real(key), i) << key;
  }
  EXPECT_EQ(copy.text("law"), "hysteresis");
  EXPECT_THROW(assigned.real("something_else"), std::logic_error);  // the assigned set's own keys are gone
  // a key given as a view into a longer text is the key, not the text
  const std::string longer = "pointsXYZ";
  EXPECT_EQ(copy.integer(std::string_view(longer).substr(0, 6)), 10);
  EXPECT_THROW(copy.integer(std::string_view(longer).substr(0, 5)), std::logic_error);
  EXPECT_THROW(copy.real(""), std::logic_error);
  // moved: the moved-to set has the values; a key declared after the copy is the copy's only
  ParamSet moved = std::move(copy);
  moved.set_value("points", 7L);
  moved.integer("declared_later", 3, "n", 0, 9);
  EXPECT_EQ(moved.integer("points"), 7);
  EXPECT_EQ(moved.integer("declared_later"), 3);
  EXPECT_THROW(assigned.integer("declared_later"), std::logic_error);
  EXPECT_EQ(assigned.integer("points"), 10);
  // the record lists every key once, in the keys' order, whatever the declaration order
  std::vector<std::string> keys;
  const nlohmann::json record = moved.to_json();
  for (const auto& item : record.items()) keys.push_back(item.key());
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
  EXPECT_EQ(keys.size(), 5u + 40u + 1u);
}

// resolve() skips the values that passed the check since they last changed: a value refused when given stays refused
// at resolve(), and reset_values gives back the declared value bit for bit (-0.0 is not 0.0) with its own check.
TEST(ParamSetIndex, ResolveChecksEveryValueThatChangedSinceItsLastCheck) {
  ParamSet p = make();
  EXPECT_THROW(p.set_value("quality_factor", -1.0), InvalidParameter);
  EXPECT_THROW(p.resolve(), InvalidParameter);  // the refused value is still there
  ParamSet declared;
  declared.real("offset", 0.0, "o", Range::non_negative()).unit("m");
  declared.real("gain", -1.0, "declared out of range", Range::positive()).unit("m");
  ParamSet q = declared;
  q.set_value("gain", 2.0);
  q.set_value("offset", -0.0);
  EXPECT_NO_THROW(q.resolve());
  q.reset_values(declared);
  EXPECT_FALSE(std::signbit(q.real("offset")));
  EXPECT_EQ(q.to_json().dump(), R"({"gain":-1.0,"offset":0.0})");
  EXPECT_THROW(q.resolve(), InvalidParameter);  // the declared value is checked again
  q.set_value("gain", 3.0);
  EXPECT_NO_THROW(q.resolve());
  q.reset_values(declared);
  q.set_value("gain", 3.0);
  EXPECT_NO_THROW(q.resolve());
  // a flag refused is reported before a value refused that is declared before it (the flags are applied first)
  ParamSet r;
  r.real("first", -1.0, "declared first, refused", Range::positive()).unit("m");
  r.real("second", 1.0, "given as a flag, refused", Range::positive()).unit("m");
  CLI::App app;
  r.add_options(app);
  app.parse(std::vector<std::string>{"0", "--second"});  // CLI11 takes the arguments in reverse order
  try {
    r.resolve();
    FAIL() << "a refused flag accepted";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "second");
  }
}

TEST(ParamSetIndex, ResetValuesRefusesTheSameKeysDeclaredInAnotherOrder) {
  ParamSet a, b;
  a.real("x", 1.0, "x").unit("m").real("y", 2.0, "y").unit("m");
  b.real("y", 2.0, "y").unit("m").real("x", 1.0, "x").unit("m");
  EXPECT_THROW(a.reset_values(b), std::logic_error);
  ParamSet c = a;
  c.set_value("y", 5.0);
  c.reset_values(a);
  EXPECT_EQ(c.real("y"), 2.0);
}

// A key is looked up first where the same address found it last time (a literal's): another key at that address, or
// the same key in another set, is confirmed against the keys, never taken on trust.
TEST(ParamSetIndex, AKeyAtAnAddressUsedBeforeIsConfirmedNotTrusted) {
  const ParamSet p = make();
  char buffer[16] = "points";
  EXPECT_EQ(p.integer(std::string_view(buffer, 6)), 10);
  std::memcpy(buffer, "verbose", 7);
  EXPECT_FALSE(p.flag(std::string_view(buffer, 7)));
  std::memcpy(buffer, "pointz", 6);
  EXPECT_THROW(p.integer(std::string_view(buffer, 6)), std::logic_error);
  std::memcpy(buffer, "law", 3);
  EXPECT_EQ(p.text(std::string_view(buffer, 3)), "hysteresis");
  ParamSet other;  // the same literal in another set: that set's own entry
  other.text("units", "physical", "u").text("law", "dmt", "l");
  EXPECT_EQ(other.text("law"), "dmt");
  EXPECT_EQ(p.text("law"), "hysteresis");
  EXPECT_EQ(other.text("law"), "dmt");
  EXPECT_THROW(other.integer("points"), std::logic_error);
}
