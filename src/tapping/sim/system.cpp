#include "afmkit/tapping/system.hpp"
#include "afmkit/core/numbers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace afmkit::tapping {

namespace {
using afmkit::numbers::infinity;
}

TappingSystem::TappingSystem(TappingModel model)
    : model_(std::move(model)),
      separation_(model_.separation),
      damping_(2.0 * model_.cantilever.damping_ratio() * model_.cantilever.natural_frequency),
      stiffness_(model_.cantilever.natural_frequency * model_.cantilever.natural_frequency),
      omega_(model_.drive.frequency),
      gamma_(model_.drive.amplitude) {
  if (const auto* p = model_.law.piecewise_linear()) linear_ = *p;
  const int regions = region_count();
  for (int r = 0; r < regions && r < 64; ++r)
    if (model_.law.branch_dependent(r)) dependent_mask_ |= 1ul << r;
  has_damping_ = model_.law.has_damping();
  if (model_.law.contact_aware()) {
    // both gaps are switching gaps (ForceLaw checks it): region r spans [s_{r−1}, s_r)
    contact_aware_ = true;
    const auto& s = switching();
    contact_top_ = static_cast<int>(std::lower_bound(s.begin(), s.end(), model_.law.contact_gap()) - s.begin());
    release_region_ = static_cast<int>(std::lower_bound(s.begin(), s.end(), model_.law.release_gap()) - s.begin()) + 1;
  }
}

namespace {
/// The TappingModel a multi-mode system carries: the model itself when single_mode() (bit for bit), else mode 1
/// (medium applied) with drive 1 and the law unscaled (the modal equations apply ρβ_i to its force).
TappingModel modal_carrier(const MultiModeModel& m) {
  if (m.single_mode()) return m.first_mode();
  return {Cantilever(m.frequency(0), m.quality_factor(0)), m.drives[0], m.law, m.separation};
}
}  // namespace

TappingSystem::TappingSystem(const MultiModeModel& m) : TappingSystem(modal_carrier(m)) {
  if (m.single_mode()) return;
  ModalTerms t;
  t.modes = m.mode_count();
  t.drives = m.drive_count();
  t.shortest_period = m.shortest_mode_period();
  for (int i = 0; i < t.modes; ++i) {
    t.stiffness[i] = m.frequency(i) * m.frequency(i);
    t.damping[i] = m.damping(i);
    t.coupling[i] = m.coupling(i);
    for (int d = 0; d < t.drives; ++d) t.forcing[i][d] = m.forcing(i, d);
  }
  for (int d = 0; d < t.drives; ++d) {
    t.omega[d] = m.drives[d].frequency;
    t.base[d] = m.base_amplitude(d);
    t.shortest_period = std::min(t.shortest_period, m.drives[d].period());
  }
  modal_ = t;
}

void TappingSystem::modal_forcing(double t, double* out, std::array<double, 4>& base) const {
  const ModalTerms& m = *modal_;
  for (int i = 0; i < m.modes; ++i) out[i] = 0.0;
  base = {0.0, 0.0, 0.0, 0.0};
  for (int d = 0; d < m.drives; ++d) {
    const double w = m.omega[d], c = std::cos(w * t), sn = std::sin(w * t), y = m.base[d];
    for (int i = 0; i < m.modes; ++i) out[i] += m.forcing[i][d] * c;
    base[0] += y * c;
    base[1] -= y * w * sn;
    base[2] -= y * w * w * c;
    base[3] += y * w * w * w * sn;
  }
}

namespace {
void coordinates_given_base(int modes, const TipState& s, const std::array<double, 4>& base, double* q, double* v) {
  q[0] = s.position - base[0];
  v[0] = s.velocity - base[1];
  for (int j = 1; j < modes; ++j) {
    q[j] = s.modal[2 * (j - 1)];
    v[j] = s.modal[2 * (j - 1) + 1];
    q[0] -= q[j];
    v[0] -= v[j];
  }
}
}  // namespace

void TappingSystem::modal_coordinates(double t, const TipState& s, double* q, double* v) const {
  double f[kMaxEigenmodes];
  std::array<double, 4> base{};
  modal_forcing(t, f, base);
  coordinates_given_base(modal_->modes, s, base, q, v);
}

double TappingSystem::modal_accelerations(ContactBranch branch, int region, double t, const TipState& s,
                                          double* out, double* force) const {
  // q̈_i = F_i(t) − 2ξ_i'ω_i' q̇_i − ω_i'² q_i − ρβ_i h(x, ẋ);  ẍ = ÿ_b + Σ q̈_i   (modes.hpp)
  const ModalTerms& m = *modal_;
  double f[kMaxEigenmodes], q[kMaxEigenmodes], v[kMaxEigenmodes];
  std::array<double, 4> base{};
  modal_forcing(t, f, base);
  coordinates_given_base(m.modes, s, base, q, v);
  double h;
  if (branch == ContactBranch::sticking) {
    // the tip held at rest: the contact force is what keeps ẍ = ÿ_b + Σ q̈_i = 0 (the modes move on)
    double free_tip = base[2], coupling = 0.0;
    for (int i = 0; i < m.modes; ++i) {
      free_tip += f[i] - m.damping[i] * v[i] - m.stiffness[i] * q[i];
      coupling += m.coupling[i];
    }
    h = free_tip / coupling;
  } else {
    h = interaction(branch, s.position, s.velocity, region);
  }
  double tip = base[2];
  for (int i = 0; i < m.modes; ++i) {
    const double a = f[i] - m.damping[i] * v[i] - m.stiffness[i] * q[i] - m.coupling[i] * h;
    if (out) out[i] = a;
    tip += a;
  }
  if (force) *force = h;
  return branch == ContactBranch::sticking ? 0.0 : tip;
}

double TappingSystem::modal_release_rate(double t, const TipState& s, int region) const {
  // g = ÿ_b + Σ (F_i − 2ξ_i'ω_i' q̇_i − ω_i'² q_i) − Σ ρβ_i h_branch(x) with x held: ġ = y_b⃛ + Σ (Ḟ_i − … q̈_i − … q̇_i)
  const ModalTerms& m = *modal_;
  double a[kMaxEigenmodes], f[kMaxEigenmodes], q[kMaxEigenmodes], v[kMaxEigenmodes];
  std::array<double, 4> base{};
  modal_forcing(t, f, base);
  coordinates_given_base(m.modes, s, base, q, v);
  modal_accelerations(ContactBranch::sticking, region, t, s, a);
  double rate = base[3];
  for (int i = 0; i < m.modes; ++i) {
    double f_rate = 0.0;
    for (int d = 0; d < m.drives; ++d) f_rate -= m.forcing[i][d] * m.omega[d] * std::sin(m.omega[d] * t);
    rate += f_rate - m.damping[i] * a[i] - m.stiffness[i] * v[i];
  }
  return rate;
}

double TappingSystem::modal_jerk(const Mode& mode, double t, const TipState& s) const {
  if (mode.branch == ContactBranch::sticking) return 0.0;
  // d/dt ẍ = y_b⃛ + Σ [Ḟ_i − 2ξ_i'ω_i' q̈_i − ω_i'² q̇_i − ρβ_i (h_x ẋ + h_ẋ ẍ)]
  const ModalTerms& m = *modal_;
  double a[kMaxEigenmodes], f[kMaxEigenmodes], q[kMaxEigenmodes], v[kMaxEigenmodes];
  std::array<double, 4> base{};
  modal_forcing(t, f, base);
  coordinates_given_base(m.modes, s, base, q, v);
  const double tip = modal_accelerations(mode.branch, mode.region, t, s, a);
  const double h_rate = interaction_slope(mode.branch, s.position, s.velocity, mode.region) * s.velocity +
                        interaction_rate_slope(mode.branch, s.position, mode.region) * tip;
  double jerk = base[3];
  for (int i = 0; i < m.modes; ++i) {
    double f_rate = 0.0;
    for (int d = 0; d < m.drives; ++d) f_rate -= m.forcing[i][d] * m.omega[d] * std::sin(m.omega[d] * t);
    jerk += f_rate - m.damping[i] * a[i] - m.stiffness[i] * v[i] - m.coupling[i] * h_rate;
  }
  return jerk;
}

int TappingSystem::region_of(double gap) const {
  return static_cast<int>(std::upper_bound(switching().begin(), switching().end(), gap) - switching().begin());
}


double TappingSystem::drive(double t) const { return gamma_ * std::cos(omega_ * t); }
double TappingSystem::drive_rate(double t) const { return -gamma_ * omega_ * std::sin(omega_ * t); }

double TappingSystem::interaction(ContactBranch branch, double x, double velocity, int region) const {
  const double elastic = elastic_interaction(branch, x, region);
  if (!has_damping_ || branch == ContactBranch::sticking) return elastic;
  return elastic + model_.law.damping(clamp_gap(gap(x), region)) * velocity;  // h = −H, H ∋ −c(d)ḋ, ḋ = ẋ
}


double TappingSystem::interaction_rate_slope(ContactBranch branch, double x, int region) const {
  if (!has_damping_ || branch == ContactBranch::sticking) return 0.0;
  return model_.law.damping(clamp_gap(gap(x), region));
}

double TappingSystem::elastic_interaction(ContactBranch branch, double x, int region) const {
  const double d = gap(x);
  if (linear_) {
    if (region != 0) return 0.0;
    // h = F + K d in contact (seed-1 eq. 26), smooth extension beyond d = 0
    switch (branch) {
      case ContactBranch::approach: return linear_->approach_adhesion + linear_->approach_stiffness * d;
      case ContactBranch::departure: return linear_->departure_adhesion + linear_->departure_stiffness * d;
      case ContactBranch::sticking:
        return 0.5 * (linear_->approach_adhesion + linear_->departure_adhesion +
                      (linear_->approach_stiffness + linear_->departure_stiffness) * d);
    }
  }
  // continuous extension: clamp the gap into the region (open upper end: stay just below the switching gap)
  const double dc = clamp_gap(d, region);
  switch (branch) {
    case ContactBranch::approach: return -model_.law.approach(dc);
    case ContactBranch::departure: return -model_.law.departure(dc);
    case ContactBranch::sticking: return -0.5 * (model_.law.approach(dc) + model_.law.departure(dc));
  }
  return 0.0;
}

double TappingSystem::interaction_slope(ContactBranch branch, double x, double velocity, int region) const {
  if (linear_) {
    if (region != 0) return 0.0;
    switch (branch) {
      case ContactBranch::approach: return linear_->approach_stiffness;
      case ContactBranch::departure: return linear_->departure_stiffness;
      case ContactBranch::sticking: return 0.5 * (linear_->approach_stiffness + linear_->departure_stiffness);
    }
  }
  const double d = gap(x);
  const double lo = region_lo(region), hi = region_hi(region);
  if (!has_damping_ && model_.law.has_slopes()) {
    // h = −H; beyond the region the law is continued by its boundary value (clamp_gap): slope 0 there
    if (d < lo || d >= hi) return 0.0;
    switch (branch) {
      case ContactBranch::approach: return -model_.law.approach_slope(d);
      case ContactBranch::departure: return -model_.law.departure_slope(d);
      case ContactBranch::sticking: return -0.5 * (model_.law.approach_slope(d) + model_.law.departure_slope(d));
    }
  }
  const double step = 1e-6 * std::max(1.0, std::abs(d));
  auto h = [&](double dd) { return interaction(branch, dd - separation_, velocity, region); };
  if (d - step >= lo && d + step < hi) return (h(d + step) - h(d - step)) / (2.0 * step);
  if (d + 2 * step < hi) return (-3.0 * h(d) + 4.0 * h(d + step) - h(d + 2 * step)) / (2.0 * step);
  return (3.0 * h(d) - 4.0 * h(d - step) + h(d - 2 * step)) / (2.0 * step);
}

double TappingSystem::interaction_with_slope(ContactBranch branch, double x, double velocity, int region,
                                             double& slope) const {
  if (linear_ || has_damping_ || !model_.law.has_slopes() || branch == ContactBranch::sticking) {
    slope = interaction_slope(branch, x, velocity, region);
    return interaction(branch, x, velocity, region);
  }
  const double d = gap(x);
  const double lo = region_lo(region), hi = region_hi(region);
  const bool inside = d >= lo && d < hi;
  const double dc = inside ? d : clamp_gap(d, region);
  if (branch == ContactBranch::approach) {
    slope = inside ? -model_.law.approach_slope(d) : 0.0;
    return -model_.law.approach(dc);
  }
  slope = inside ? -model_.law.departure_slope(d) : 0.0;
  return -model_.law.departure(dc);
}

double TappingSystem::acceleration(ContactBranch branch, int region, double t, TipState s) const {
  if (modal_) return modal_accelerations(branch, region, t, s, nullptr);
  return acceleration_given_drive({region, branch}, drive(t), s);
}

double TappingSystem::acceleration(const Mode& mode, double t, TipState s) const {
  if (mode.branch == ContactBranch::sticking) return 0.0;
  return acceleration(mode.branch, mode.region, t, s);
}


Mode TappingSystem::initial_mode(double t, TipState& s) const {
  int region = region_of(gap(s.position));
  // exactly on a switching gap and moving down: the motion continues in the region below
  if (region > 0 && gap(s.position) == switching()[region - 1] && s.velocity < 0) --region;
  // contact-aware: in contact below the contact gap, free above the release gap, the state's memory between
  const bool contact = contact_aware_ && (region <= contact_top_ || (s.contact && region < release_region_));
  return enter_region(region, t, s, contact);
}

Mode TappingSystem::enter_region(int region, double t, TipState& s, bool contact) const {
  if (contact_aware_ && !contact) return {region, ContactBranch::approach, false};  // free: H_a whatever ẋ
  if (s.velocity < 0) return {region, ContactBranch::approach, contact};
  if (s.velocity > 0) return {region, ContactBranch::departure, contact};
  if (!branch_dependent(region)) {
    const double a = acceleration(ContactBranch::approach, region, t, s);
    return {region, a < 0 ? ContactBranch::approach : ContactBranch::departure, contact};
  }
  const double aa = acceleration(ContactBranch::approach, region, t, s);
  const double ab = acceleration(ContactBranch::departure, region, t, s);
  if (aa < 0) return {region, ContactBranch::approach, contact};
  if (ab > 0) return {region, ContactBranch::departure, contact};
  s.velocity = 0.0;
  return {region, ContactBranch::sticking, contact};
}

Mode TappingSystem::after_velocity_zero(int region, ContactBranch from, double t, TipState& s) const {
  TipState rest = s;  // at rest: the tip's velocity 0 (a multi-mode state keeps its higher modal coordinates)
  rest.velocity = 0.0;
  const double aa = acceleration(ContactBranch::approach, region, t, rest);
  const double ab = acceleration(ContactBranch::departure, region, t, rest);
  // (a velocity guard exists only in velocity-switched modes: in contact for a contact-aware law)
  const bool contact = contact_aware_;
  if (from == ContactBranch::approach) {
    if (ab > 0) return {region, ContactBranch::departure, contact};
    if (aa < 0) {
      s.velocity = 0.0;
      return {region, ContactBranch::approach, contact};
    }
  } else {
    if (aa < 0) return {region, ContactBranch::approach, contact};
    if (ab > 0) {
      s.velocity = 0.0;
      return {region, ContactBranch::departure, contact};
    }
  }
  s.velocity = 0.0;  // both branches push back onto ẋ = 0: the tip sticks
  return {region, ContactBranch::sticking, contact};
}

Mode TappingSystem::after_event(const Mode& mode, const Guard& guard, double t, TipState& s) const {
  switch (guard.kind) {
    case GuardKind::gap: {
      const int region = guard.direction == CrossingDirection::falling ? mode.region - 1 : mode.region + 1;
      // contact-aware: contact begins when the gap falls through the contact gap, ends when it rises through
      // the release gap (the memory holds in between)
      bool contact = mode.contact;
      if (contact_aware_) {
        if (region <= contact_top_) contact = true;
        if (region >= release_region_) contact = false;
      }
      return enter_region(region, t, s, contact);
    }
    case GuardKind::velocity:
      return after_velocity_zero(mode.region, mode.branch, t, s);
    case GuardKind::release_departure:
      s.velocity = 0.0;
      return {mode.region, ContactBranch::departure, mode.contact};
    case GuardKind::release_approach:
      s.velocity = 0.0;
      return {mode.region, ContactBranch::approach, mode.contact};
  }
  return mode;
}

int TappingSystem::guards(const Mode& mode, std::array<Guard, 3>& out) const {
  int n = 0;
  if (mode.branch == ContactBranch::sticking) {
    out[n++] = {GuardKind::release_departure, CrossingDirection::rising, 0.0};
    out[n++] = {GuardKind::release_approach, CrossingDirection::falling, 0.0};
    return n;
  }
  if (mode.region > 0) out[n++] = {GuardKind::gap, CrossingDirection::falling, switching()[mode.region - 1]};
  if (mode.region < static_cast<int>(switching().size()))
    out[n++] = {GuardKind::gap, CrossingDirection::rising, switching()[mode.region]};
  if (velocity_switched(mode)) {
    out[n++] = {GuardKind::velocity,
                mode.branch == ContactBranch::approach ? CrossingDirection::rising : CrossingDirection::falling, 0.0};
  }
  return n;
}

double TappingSystem::witness(const Guard& guard, const Mode& mode, double t, TipState s) const {
  switch (guard.kind) {
    case GuardKind::gap: return gap(s.position) - guard.level;
    case GuardKind::velocity: return s.velocity;
    case GuardKind::release_departure:
      s.velocity = 0.0;  // at rest (a multi-mode state keeps its higher modal coordinates)
      return acceleration(ContactBranch::departure, mode.region, t, s);
    case GuardKind::release_approach:
      s.velocity = 0.0;
      return acceleration(ContactBranch::approach, mode.region, t, s);
  }
  return 0.0;
}

double TappingSystem::witness_rate(const Guard& guard, const Mode& mode, double t, TipState s) const {
  switch (guard.kind) {
    case GuardKind::gap: return s.velocity;
    case GuardKind::velocity: return acceleration(mode, t, s);
    case GuardKind::release_departure:
    case GuardKind::release_approach: return modal_ ? modal_release_rate(t, s, mode.region) : drive_rate(t);
  }
  return 0.0;
}

double TappingSystem::witness_rate_derivative(const Guard& guard, const Mode& mode, double t, TipState s) const {
  switch (guard.kind) {
    case GuardKind::gap: return acceleration(mode, t, s);
    case GuardKind::velocity: {
      if (mode.branch == ContactBranch::sticking) return 0.0;
      if (modal_) return modal_jerk(mode, t, s);
      // jerk: d/dt (Γ cos ωt − cẋ − ω_n² x − h(x, ẋ)) = −Γω sin ωt − (c + h_ẋ) ẍ − (ω_n² + h_x) ẋ
      const double a = acceleration(mode, t, s);
      return drive_rate(t) - (damping_ + interaction_rate_slope(mode.branch, s.position, mode.region)) * a -
             (stiffness_ + interaction_slope(mode.branch, s.position, s.velocity, mode.region)) * s.velocity;
    }
    case GuardKind::release_departure:
    case GuardKind::release_approach: return modal_ ? 0.0 : -omega_ * omega_ * drive(t);  // modal: unused (bisection)
  }
  return 0.0;
}

void TappingSystem::witness_gradient(const Guard& guard, const Mode& mode, double t, TipState s, double grad[3],
                                     double& time_partial) const {
  time_partial = 0.0;
  switch (guard.kind) {
    case GuardKind::gap:
      grad[0] = 1.0, grad[1] = 0.0, grad[2] = 1.0;  // g = x + l − s_i
      return;
    case GuardKind::velocity:
      grad[0] = 0.0, grad[1] = 1.0, grad[2] = 0.0;
      return;
    case GuardKind::release_departure:
    case GuardKind::release_approach: {
      const ContactBranch b =
          guard.kind == GuardKind::release_departure ? ContactBranch::departure : ContactBranch::approach;
      // g = Γcos ωt − ω_n² x − cẋ − h(x + l, ẋ)
      const double slope = interaction_slope(b, s.position, s.velocity, mode.region);
      grad[0] = -stiffness_ - slope, grad[1] = -damping_ - interaction_rate_slope(b, s.position, mode.region),
      grad[2] = -slope;
      time_partial = drive_rate(t);
      return;
    }
  }
}

}  // namespace afmkit::tapping
