#pragma once
// Smith-predictor variant of the harmonic-rejection controller (beyond the paper; seed-2 Discussion suggests
// "a classical Smith predictor"). Notation: P(s) = e^{−sτ} P0(s) the true plant (seed-2 eq. 9), P̂0 the model
// of its delay-free part with rate estimate γ̂ (static: 1/γ̂, first order: 1/(s+γ̂)), τ̂ the delay estimate,
// C(s) the oscillator bank (finite, eq. 18, or N = ∞, eq. 29), negative feedback u = −w.
//
// The bank is fed a predicted measurement m̂ instead of m:
//
//   Classic  (Smith 1957):  m̂ = m + P̂0(s) [1 − e^{−sτ̂}] u
//   Periodic (default)   :  m̂ = e^{−s(nT−τ̂)} m + P̂0(s) [1 − e^{−snT}] u,   n = ⌈τ̂/T⌉ (n = 0 ⇒ m̂ = m)
//
//   w = C(s) m̂,  u = −w   ⇒   C_sp(s) = W/M = C A_m / (1 + C Π),   A_m = 1 or e^{−s(nT−τ̂)},
//                                                                  Π = P̂0 (1 − e^{−sτ̂}) or P̂0 (1 − e^{−snT}).
// Closed loop: 1 + P C_sp = 0 ⇔ 1 + C [Π + A_m P] = 0. With an exact model both forms reduce to the
// delay-free loop 1 + C P0 = 0, i.e. the τ = 0 stability region of B.5 holds for every delay.
//
// Why the periodic form is the default (DERIVED here, tested in tests/control): rejection of the first
// harmonic needs the bank input m̂ to have no first harmonic AND m̂_1 ∝ y_1. In the classic form
// m̂_1 = m_1 + P̂0(iΩ)(1 − e^{−iΩτ̂}) u_1, so the steady state has y_1 ≠ 0: the sensitivity at Ω is
// S(iΩ) = 1/(1 + e^{−iΩτ}γ̂/(γ(1 − e^{−iΩτ̂}))) (static plant/model), |S(iΩ)| = 2|sin(Ωτ/2)| for an exact
// model — the classic predictor trades rejection for delay robustness. In the periodic form
// 1 − e^{−snT} vanishes at every harmonic kΩ, so m̂_1 = e^{−iΩ(nT−τ̂)} m_1 and S(iΩ) = 0 for ANY model error;
// the measurement is delayed by nT − τ̂ (an advance by τ̂ for T-periodic signals).
//
// Time-domain realisation (finite bank): bank state z (ż = A z + b m̂, w = K c_rᵀ z, oscillator_bank.hpp),
// model state ŷ for the first-order model (dŷ/dt = −γ̂ ŷ + u; static model ŷ = u/γ̂), two delay lines:
//   m̂(t) = m(t − measurement_delay()) + ŷ(t) − ŷ(t − correction_delay()).
#include <complex>
#include <variant>

#include "afmkit/control/infinite_bank.hpp"
#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/plant.hpp"
#include "afmkit/control/state_space.hpp"

namespace afmkit::control {

/// The controller inside a loop without prediction: finite bank (eq. 15) or N = ∞ bank (eq. 31).
using Bank = std::variant<OscillatorBank, InfiniteBank>;

struct SmithPredictor {
  enum class Structure { Periodic, Classic };

  Bank bank;              // C(s)
  PlantKind model_kind;   // kind of P̂0 (static 1/γ̂ or first order 1/(s+γ̂))
  double model_rate;      // γ̂ > 0
  double model_delay;     // τ̂ ≥ 0
  Structure structure;

  /// Validated: model_rate > 0 finite, model_delay ≥ 0 finite.
  SmithPredictor(Bank bank, PlantKind model_kind, double model_rate, double model_delay,
                 Structure structure = Structure::Periodic);

  double rotation_frequency() const;  // Ω of the bank
  double gain() const;                // K of the bank
  double period() const;              // T = 2π/Ω
  /// n = ⌈τ̂/T⌉ (periodic structure; 0 for τ̂ = 0). Classic: 0.
  int model_periods() const;
  /// Delay applied to m before it enters the bank: nT − τ̂ (periodic), 0 (classic).
  double measurement_delay() const;
  /// Delay of the model-correction term: nT (periodic), τ̂ (classic).
  double correction_delay() const;
  /// P̂0(s): 1/γ̂ or 1/(s + γ̂).
  std::complex<double> model(std::complex<double> s) const;
};

/// State-space pieces of a Smith predictor around a FINITE bank (InvalidParameter("bank") for N = ∞):
///   m̂(t) = m(t − measurement_delay) + ŷ(t) − ŷ(t − correction_delay),   ŷ = model(u),   w = bank(m̂),   u = −w,
/// so that W/M = bank(s) e^{−sτ_m} / (1 + bank(s) model(s) (1 − e^{−sτ_c})) = controller_response (loop.hpp).
struct SmithRealisation {
  StateSpace bank;           // m̂ → w (= −u): ss(bank), docs/theory-control.md#oscillator-bank
  StateSpace model;          // u → ŷ: P̂0 = 1/γ̂ (static gain) or dŷ/dt = −γ̂ ŷ + u
  double measurement_delay;  // τ_m
  double correction_delay;   // τ_c
};
SmithRealisation smith_realisation(const SmithPredictor& predictor);

}  // namespace afmkit::control
