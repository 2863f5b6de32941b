// A user-defined force law in one file, registered with one line, then used in an impact and in a tapping orbit.
//
// The law: Hertz repulsion in contact plus a capillary water neck that forms at contact and holds the tip while it
// retracts, until the neck breaks at the rupture distance (a classic source of dissipation in tapping mode under
// ambient humidity). Units as for the built-in contact laws: gap d in nm, force in nN (H > 0 repulsive),
// E* in GPa, R in nm, surface tension γ in J/m² (γ·R in J/m = nN).
//   approach  (ḋ < 0): H_a(d) = (4/3) E* √R (−d)^{3/2} for d < 0, 0 otherwise (no neck before the first contact)
//   departure (ḋ > 0): H_b(d) = H_a(d) − F_cap for d < d_rupture, 0 beyond,  F_cap = 4π γ R cos θ
// Energy taken per touch: ∫ (H_a − H_b) dd = F_cap · (d_rupture − d_min) (closed form below).
// (The branch model is memoryless, seed-1 eq. 4: a tip retracting inside d_rupture feels the neck whether or not it
// touched the sample this time; in an impact or a tapping orbit it always has.)
//
// Build against the installed library: examples/README.md.
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <afmkit/core/error.hpp>
#include <afmkit/core/validate.hpp>
#include <afmkit/core/version.hpp>
#include <afmkit/impact/impact.hpp>
#include <afmkit/impact/law_registry.hpp>
#include <afmkit/impact/laws/contact_laws.hpp>
#include <afmkit/tapping/orbit.hpp>
#include <afmkit/tapping/units.hpp>

namespace {

using afmkit::impact::ForceLawModel;

class CapillaryLaw final : public ForceLawModel {
 public:
  CapillaryLaw(double effective_modulus, double tip_radius, double surface_tension, double contact_angle_deg,
               double rupture_distance)
      : stiffness_(4.0 / 3.0 * afmkit::validate::positive("effective_modulus", effective_modulus) *
                   std::sqrt(afmkit::validate::positive("tip_radius", tip_radius))),
        capillary_force_(4.0 * std::numbers::pi * afmkit::validate::non_negative("surface_tension", surface_tension) *
                         tip_radius *
                         std::cos(afmkit::validate::in_range("contact_angle", contact_angle_deg, 0.0, 90.0) *
                                  std::numbers::pi / 180.0)),
        rupture_(afmkit::validate::positive("rupture_distance", rupture_distance)) {}

  std::string name() const override { return "capillary"; }
  double approach(double d) const override { return d < 0 ? stiffness_ * (-d) * std::sqrt(-d) : 0.0; }
  double departure(double d) const override { return d < rupture_ ? approach(d) - capillary_force_ : 0.0; }
  std::vector<double> switching_gaps() const override { return {0.0, rupture_}; }  // contact edge, neck rupture
  bool branch_dependent(int region) const override { return region <= 1; }        // below the rupture distance
  double hysteresis_area(double lo, double hi) const override {
    return capillary_force_ * std::fmax(0.0, std::fmin(hi, rupture_) - lo);
  }
  double capillary_force() const { return capillary_force_; }

 private:
  double stiffness_;        // (4/3) E* √R [nN/nm^{3/2}]
  double capillary_force_;  // F_cap [nN]
  double rupture_;          // d_rupture [nm]
};

int run() {
  using namespace afmkit;
  using V = std::function<double(const std::string&)>;

  // ---- the one registration line (new keys declared with unit, default, help and allowed range) ----------------
  auto registry = impact::LawRegistry::builtin();
  registry.add({.name = "capillary",
                .summary = "Hertz contact + capillary neck on retract, F_cap = 4 pi gamma R cos(theta)",
                .keys = {"effective_modulus", "tip_radius", "surface_tension", "contact_angle", "rupture_distance"},
                .build = [](const V& v, const impact::LawArguments&) {
                  return impact::make_law<CapillaryLaw>(v("effective_modulus"), v("tip_radius"),
                                                        v("surface_tension"), v("contact_angle"),
                                                        v("rupture_distance"));
                }},
               {{.key = "surface_tension", .unit = "J/m^2", .default_value = 0.072,
                 .help = "surface tension of the liquid film (water 0.072)", .lower = 0.0},
                {.key = "contact_angle", .unit = "deg", .default_value = 0.0, .help = "contact angle of the meniscus",
                 .lower = 0.0, .upper = 90.0},
                {.key = "rupture_distance", .unit = "nm", .default_value = 2.0,
                 .help = "gap at which the neck breaks on retract", .lower = 0.0, .lower_open = true}});

  // Built like every other law: by name, from named values (anything not given takes the key's default).
  impact::LawArguments args;
  args.values = {{"effective_modulus", 1.0}, {"tip_radius", 10.0}, {"rupture_distance", 2.0}};
  const impact::ForceLaw law = registry.build("capillary", args);
  const double f_cap = dynamic_cast<const CapillaryLaw&>(law.model()).capillary_force();
  const double rupture = law.switching_gaps().back();
  std::printf("afmkit %s: law '%s', capillary force %.4g nN, rupture distance %.4g nm\n", afmkit::version,
              law.name().c_str(), f_cap, rupture);

  // The registry checks ranges for us: a negative surface tension is refused, naming the key.
  try {
    impact::LawArguments bad = args;
    bad.values["surface_tension"] = -1.0;
    (void)registry.build("capillary", bad);
    std::printf("error: a negative surface tension was accepted\n");
    return 1;
  } catch (const InvalidParameter& e) {
    std::printf("refused as expected (%s): %s\n", e.parameter().c_str(), e.what());
  }

  // ---- (a) impact of an AFM tip (m1 = 1e-11 kg) on a sample (m2 = 1 kg) at 1 cm/s ------------------------------
  // Units: masses in kg, gap in nm, speed in nm/s -> forces in nN, times in s, energies in aJ (1e-18 J).
  const auto problem = impact::ImpactProblem::head_on(1e-11, 1.0, 1e7, 5.0, law);
  const impact::ImpactResult r = impact::simulate_impact(problem);
  if (r.outcome != impact::ImpactOutcome::separated) {
    std::printf("error: the tip was captured: %s\n", r.capture_reason.c_str());
    return 1;
  }
  std::printf("impact (%s): restitution e = %.6f, contact %.4g ns, max penetration %.4g nm, peak force %.4g nN\n",
              r.method.c_str(), r.restitution, r.contact_duration * 1e9, r.max_penetration, r.peak_force);
  std::printf("  energy loss %.6g aJ (kinetic), %.6g aJ (hysteresis area, eq. 6), of %.6g aJ\n",
              r.kinetic_energy_loss, r.energy_loss_area, r.kinetic_energy_before);
  // The loss is the area between the branches: F_cap (d_rupture - d_min).
  const double expected = f_cap * (rupture - r.minimum_gap);
  if (std::abs(r.energy_loss_area - expected) > 1e-9 * expected ||
      std::abs(r.kinetic_energy_loss - expected) > 1e-6 * expected) {
    std::printf("error: energy loss %.17g / %.17g differs from F_cap (d_r - d_min) = %.17g\n", r.kinetic_energy_loss,
                r.energy_loss_area, expected);
    return 1;
  }

  // ---- (b) converged tapping orbit in physical units --------------------------------------------------------------
  // k = 40 N/m, f0 = 300 kHz, Q = 100, free amplitude 20 nm, driven at resonance; separation 15 nm.
  const tapping::PhysicalCantilever cantilever(40.0, 300.0, 100.0, 20.0, 1.0);
  const tapping::UnitScales units = cantilever.scales();
  // The law in the model's normalised units: forces nN -> per unit mass (divided by k), gap rates nm/s -> nm per
  // model time unit (times ω_n = 2π f0 [Hz]); the same as law.scaled(1 / k, 2π f0 [Hz]).
  const impact::ForceLaw model_law = cantilever.normalised_law(law);
  const tapping::TappingModel model(cantilever.cantilever(), cantilever.drive(), model_law, 15.0);

  // What the instrument does: start from the free oscillation and let the transient settle on a stable orbit.
  const tapping::TransientOutcome settled = tapping::settle(model, tapping::free_response_state(model));
  if (settled.kind != tapping::ResponseKind::periodic || !settled.orbit) {
    std::printf("error: the transient did not settle: %s\n", settled.message.c_str());
    return 1;
  }
  const tapping::PeriodicOrbit& orbit = *settled.orbit;
  const tapping::OrbitMetrics m = tapping::analyse_orbit(model, orbit);
  std::printf("tapping orbit at separation 15 nm (free amplitude %.4g nm): period-%d, %s (max |Floquet| %.4f)\n",
              model.free_amplitude() * units.length, orbit.period_multiple, orbit.stable ? "stable" : "unstable",
              orbit.floquet_max);
  std::printf("  amplitude %.4f nm, phase %.4f rad (%.2f deg), offset %.4f nm, min gap %.4f nm\n",
              m.amplitude * units.length, m.phase, m.phase * 180.0 / std::numbers::pi, m.offset * units.length,
              m.min_gap * units.length);
  std::printf("  peak force %.4g nN, dissipated per period %.4g aJ (contact %.4g aJ, air %.4g aJ)\n",
              m.peak_force * units.force, m.energy_dissipated() * units.energy, m.contact_dissipation * units.energy,
              m.viscous_dissipation * units.energy);
  // A periodic orbit: the drive work equals what is dissipated.
  if (!(m.amplitude > 0) || std::abs(m.drive_work - m.energy_dissipated()) > 1e-6 * m.drive_work) {
    std::printf("error: drive work %.17g != dissipated %.17g\n", m.drive_work, m.energy_dissipated());
    return 1;
  }
  std::printf("ok\n");
  return 0;
}

}  // namespace

int main() {
  try {
    return run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "custom_law: %s\n", e.what());
    return 1;
  }
}
