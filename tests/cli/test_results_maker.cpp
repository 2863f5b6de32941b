// A command that makes its summary where it is read (CommandOutput::finish(ResultsMaker)): a capture that takes the
// maker (the Python module: r.results made on first access) gets it unmade, and the document it makes is the one
// every other front end gets at once (a capture without the hook, the sidecar): issue 26, "the command layer adds
// <= 5 % to a 1 ms command" (bench/command_layer.py), without changing any output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "orbit_as_python.hpp"

namespace {

/// The document without the search's wall time (the one value two runs do not share).
nlohmann::json results_maker_timeless(nlohmann::json j) {
  j.at("search").at("seconds") = 0.0;
  return j;
}

TEST(ResultsMaker, TappingOrbitHandsItsSummaryUnmadeAndMakesTheDocumentOthersGet) {
  const afmkit::io::ParamSet p = afmkit_test::orbit_params_as_python("");
  // a capture that takes a maker: handed over, not made; the document not given to take_results either
  afmkit::cli::Captured lazy;
  afmkit::cli::ResultsMaker maker;
  int handed = 0, eager = 0;
  lazy.take_results_maker = [&](afmkit::cli::ResultsMaker m) {
    ++handed;
    maker = std::move(m);
  };
  lazy.take_results = [&](const nlohmann::json&) { ++eager; };
  afmkit_test::orbit_command_spec().run(p, &lazy);
  ASSERT_EQ(handed, 1);
  EXPECT_EQ(eager, 0);
  ASSERT_TRUE(maker);
  EXPECT_EQ(lazy.results, nlohmann::json::object());  // nothing made at run time
  EXPECT_EQ(lazy.rows.size(), 1u);                     // the table as before
  EXPECT_FALSE(lazy.parameters.is_null());             // and the parameters as run
  const nlohmann::json made = maker();
  EXPECT_EQ(made, maker());  // the same document each time it is made
  // the search report lists every seed, with its units
  EXPECT_EQ(made.at("search").at("seeds").size(), made.at("search").at("seeds_total").get<std::size_t>());
  EXPECT_GT(made.at("search").at("seeds").size(), 10u);
  EXPECT_EQ(made.at("units").at("search").at("seeds").at("initial_position"), "L");
  EXPECT_EQ(made.at("status"), "ok");

  // a capture without the hook (the study batch): the document at once, the same one
  afmkit::cli::Captured at_once;
  afmkit_test::orbit_command_spec().run(p, &at_once);
  EXPECT_EQ(results_maker_timeless(made), results_maker_timeless(at_once.results));
  EXPECT_EQ(lazy.parameters, at_once.parameters);
}

TEST(ResultsMaker, AFileWrittenRecordsTheDocumentInItsSidecarAndTheCaptureGetsItAtOnce) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "afmkit_test_results_maker";
  std::filesystem::create_directories(dir);
  const std::string csv = (dir / "orbit.csv").string();
  const afmkit::io::ParamSet p = afmkit_test::orbit_params_as_python(csv);
  afmkit::cli::Captured c;
  int handed = 0;
  nlohmann::json taken;
  c.take_results_maker = [&](afmkit::cli::ResultsMaker) { ++handed; };
  c.take_results = [&](const nlohmann::json& j) { taken = j; };
  afmkit_test::orbit_command_spec().run(p, &c);
  EXPECT_EQ(handed, 0);  // made for the sidecar: handed over made
  std::ifstream in(csv + ".json");
  const nlohmann::json sidecar = nlohmann::json::parse(in);
  EXPECT_EQ(sidecar.at("results"), taken);
  EXPECT_GT(taken.at("search").at("seeds").size(), 10u);
  std::filesystem::remove_all(dir);
}

}  // namespace
