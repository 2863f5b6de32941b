#pragma once
// What the tapping system is (independent of how it is integrated): for a TappingModel, the modes, the smooth
// vector field of each mode, the guards that end a mode and the rules that pick the next mode at an event.
//   ẍ = Γ cos(ωt) − 2ξω_n ẋ − ω_n² x − h_branch(x),   h_branch(x) = −H_branch(x + l)   (seed-1 eq. 8)
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "afmkit/tapping/events.hpp"
#include "afmkit/tapping/model.hpp"
#include "afmkit/tapping/modes.hpp"

namespace afmkit::tapping {

/// The hybrid system of a TappingModel. Owns a copy of the model (no lifetime coupling to the caller's model;
/// the copy costs about what the old switching-gap copy did, see bench/bench_tapping.cpp).
class TappingSystem {
 public:
  explicit TappingSystem(TappingModel model);
  /// The system of a multi-mode cantilever (modes.hpp): the same modes, guards and events, seen at the tip
  /// (TipState::modal carries the higher modal coordinates). A MultiModeModel::single_mode() model gives exactly
  /// the system of its TappingModel. model() is then mode 1 with drive 1 (the law unscaled by the medium).
  explicit TappingSystem(const MultiModeModel& model);

  const TappingModel& model() const& { return model_; }
  TappingModel model() && { return std::move(model_); }
  double separation() const { return separation_; }
  /// Moves the sample to the separation l (finite) in place: no rebuilt system, no allocation (an imaging engine
  /// steps cycle by cycle with the height under the moving tip). A single-mode system only (the modal carrier's
  /// separation is that of the multi-mode model).
  void set_separation(double l) { model_.separation = separation_ = l; }
  double gap(double x) const { return x + separation_; }  // d = x + l
  /// Number of gap regions (switching gaps + 1). Region r: s_{r−1} ≤ gap < s_r.
  int region_count() const { return static_cast<int>(switching().size()) + 1; }
  int region_of(double gap) const;
  /// The law's contact gap (0 when it has none): x + l below it counts as contact.
  double contact_gap() const { return std::isnan(model_.law.contact_gap()) ? 0.0 : model_.law.contact_gap(); }
  /// Whether the contact gap is a switching gap, i.e. the contact region is region 0 exactly.
  bool contact_is_region_zero() const { return !switching().empty() && switching().front() == contact_gap(); }
  /// Whether the law is contact-aware (docs/force-laws.md#hysteresis): modes carry the memory of contact.
  bool contact_aware() const { return contact_aware_; }
  /// Whether `mode` selects its branch by the velocity sign: always for velocity-sign laws; for a
  /// contact-aware law only in contact and where the branches may differ.
  bool velocity_switched(const Mode& mode) const {
    return branch_dependent(mode.region) && (!contact_aware_ || mode.contact);
  }
  /// Whether approach and departure branches differ in `region` (else no velocity guard there).
  bool branch_dependent(int region) const {
    return region < 64 ? ((dependent_mask_ >> region) & 1u) != 0 : model_.law.branch_dependent(region);
  }

  double drive(double t) const;       // Γ cos ωt
  double drive_rate(double t) const;  // d/dt Γ cos ωt
  double damping() const { return damping_; }      // 2ξω_n
  double stiffness() const { return stiffness_; }  // ω_n²

  /// h of the given (fixed) branch at position x, extended smoothly (piecewise-linear laws) or continuously
  /// (clamped gap, other laws) beyond the bounds of `region`; sticking uses the mean of the branches (eq. 4).
  /// With a Kelvin–Voigt law h also has the term c(d)·ẋ (c evaluated at the clamped gap); none while sticking.
  double interaction(ContactBranch branch, double x, double velocity, int region) const;
  /// ∂h/∂x of the same extension: exact for piecewise-linear laws, one-sided differences inside `region` else.
  double interaction_slope(ContactBranch branch, double x, double velocity, int region) const;
  /// ∂h/∂ẋ = c(d) (0 unless the law has a Kelvin–Voigt term).
  double interaction_rate_slope(ContactBranch branch, double x, int region) const;
  /// ẍ in `mode` at (t, x, ẋ) (0 while sticking).
  double acceleration(const Mode& mode, double t, TipState s) const;
  /// h(x, ẋ) and ∂h/∂x together (one region lookup; the law's closed-form slopes when it has them).
  double interaction_with_slope(ContactBranch branch, double x, double velocity, int region, double& slope) const;
  /// Γ cos ωt − 2ξω_n ẋ − ω_n² x − h(x, ẋ) with the drive term Γ cos ωt given (any branch, sticking included;
  /// acceleration(mode, …) answers 0 in the sticking mode) (integrators that advance the drive phase themselves).
  double acceleration_given_drive(const Mode& mode, double drive_term, TipState s) const {
    return drive_term - damping_ * s.velocity - stiffness_ * s.position -
           interaction(mode.branch, s.position, s.velocity, mode.region);
  }
  double drive_frequency() const { return omega_; }
  /// ẍ with the given branch's force in `region`.
  double acceleration(ContactBranch branch, int region, double t, TipState s) const;

  /// Mode of a state at time t (region from the gap, branch from ẋ, or from the accelerations when ẋ = 0).
  Mode initial_mode(double t, TipState& s) const;
  /// Mode when entering `region` at (t, s): branch from ẋ, or from the accelerations when ẋ = 0 (may stick);
  /// `contact`: the memory of a contact-aware law (free: the approach branch whatever ẋ).
  Mode enter_region(int region, double t, TipState& s, bool contact = false) const;
  /// Mode after ẋ reached 0 coming from branch `from`: the branch whose acceleration moves the tip away from
  /// ẋ = 0, or sticking (ẋ set to 0) when both push back onto it.
  Mode after_velocity_zero(int region, ContactBranch from, double t, TipState& s) const;
  /// Mode after the crossing of `guard` out of `mode` (s may be adjusted: ẋ = 0 on sticking / release).
  Mode after_event(const Mode& mode, const Guard& guard, double t, TipState& s) const;

  /// Whether this is the system of a multi-mode model other than a TappingModel (more modes, two drives, base
  /// excitation or a liquid): the tip acceleration is then the sum of the modal ones.
  bool modal() const { return modal_.has_value(); }
  int mode_count() const { return modal_ ? modal_->modes : 1; }
  /// Shortest period of the drives and modes other than drive 1 and mode 1 (infinity for a TappingModel).
  double shortest_extra_period() const { return modal_ ? modal_->shortest_period : afmkit_infinity(); }
  /// Multi-mode: the modal accelerations q̈_i (`out`, mode_count() values, may be null) in `branch` and `region`
  /// at (t, s); returns the tip's ẍ = ÿ_b + Σ q̈_i. Sticking: the tip is held (ẍ = 0 returned) by the contact force
  /// h = (ÿ_b + Σ (F_i − 2ξ_i'ω_i' q̇_i − ω_i'² q_i)) / Σ ρβ_i, and the modes move on under it. `force`: h used.
  double modal_accelerations(ContactBranch branch, int region, double t, const TipState& s, double* out,
                             double* force = nullptr) const;
  /// Multi-mode: the modal coordinates q_i, q̇_i of s at t (mode 1 = the tip minus the base motion and the others).
  void modal_coordinates(double t, const TipState& s, double* q, double* v) const;
  /// Multi-mode: the modal forcing F_i(t) (`out`, mode_count() values) and the base motion (y_b, ẏ_b, ÿ_b, y_b⃛).
  void modal_forcing(double t, double* out, std::array<double, 4>& base) const;
  /// Multi-mode: the effective coefficients of mode i: ω_i'², 2ξ_i'ω_i', and ρβ_i (the tip force's coupling).
  double modal_stiffness(int i) const { return modal_->stiffness[i]; }
  double modal_damping(int i) const { return modal_->damping[i]; }
  double modal_coupling(int i) const { return modal_->coupling[i]; }

  /// Guards that can end `mode` (at most 3). Returns their number.
  int guards(const Mode& mode, std::array<Guard, 3>& out) const;
  /// Value of a guard's witness function at (t, s) in `mode`.
  double witness(const Guard& guard, const Mode& mode, double t, TipState s) const;
  /// Time derivative of the witness along the mode's flow (detects double crossings inside a scan step).
  double witness_rate(const Guard& guard, const Mode& mode, double t, TipState s) const;
  /// Second time derivative of the witness along the mode's flow (Newton on the witness rate).
  double witness_rate_derivative(const Guard& guard, const Mode& mode, double t, TipState s) const;
  /// Gradient of the witness with respect to (x, ẋ, l) and its explicit time derivative (saltation matrices).
  void witness_gradient(const Guard& guard, const Mode& mode, double t, TipState s, double grad[3],
                        double& time_partial) const;

 private:
  TappingModel model_;
  double separation_;
  const std::vector<double>& switching() const& { return model_.law.switching_gaps(); }
  unsigned long dependent_mask_ = 0;
  bool contact_aware_ = false;
  int contact_top_ = -1;    // contact-aware: regions ≤ this lie below the contact gap (in contact)
  int release_region_ = 0;  // contact-aware: regions ≥ this lie above the release gap (free)
  std::optional<impact::PiecewiseLinearLaw> linear_;
  bool has_damping_ = false;
  double elastic_interaction(ContactBranch branch, double x, int region) const;
  /// the gap clamped into the region (open upper end: just below its switching gap)
  double clamp_gap(double gap, int region) const {
    double dc = std::max(gap, region_lo(region));
    const double hi = region_hi(region);
    if (dc >= hi) dc = std::nextafter(hi, -afmkit_infinity());
    return dc;
  }
  double damping_;    // 2ξω_n
  double stiffness_;  // ω_n²
  double omega_;      // ω
  double gamma_;      // Γ
  double region_lo(int region) const { return region == 0 ? -afmkit_infinity() : switching()[region - 1]; }
  double region_hi(int region) const {
    return region >= static_cast<int>(switching().size()) ? afmkit_infinity() : switching()[region];
  }
  static double afmkit_infinity() { return std::numeric_limits<double>::infinity(); }
  /// The terms of a multi-mode model (modes.hpp), effective (medium applied).
  struct ModalTerms {
    int modes = 1, drives = 1;
    std::array<double, kMaxEigenmodes> stiffness{}, damping{}, coupling{};
    std::array<std::array<double, 2>, kMaxEigenmodes> forcing{};  // [mode][drive]
    std::array<double, 2> omega{}, base{};                        // ω_d, Y_d
    double shortest_period = 0.0;
  };
  std::optional<ModalTerms> modal_;
  double modal_jerk(const Mode& mode, double t, const TipState& s) const;
  double modal_release_rate(double t, const TipState& s, int region) const;
};

}  // namespace afmkit::tapping
