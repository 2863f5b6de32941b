// libFuzzer target: the parameter reader. Input = a TOML configuration file (what --config reads), or, when it
// starts with "--", one flag value per line ("--key value"), as the command line gives them. Invariant: every
// input is either accepted with every value inside its declared range, or rejected with afmkit::InputError /
// afmkit::InvalidParameter; nothing else (no crash, no other exception, no sanitizer report).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/io/params.hpp"

namespace {

afmkit::io::ParamSet make_params() {
  using afmkit::io::Range;
  afmkit::io::ParamSet p;
  p.real("quality_factor", 100.0, "Q", Range::positive())
      .real("frequency_ratio", 1.0, "omega", Range{0.0, 10.0, true, false})
      .real("separation", 10.0, "l", Range::any())
      .integer("points", 10, "n", 2, 1000000)
      .integer("harmonics", 10, "N", 1, 1000)
      .text("law", "linear", "force law", {"linear", "hysteresis", "attractive", "dmt"})
      .text("output", "out/x.csv", "path")
      .flag("json", false, "json")
      .reals("amplitudes", {1.0, 0.5}, "list", Range::non_negative());
  return p;
}

void check_invariants(const afmkit::io::ParamSet& p) {
  const double q = p.real("quality_factor"), w = p.real("frequency_ratio"), l = p.real("separation");
  if (!(q > 0 && std::isfinite(q)) || !(w > 0 && w <= 10) || !std::isfinite(l)) std::abort();
  if (p.integer("points") < 2 || p.integer("points") > 1000000) std::abort();
  if (p.integer("harmonics") < 1 || p.integer("harmonics") > 1000) std::abort();
  const std::string& law = p.text("law");
  if (law != "linear" && law != "hysteresis" && law != "attractive" && law != "dmt") std::abort();
  for (double a : p.reals("amplitudes"))
    if (!(a >= 0 && std::isfinite(a))) std::abort();
  (void)p.to_json().dump();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  afmkit::io::ParamSet p = make_params();
  try {
    if (text.rfind("--", 0) == 0) {
      std::istringstream lines(text);
      for (std::string line; std::getline(lines, line);) {
        if (line.rfind("--", 0) != 0) continue;
        const std::size_t space = line.find(' ');
        std::string key = line.substr(2, space == std::string::npos ? std::string::npos : space - 2);
        for (char& c : key)
          if (c == '-') c = '_';
        p.set_from_string(key, space == std::string::npos ? "" : line.substr(space + 1));
      }
    } else {
      p.load_toml_text(text, "fuzz.toml");
    }
    p.resolve();
  } catch (const afmkit::InvalidParameter&) {
    return 0;
  } catch (const afmkit::InputError&) {
    return 0;
  }
  check_invariants(p);
  return 0;
}
