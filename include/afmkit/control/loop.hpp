#pragma once
// The closed loop of seed 2 (docs/theory-control.md#spectrum) as a linear time-invariant system with delays:
//   plant      P(s) = e^{−sτ} P0(s),  P0 = 1/γ (static plant, eq. 3/9) or 1/(s + γ) (first-order plant, eq. 1)
//   controller W = C(s) M, u = −w   (negative feedback, docs/conventions.md); C = bank (eq. 18 / 29) or Smith predictor
//   closed-loop poles: 1 + P(s) C(s) = 0  (eq. 12, 19, 21).
//
// Characteristic function Δ(s) (entire in s; its zeros are exactly the closed-loop poles, no cancelled factors):
//   write C = Kn(s)/d(s) with the pole-free normalised parts (q_k(s) = 1 + s²/(k²Ω²), ℓ_k = s(a_k s − b_k kΩ)/(k²Ω²))
//     finite bank:  d = (s + a0) Π_k q_k + Σ_{k∉R} ℓ_k Π_{j≠k} q_j,    Kn = K Σ_{k∈R} ℓ_k Π_{j≠k} q_j
//                   (= det(sI − A_c)/Π k²Ω² and the matching numerator; R = rejected harmonics)
//     N = ∞ bank:   d = Q∞ (F∞ − H1),  Kn = K Q∞ H1,   Q∞(s) = (Ω/π) sinh(πs/Ω) = lim Q_N (eqs. 23, 43, 44);
//                   removable singularities at s = 0, ±iΩ are evaluated by series. This is the limit N → ∞ of
//                   the finite-bank Δ and does NOT contain the spurious factor s²(s² + Ω²) of the
//                   quasi-polynomial γ(𝒜 − ℬe^{−sT}) + e^{−sτ}𝒩(1 − e^{−sT})
//                   (docs/theory-control.md#neutral-realisation caveat): γ(𝒜 − ℬe^{−sT}) + e^{−sτ}𝒩(1 − e^{−sT}) =
//                   (2π/Ω) γ s²(s² + Ω²) e^{−πs/Ω} Δ(s)  (static plant).
//   plain loop:     Δ = M(s) d + Kn e^{−sτ}/γ,                       M = 1 (static) or 1 + s/γ (first order)
//   Smith loop:     Δ = M M̂ d + Kn [M (1 − e^{−sτ_c})/γ̂ + M̂ e^{−s(τ_m + τ)}/γ]   (smith_predictor.hpp;
//                   M̂ = 1 or 1 + s/γ̂, τ_m = measurement_delay, τ_c = correction_delay)
// For a finite bank Δ(s) = det(sI − A0 − Σ_i A_i e^{−sτ_i}) / (Π_k k²Ω² · [γ for a first-order plant]
// · [γ̂ for a first-order model]) with the matrices of closed_loop_dde() below. Static plant, K = γ, τ = 0,
// couplings (20): Δ = p_N(s)/Π k²Ω² with p_N of eq. (22) (stability_tau0.hpp).
//
// If a0 = 0 (single oscillator, eqs. 5–6) the integrator x0 is disconnected: it is left out of Δ (no root at 0
// from it) and of closed_loop_dde, so the single oscillator gives exactly eq. (12) times 1/Ω².
// Smith predictor: Δ contains terms of size e^{−Re(s)τ_i} that cancel (exactly, for an exact model), so zeros far
// in the left half plane (Re s · τ_i ≪ −1) are ill-conditioned (relative error ~ 1e-16 e^{−Re(s)τ_i}).
//
// Evaluation is O(N), allocation-free, and keeps a separate exponential scale so that Δ and Δ' can be
// formed even where Δ itself overflows a double (|s| ≫ NΩ, large N, Re s ≪ 0 with delay): use
// characteristic_scaled() or newton_step() there; characteristic() returns ±inf if the value overflows.
#include <complex>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Dense>

#include "afmkit/control/infinite_bank.hpp"
#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/plant.hpp"
#include "afmkit/control/smith_predictor.hpp"

namespace afmkit::control {

/// Any controller of the loop.
using Controller = std::variant<OscillatorBank, InfiniteBank, SmithPredictor>;

struct LoopSpec {
  Controller controller;
  PlantKind plant_kind;  // Static (eq. 3) or FirstOrder (eq. 1)
  double plant_rate;     // γ > 0
  double delay;          // τ ≥ 0

  /// Validated: plant_rate > 0 finite, delay ≥ 0 finite.
  LoopSpec(Controller controller, PlantKind plant_kind, double plant_rate, double delay);

  double rotation_frequency() const;  // Ω of the controller
  double period() const;              // T = 2π/Ω
  double gain() const;                // K of the controller's bank
  double gain_ratio() const;          // ρ = K/γ (design point ρ = 1)
  LoopSpec with_delay(double delay) const;
  /// Short human-readable description ("bank N=10 α=0.1 β=-0.1 K=20, static plant γ=20, τ=0.1").
  std::string describe() const;
};

/// Δ(s) as described above (value).
std::complex<double> characteristic(const LoopSpec& loop, std::complex<double> s);
/// dΔ/ds, exact (forward-mode differentiation of the same formula).
std::complex<double> characteristic_derivative(const LoopSpec& loop, std::complex<double> s);

/// Δ and Δ' with a common scale: Δ = value · e^{log_scale}, Δ' = derivative · e^{log_scale}.
struct ScaledCharacteristic {
  std::complex<double> value;
  std::complex<double> derivative;
  double log_scale;
};
ScaledCharacteristic characteristic_scaled(const LoopSpec& loop, std::complex<double> s);
/// Newton step Δ(s)/Δ'(s) (scale-free, never overflows).
std::complex<double> newton_step(const LoopSpec& loop, std::complex<double> s);

// ---- frequency functions of the loop (exact at any complex s; ±inf magnitude exactly at a pole) ----------
/// Controller C(s) (W = C M); Smith predictor: C_sp = C A_m/(1 + C Π).
std::complex<double> controller_response(const Controller& controller, std::complex<double> s);
/// Delay-free plant P0(s) = 1/γ or 1/(s + γ).
std::complex<double> plant_response_delay_free(const LoopSpec& loop, std::complex<double> s);
/// Plant P(s) = e^{−sτ} P0(s) (eq. 9 for the static plant).
std::complex<double> plant_response(const LoopSpec& loop, std::complex<double> s);
/// Loop transfer function L = P C.
std::complex<double> loop_response(const LoopSpec& loop, std::complex<double> s);
/// Sensitivity S = 1/(1 + L): disturbance at the plant output → output.
std::complex<double> sensitivity(const LoopSpec& loop, std::complex<double> s);
/// Closed loop, disturbance f → output y: G_f S with G_f = 1 (static plant) or γ/(s + γ) (first order).
/// S(ikΩ) = 0 for rejected k, = 1 for kept k (internal-model principle, docs/theory-control.md#oscillator-bank).
std::complex<double> disturbance_response(const LoopSpec& loop, std::complex<double> s);

// ---- delay-differential form (finite banks only) ------------------------------------------------------------
/// x' = A0 x + Σ_i A_i x(t − τ_i). State: (controller bank z ∈ ℝ^{2N+1}, then y for a first-order plant, then
/// ŷ for a first-order Smith model). Throws InvalidParameter("controller") for an N = ∞ bank.
struct DelayDifferentialSystem {
  Eigen::MatrixXd a0;
  std::vector<std::pair<double, Eigen::MatrixXd>> delayed;  // (τ_i, A_i), τ_i ≥ 0 (entries may share τ_i)
  /// A0 + Σ A_i: the closed-loop state matrix when every delay is 0 (τ = 0 stability by eigenvalues).
  Eigen::MatrixXd undelayed_matrix() const;
  /// det(sI − A0 − Σ A_i e^{−sτ_i}) (Eigen partial-pivot LU; for tests and small systems).
  std::complex<double> determinant(std::complex<double> s) const;
};
DelayDifferentialSystem closed_loop_dde(const LoopSpec& loop);

}  // namespace afmkit::control
