#include "tapping_params.hpp"

#include <algorithm>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "cantilever_params.hpp"
#include "law_params.hpp"

namespace afmkit::cli {

namespace {
using io::Range;
const std::vector<const char*> normalised_keys = {"natural_frequency", "drive_amplitude", "approach_stiffness",
                                       "departure_stiffness", "approach_adhesion", "departure_adhesion"};
const std::vector<const char*> physical_cantilever_keys = {"spring_constant", "resonance_frequency", "free_amplitude",
                                                           "sample_stiffness_approach", "sample_stiffness_departure",
                                                           "adhesion_approach", "adhesion_departure"};

/// The built-in laws (fixed: built once, not per run).
const impact::LawRegistry& builtin_laws() {
  static const impact::LawRegistry registry = impact::LawRegistry::builtin();
  return registry;
}

/// A key of one unit system only, and its index among the registry's keys (-1: none), whose LawChoice::given says
/// whether it was given (read once per run).
struct ForeignKey {
  std::string key;
  int law_key = -1;
};
std::vector<ForeignKey> foreign_keys(const std::vector<std::string>& keys) {
  const auto& law_keys = builtin_laws().keys();
  std::vector<ForeignKey> out;
  for (const std::string& k : keys) {
    const auto it = std::find_if(law_keys.begin(), law_keys.end(), [&](const impact::LawKey& l) { return l.key == k; });
    out.push_back({k, it == law_keys.end() ? -1 : static_cast<int>(it - law_keys.begin())});
  }
  return out;
}

/// Keys that exist only in physical units: the cantilever's and those of the laws that need physical units.
std::vector<std::string> physical_keys() {
  const impact::LawRegistry& registry = builtin_laws();
  std::vector<std::string> keys(physical_cantilever_keys.begin(), physical_cantilever_keys.end());
  for (const auto& k : registry.keys()) {
    bool piecewise = false;
    for (const auto& law : registry.laws_using(k.key)) piecewise = piecewise || registry.find(law).piecewise_linear;
    if (!piecewise) keys.push_back(k.key);
  }
  keys.push_back("force_curve");
  return keys;
}

/// The keys a run in physical (`physical_run`) or normalised units must not be given, worked out once (the built-in
/// laws are fixed): every run checks them.
const std::vector<ForeignKey>& foreign_keys_once(bool physical_run) {
  static const std::vector<ForeignKey> in_physical =
      foreign_keys(std::vector<std::string>(normalised_keys.begin(), normalised_keys.end()));
  static const std::vector<ForeignKey> in_normalised = foreign_keys(physical_keys());
  return physical_run ? in_physical : in_normalised;
}

bool physical(const io::ParamSet& p) { return p.text("units") == "physical"; }

void reject_foreign_keys(const io::ParamSet& p, bool phys, const LawChoice& law) {
  for (const ForeignKey& k : foreign_keys_once(phys)) {
    if (k.law_key >= 0 ? law.given[static_cast<std::size_t>(k.law_key)] != 0 : p.was_set(k.key))
      throw InvalidParameter(k.key, fmt::format("{} applies only with units = {}; this run uses units = {}", k.key,
                                                phys ? "normalised" : "physical", p.text("units")));
  }
}

// The tapping command's own keys for the piecewise-linear laws in physical units (N/m, nN); the registry keys
// of the same laws (approach_stiffness, …) are the normalised ones here (units of ω_n², nm·ω_n²).
const LawKeyAliases physical_aliases = {{"sample_stiffness_approach", "approach_stiffness"},
                                        {"sample_stiffness_departure", "departure_stiffness"},
                                        {"adhesion_approach", "approach_adhesion"},
                                        {"adhesion_departure", "departure_adhesion"}};

impact::ForceLaw law_from(const io::ParamSet& p, const LawChoice& law, const tapping::PhysicalCantilever* pc,
                          const std::shared_ptr<const impact::ForceLawModel>& object) {
  const impact::LawRegistry& registry = builtin_laws();
  // law = python without its object (the command line): say so first, whatever the units
  if (law.spec.needs_object && !object) return law_from_params(p, registry, law, {}, object);
  if (!pc) {
    if (!law.spec.piecewise_linear)
      throw InvalidParameter("law", fmt::format("law = {} needs physical units (units = physical): its parameters are "
                                                "in GPa, nm, J (docs/force-laws.md)",
                                                law.spec.name));
    return law_from_params(p, registry, law, {}, object);
  }
  // physical law (nm, nN, nm/s) -> per unit mass (nm·ω_n²) in normalised time (1/ω_n)
  return pc->normalised_law(law_from_params(p, registry, law, physical_aliases, object));
}

tapping::PhysicalCantilever physical_cantilever(const io::ParamSet& p) {
  return {p.real("spring_constant"), p.real("resonance_frequency"), p.real("quality_factor"), p.real("free_amplitude"),
          p.real("frequency_ratio")};
}
}  // namespace

namespace {
// Wide but finite upper bounds: products of the model's scales stay far inside the double range (no inf/nan
// results from extreme inputs; issue of ±1e308 parameters). Real cantilevers lie decades inside them.
Range below(double hi) { return {0.0, hi, true, false}; }
}  // namespace

void add_separation_list_params(io::ParamSet& p, const std::string& help) {
  p.reals("separations", {}, help, Range::closed(-1e6, 1e6))
      .unit(kLengthUnit)
      .default_text("none: points on [separation_min, separation_max]")
      .only_if_given(uniform_grid_keys())  // the record of a run gives the list or the grid it used
      .file("separations_file", "",
            "file with the separations instead (numbers separated by commas, spaces or lines; # comments)")
      .only_if_given(uniform_grid_keys());
}

void add_separation_range_params(io::ParamSet& p, double min_default, double max_default,
                                 const SeparationRangeForm& form) {
  p.real("separation_min", min_default, form.min_help, form.range).unit(kLengthUnit);
  if (!form.min_default_text.empty()) p.default_text(form.min_default_text);
  p.real("separation_max", max_default, form.max_help, form.range).unit(kLengthUnit);
  if (!form.max_default_text.empty()) p.default_text(form.max_default_text);
}

void add_separation_points_param(io::ParamSet& p, long points_default, long min_points, long max_points,
                                 const std::string& help) {
  p.integer("points", points_default, help, min_points, max_points);
}

void add_tapping_model_params(io::ParamSet& p) {
  p.group("Model");
  p.text("units", "normalised", "unit system of the model parameters and results", {"normalised", "physical"});
  add_cantilever_param(p, CantileverKey::quality_factor, CantileverDefault::of(100.0), "quality factor Q = 1/(2ξ)");
  p.real("frequency_ratio", 1.0, "drive frequency over natural frequency ω/ω_n", below(1e3))
      .unit("dimensionless")
      .real("separation", 10.0, "separation l: sample surface at x = -l", Range::closed(-1e6, 1e6))
      .unit(kLengthUnit)
      // normalised units (ω_n, lengths in nm, per-unit-mass forces in nm·ω_n²)
      .group("Model in normalised units (--units normalised; --units physical --help lists the physical keys)",
             "units", "normalised")
      .real("natural_frequency", 1.0, "[normalised] natural frequency ω_n", below(1e12))
      .unit("rad/t")
      .real("drive_amplitude", 0.2, "[normalised] drive Γ (per unit mass)", below(1e12))
      .unit("L/t^2");
  // the hysteresis law's keys per unit mass (the registry's keys, in normalised units: add_law_params skips them)
  const impact::LawRegistry& registry = builtin_laws();
  const auto per_unit_mass = [&](const char* key, const char* unit, const char* help) {
    add_law_key_param(p, registry, key,
                      {.help = help, .default_value = {}, .range = Range::closed(0.0, 1e12), .unit = unit});
  };
  per_unit_mass("approach_stiffness", "1/t^2", "[normalised] K_a, sample stiffness while approaching (per unit mass)");
  per_unit_mass("departure_stiffness", "1/t^2", "[normalised] K_b, sample stiffness while departing (per unit mass)");
  per_unit_mass("approach_adhesion", "L/t^2",
                "[normalised] F_a >= 0, attraction at contact while approaching (per unit mass)");
  per_unit_mass("departure_adhesion", "L/t^2",
                "[normalised] F_b >= F_a, attraction at contact while departing (per unit mass)");
  // physical units
  p.group("Model in physical units (--units physical)", "units", "physical");
  add_cantilever_param(p, CantileverKey::spring_constant, CantileverDefault::of(40.0),
                       "[physical] cantilever spring constant k");
  add_cantilever_param(p, CantileverKey::resonance_frequency, CantileverDefault::of(300.0),
                       "[physical] resonance frequency f0");
  add_cantilever_param(p, CantileverKey::free_amplitude, CantileverDefault::of(20.0),
                       "[physical] free amplitude at the drive frequency");
  p.real("sample_stiffness_approach", 400.0, "[physical] contact stiffness while approaching", Range::closed(0.0, 1e9))
      .unit("N/m")
      .real("sample_stiffness_departure", 320.0, "[physical] contact stiffness while departing", Range::closed(0.0, 1e9))
      .unit("N/m")
      .real("adhesion_approach", 0.0, "[physical] attraction at contact while approaching", Range::closed(0.0, 1e9))
      .unit("nN")
      .real("adhesion_departure", 0.0, "[physical] attraction at contact while departing", Range::closed(0.0, 1e9))
      .unit("nN")
      ;
  add_law_params(p, registry, "hysteresis",
                 {"approach_stiffness", "departure_stiffness", "approach_adhesion", "departure_adhesion"},
                 physical_aliases);
}

tapping::TappingModel tapping_model_from(const io::ParamSet& p, std::shared_ptr<const impact::ForceLawModel> law_object) {
  const LawChoice law(p, builtin_laws());  // the law and the law keys given, read once
  const bool phys = physical(p);
  reject_foreign_keys(p, phys, law);
  if (phys) {
    const auto pc = physical_cantilever(p);
    return {pc.cantilever(), pc.drive(), law_from(p, law, &pc, law_object), p.real("separation")};
  }
  const double wn = p.real("natural_frequency");
  return {tapping::Cantilever(wn, p.real("quality_factor")), tapping::Drive(p.real("drive_amplitude"), p.real("frequency_ratio") * wn),
          law_from(p, law, nullptr, law_object), p.real("separation")};
}

TappingScales tapping_scales_from(const io::ParamSet& p) {
  if (!physical(p)) return {};
  return physical_cantilever(p).scales();
}

}  // namespace afmkit::cli
