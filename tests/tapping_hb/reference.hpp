#pragma once
// Independent reference computations for the harmonic-balance tests (no closed forms used):
//  * describing functions by adaptive Gauss–Kronrod quadrature of eq. (12) with the actual nonlinearity
//    h(x, ẋ) = TappingModel::interaction (the impact module's force law), split where the gap crosses a switching
//    gap of the law; and by tanh_sinh for any law;
//  * a damped Newton solve of the balance equations (17) with those quadrature describing functions.
#include <complex>
#include <optional>
#include <vector>

#include "afmkit/tapping/model.hpp"

namespace afmkit::tapping::test {

struct QuadratureDf {
  double mean;                   // N0·A = (1/T)∫h dt
  std::complex<double> first;    // N1 = (2/(TB))∫h e^{−iωt} dt
};

/// Quadrature of eq. (12) for x = A + B cos θ at model.separation (split where the gap crosses a switching gap).
QuadratureDf quadrature_df(const TappingModel& model, double offset, double amplitude);

/// The same by Boost tanh_sinh (endpoint singularities such as (a0 − d)^{3/2} need no change of variable) over
/// [0, 2π] split at the switching angles (located by bisection) and at π, with h = −law.force(d, ḋ) directly:
/// an independent reference for any law, including the Kelvin–Voigt velocity term.
QuadratureDf tanh_sinh_df(const impact::ForceLaw& law, double mean_gap, double amplitude, double frequency);

/// Scaled residual of (17): [(A + L(0)⟨h⟩)/(ΓL(0)), Re, Im of (B(L(iω)⁻¹ + N1) − Γe^{iφ})/Γ].
std::vector<double> balance_residual(const TappingModel& model, double offset, double amplitude, double phase);

struct NewtonSolution {
  double offset, amplitude, phase;  // phase wrapped to (−π, π]
  double residual;                  // max |scaled residual|
};
/// Damped Newton with a finite-difference Jacobian from (A, B, φ); nullopt if no convergence to 1e-11.
std::optional<NewtonSolution> newton_solve(const TappingModel& model, double offset, double amplitude, double phase);

}  // namespace afmkit::tapping::test
