#include "tapping_params.hpp"

#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::cli {

namespace {
using io::Range;
const std::vector<const char*> normalised_keys = {"natural_frequency", "drive_amplitude", "approach_stiffness",
                                       "departure_stiffness", "approach_adhesion", "departure_adhesion"};
const std::vector<const char*> physical_keys = {"spring_constant", "resonance_frequency", "free_amplitude",
                                     "sample_stiffness_approach", "sample_stiffness_departure", "adhesion_approach",
                                     "adhesion_departure", "effective_modulus", "departure_modulus", "tip_radius",
                                     "hamaker", "departure_hamaker", "intermolecular_distance"};

bool physical(const io::ParamSet& p) { return p.text("units") == "physical"; }

void reject_foreign_keys(const io::ParamSet& p) {
  const bool phys = physical(p);
  for (const char* k : phys ? normalised_keys : physical_keys) {
    if (p.was_set(k))
      throw InvalidParameter(k, fmt::format("{} applies only with units = {}; this run uses units = {}", k,
                                            phys ? "normalised" : "physical", p.text("units")));
  }
}

impact::ForceLaw law_from(const io::ParamSet& p, const tapping::PhysicalCantilever* pc) {
  const std::string& law = p.text("law");
  if (!pc) {
    const double ka = p.real("approach_stiffness"), kb = p.real("departure_stiffness");
    const double fa = p.real("approach_adhesion"), fb = p.real("departure_adhesion");
    if (law == "linear") return impact::PiecewiseLinearLaw::linear_repulsive(ka);
    if (law == "hysteresis") return impact::PiecewiseLinearLaw::linear_hysteresis(ka, kb);
    if (law == "attractive") return impact::PiecewiseLinearLaw::repulsive_attractive(ka, kb, fa, fb);
    throw InvalidParameter("law", "law = dmt needs physical units (units = physical): its parameters are in GPa, nm, J");
  }
  const double ka = pc->normalised_stiffness(p.real("sample_stiffness_approach"));
  const double kb = pc->normalised_stiffness(p.real("sample_stiffness_departure"));
  const double fa = pc->normalised_force(p.real("adhesion_approach"));
  const double fb = pc->normalised_force(p.real("adhesion_departure"));
  if (law == "linear") return impact::PiecewiseLinearLaw::linear_repulsive(ka);
  if (law == "hysteresis") return impact::PiecewiseLinearLaw::linear_hysteresis(ka, kb);
  if (law == "attractive") return impact::PiecewiseLinearLaw::repulsive_attractive(ka, kb, fa, fb);
  impact::DmtLaw dmt(p.real("effective_modulus"), p.real("departure_modulus"), p.real("tip_radius"), p.real("hamaker"),
                     p.real("departure_hamaker"), p.real("intermolecular_distance"));
  return impact::ForceLaw(dmt).scaled(1.0 / pc->spring_constant);  // nN -> nm·ω_n² per unit mass
}

tapping::PhysicalCantilever physical_cantilever(const io::ParamSet& p) {
  return {p.real("spring_constant"), p.real("resonance_frequency"), p.real("quality_factor"), p.real("free_amplitude"),
          p.real("frequency_ratio")};
}
}  // namespace

void add_tapping_model_params(io::ParamSet& p) {
  p.text("units", "normalised", "unit system of the model parameters and results", {"normalised", "physical"})
      .real("quality_factor", 100.0, "quality factor Q = 1/(2ξ)", Range::positive())
      .real("frequency_ratio", 1.0, "drive frequency over natural frequency ω/ω_n", Range::positive())
      .text("law", "hysteresis", "tip-sample force law: linear (eq. 10), hysteresis (eq. 11), attractive (eq. 26), dmt",
            {"linear", "hysteresis", "attractive", "dmt"})
      .real("separation", 10.0, "separation l (nm): sample surface at x = -l", Range::any())
      // normalised units (ω_n, lengths in nm, per-unit-mass forces in nm·ω_n²)
      .real("natural_frequency", 1.0, "[normalised] natural frequency ω_n", Range::positive())
      .real("drive_amplitude", 0.2, "[normalised] drive Γ (per unit mass)", Range::positive())
      .real("approach_stiffness", 10.0, "[normalised] K_a, sample stiffness while approaching (units of ω_n²)",
            Range::non_negative())
      .real("departure_stiffness", 8.0, "[normalised] K_b, sample stiffness while departing (units of ω_n²)",
            Range::non_negative())
      .real("approach_adhesion", 0.0, "[normalised] F_a >= 0, attraction at contact while approaching", Range::non_negative())
      .real("departure_adhesion", 0.0, "[normalised] F_b >= F_a, attraction at contact while departing",
            Range::non_negative())
      // physical units
      .real("spring_constant", 40.0, "[physical] cantilever spring constant k (N/m)", Range::positive())
      .real("resonance_frequency", 300.0, "[physical] resonance frequency f0 (kHz)", Range::positive())
      .real("free_amplitude", 20.0, "[physical] free amplitude at the drive frequency (nm)", Range::positive())
      .real("sample_stiffness_approach", 400.0, "[physical] contact stiffness while approaching (N/m)", Range::non_negative())
      .real("sample_stiffness_departure", 320.0, "[physical] contact stiffness while departing (N/m)", Range::non_negative())
      .real("adhesion_approach", 0.0, "[physical] attraction at contact while approaching (nN)", Range::non_negative())
      .real("adhesion_departure", 0.0, "[physical] attraction at contact while departing (nN)", Range::non_negative())
      .real("effective_modulus", 1.0, "[physical, dmt] effective modulus E* while approaching (GPa)", Range::positive())
      .real("departure_modulus", 1.0, "[physical, dmt] effective modulus E* while departing (GPa)", Range::positive())
      .real("tip_radius", 10.0, "[physical, dmt] tip radius R (nm)", Range::positive())
      .real("hamaker", 6.4e-20, "[physical, dmt] Hamaker constant while approaching (J)", Range::non_negative())
      .real("departure_hamaker", 6.4e-20, "[physical, dmt] Hamaker constant while departing (J)", Range::non_negative())
      .real("intermolecular_distance", 0.165, "[physical, dmt] intermolecular distance a0 (nm)", Range::positive());
}

tapping::TappingModel tapping_model_from(const io::ParamSet& p) {
  reject_foreign_keys(p);
  if (physical(p)) {
    const auto pc = physical_cantilever(p);
    return {pc.cantilever(), pc.drive(), law_from(p, &pc), p.real("separation")};
  }
  const double wn = p.real("natural_frequency");
  return {tapping::Cantilever(wn, p.real("quality_factor")), tapping::Drive(p.real("drive_amplitude"), p.real("frequency_ratio") * wn),
          law_from(p, nullptr), p.real("separation")};
}

TappingScales tapping_scales_from(const io::ParamSet& p) {
  if (!physical(p)) return {};
  return physical_cantilever(p).scales();
}

}  // namespace afmkit::cli
