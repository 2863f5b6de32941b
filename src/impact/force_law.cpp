#include "afmkit/impact/force_law.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::impact {

const char* hysteresis_name(Hysteresis h) { return h == Hysteresis::contact ? "contact" : "velocity"; }

PiecewiseLinearLaw::PiecewiseLinearLaw(double ka, double kb, double fa, double fb, bool allow_gain)
    : approach_stiffness(validate::non_negative("approach_stiffness", ka)),
      departure_stiffness(validate::non_negative("departure_stiffness", kb)),
      approach_adhesion(validate::non_negative("approach_adhesion", fa)),
      departure_adhesion(validate::finite("departure_adhesion", fb)),
      allow_energy_gain(allow_gain) {
  if (!(fb >= fa))  // (the message made only when it is said: every run builds a law)
    validate::require(false, "departure_adhesion", fb,
                      fmt::format(">= approach_adhesion = {} (0 <= F_a <= F_b, seed-1 eq. 26)", fa));
}

void PiecewiseLinearLaw::require_dissipative() const {
  // Area between the branches (seed-1 eq. 6) at penetration δ: (F_b − F_a)δ + ½(K_a − K_b)δ² ≥ 0 for all
  // δ ≥ 0 iff F_b ≥ F_a (always enforced) and K_b ≤ K_a.
  if (allow_energy_gain || departure_stiffness <= approach_stiffness) return;
  throw InvalidParameter(
      "departure_stiffness",
      fmt::format("departure_stiffness = {} must be <= approach_stiffness = {} (a hysteresis law dissipates energy; "
                  "set allow_energy_gain = true to allow e > 1)",
                  departure_stiffness, approach_stiffness));
}

PiecewiseLinearLaw PiecewiseLinearLaw::linear_repulsive(double k) { return {k, k, 0.0, 0.0}; }
PiecewiseLinearLaw PiecewiseLinearLaw::linear_hysteresis(double ka, double kb) { return {ka, kb, 0.0, 0.0}; }
PiecewiseLinearLaw PiecewiseLinearLaw::repulsive_attractive(double ka, double kb, double fa, double fb) {
  return {ka, kb, fa, fb};
}
double PiecewiseLinearLaw::departure_stiffness_for_restitution(double ka, double e, bool allow_gain) {
  validate::non_negative("approach_stiffness", ka);
  validate::require(std::isfinite(e) && e > 0 && (e <= 1 || allow_gain), "restitution", e,
                    allow_gain ? "> 0 (finite)"
                               : "in (0, 1] (e > 1 creates energy; set allow_energy_gain = true to allow it)");
  // K_b = e² K_a written as K_a − K_a(1 − e)(1 + e): for e ∈ [½, 1] 1 − e is exact, so K_a − K_b keeps its
  // relative accuracy as e → 1 (the loss (1 − e²) μ v²/2 of seed-1 eq. 3 is proportional to it).
  const double kb = e >= 0.5 && e <= 1.0 ? ka - ka * ((1.0 - e) * (1.0 + e)) : e * e * ka;
  if (!std::isfinite(kb))
    throw InvalidParameter("restitution", fmt::format("restitution = {} with approach_stiffness = {} gives a "
                                                      "departure stiffness e^2 K_a beyond the double range",
                                                      e, ka));
  return kb;
}

namespace {

/// ∫_lo^hi (H_a − H_b) dξ for H_X = −(F_X + K_X ξ) (ξ < 0), 0 (ξ ≥ 0), seed-1 eqs. (10), (11), (26):
/// on [lo, min(hi, 0)] the integrand is (F_b − F_a) − (K_a − K_b) ξ, so the area is
/// w·((F_b − F_a) − ½(K_a − K_b)(lo + hi')) with w = hi' − lo: a sum of non-negative terms for a dissipative law.
double piecewise_linear_area(const PiecewiseLinearLaw& p, double lo, double hi) {
  const double top = std::min(hi, 0.0);
  if (!(lo < top)) return 0.0;
  const double dk = p.approach_stiffness - p.departure_stiffness;  // exact when K_b is near K_a (Sterbenz)
  const double df = p.departure_adhesion - p.approach_adhesion;
  return (top - lo) * (df - 0.5 * dk * (lo + top));
}

class PiecewiseLinearModel final : public ForceLawModel {
 public:
  explicit PiecewiseLinearModel(const PiecewiseLinearLaw& law) : law_(law) {}
  std::string name() const override {
    if (law_.approach_adhesion == 0 && law_.departure_adhesion == 0)
      return law_.approach_stiffness == law_.departure_stiffness ? "linear" : "hysteresis";
    return "attractive";
  }
  double approach(double gap) const override { return law_.approach(gap); }
  double departure(double gap) const override { return law_.departure(gap); }
  std::vector<double> switching_gaps() const override { return {0.0}; }
  bool branch_dependent(int region) const override {
    return region == 0 && (law_.approach_stiffness != law_.departure_stiffness ||
                           law_.approach_adhesion != law_.departure_adhesion);
  }
  const PiecewiseLinearLaw* piecewise_linear() const override { return &law_; }
  void require_dissipative() const override { law_.require_dissipative(); }
  double hysteresis_area(double lo, double hi) const override { return piecewise_linear_area(law_, lo, hi); }

 private:
  PiecewiseLinearLaw law_;
};

class CustomModel final : public ForceLawModel {
 public:
  explicit CustomModel(CustomLaw law) : law_(std::move(law)) {
    if (!law_.approach || !law_.departure)
      throw InvalidParameter("force_law", "custom force law: both branches must be set");
    for (double g : law_.switching_gaps) validate::finite("switching_gaps", g);
  }
  std::string name() const override { return law_.name; }
  double approach(double gap) const override { return law_.approach(gap); }
  double departure(double gap) const override { return law_.departure(gap); }
  std::vector<double> switching_gaps() const override { return law_.switching_gaps; }

 private:
  CustomLaw law_;
};

}  // namespace

ForceLaw::ForceLaw(std::shared_ptr<const ForceLawModel> model) : model_(std::move(model)) {
  if (!model_) throw InvalidParameter("force_law", "force law: no model given (null pointer)");
  refresh();
}
ForceLaw::ForceLaw(PiecewiseLinearLaw law) : ForceLaw(std::make_shared<PiecewiseLinearModel>(law)) {}
ForceLaw::ForceLaw(CustomLaw law) : ForceLaw(std::make_shared<CustomModel>(std::move(law))) {}

void ForceLaw::refresh() {
  switching_gaps_ = model_->switching_gaps();
  for (double g : switching_gaps_) validate::finite("switching_gaps", g);
  std::sort(switching_gaps_.begin(), switching_gaps_.end());
  switching_gaps_.erase(std::unique(switching_gaps_.begin(), switching_gaps_.end()), switching_gaps_.end());
  has_damping_ = model_->has_damping();
  contact_gap_ = model_->contact_gap();
  hysteresis_ = model_->hysteresis();
  if (hysteresis_ == Hysteresis::contact) {
    // the mode switches of a contact-aware law are events: both gaps must be switching gaps, d_c ≤ d_r
    release_gap_ = model_->release_gap();
    const auto listed = [&](double g) {
      return std::find(switching_gaps_.begin(), switching_gaps_.end(), g) != switching_gaps_.end();
    };
    if (!std::isfinite(contact_gap_) || !std::isfinite(release_gap_) || !(release_gap_ >= contact_gap_) ||
        !listed(contact_gap_) || !listed(release_gap_))
      throw InvalidParameter("force_law",
                             fmt::format("force law '{}': a contact-aware law needs a finite contact gap ({}) and "
                                         "release gap ({}) >= it, both among its switching gaps",
                                         model_->name(), contact_gap_, release_gap_));
  } else {
    release_gap_ = std::numeric_limits<double>::quiet_NaN();
  }
  scaled_linear_.reset();
  if (const auto* p = model_->piecewise_linear())
    scaled_linear_ = std::make_shared<PiecewiseLinearLaw>(p->approach_stiffness * scale_, p->departure_stiffness * scale_,
                                                          p->approach_adhesion * scale_, p->departure_adhesion * scale_,
                                                          p->allow_energy_gain);
}

double ForceLaw::force(double gap, double rate) const {
  const double viscous = has_damping_ ? -damping(gap) * rate : 0.0;
  if (rate < 0) return approach(gap) + viscous;
  if (rate > 0) return departure(gap) + viscous;
  return 0.5 * (approach(gap) + departure(gap));
}

double ForceLaw::force(double gap, double rate, bool in_contact) const {
  if (hysteresis_ == Hysteresis::velocity || in_contact) return force(gap, rate);
  return approach(gap) + (has_damping_ ? -damping(gap) * rate : 0.0);
}

const PiecewiseLinearLaw* ForceLaw::piecewise_linear() const& { return scaled_linear_.get(); }

ForceLaw ForceLaw::scaled(double force_factor, double rate_factor) const {
  validate::positive("force_scale", force_factor);
  validate::positive("rate_scale", rate_factor);
  ForceLaw out = *this;
  out.scale_ = scale_ * force_factor;
  out.damping_scale_ = damping_scale_ * force_factor * rate_factor;
  out.refresh();
  return out;
}

}  // namespace afmkit::impact
