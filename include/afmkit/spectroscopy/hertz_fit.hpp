#pragma once
// Step 7 (and the contact point of step 3) of preparing a measured force curve (docs/spectroscopy.md#hertz-fit):
// the approach's contact part fitted by a paraboloid Hertz law
//     F = (4/3) E/(1 − ν²) √R δ^{3/2},   δ = max(0, x_c − x)        (Hertz 1882; paraboloid tip of radius R)
// where x = z + d is the tip position and x_c the contact point; DMT (Derjaguin–Muller–Toporov) adds a constant
// adhesion offset F0 (= −2πRw, fitted). Nonlinear least squares by Eigen's Levenberg–Marquardt (MINPACK lmder, from
// unsupported/Eigen/NonLinearOptimization) on scaled unknowns; standard errors from the covariance σ²(JᵀJ)⁻¹ with σ²
// the residual variance.
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace afmkit::spectroscopy {

enum class ContactModel { hertz, dmt };
const char* to_string(ContactModel model);

struct HertzFitOptions {
  ContactModel model = ContactModel::hertz;
  double tip_radius = std::numeric_limits<double>::quiet_NaN();  ///< R [m]; NaN: E is not computed
  double poisson_ratio = 0.5;                                     ///< ν of the sample
};

struct HertzFit {
  ContactModel model = ContactModel::hertz;
  double contact_point = 0, contact_point_error = 0;  ///< x_c and its standard error [m]
  double coefficient = 0, coefficient_error = 0;      ///< C = (4/3) E/(1 − ν²) √R [N/m^1.5]
  double offset = 0, offset_error = 0;                ///< F0 [N] (DMT; 0 for Hertz)
  double youngs_modulus = std::numeric_limits<double>::quiet_NaN();        ///< E [Pa] (R given)
  double youngs_modulus_error = std::numeric_limits<double>::quiet_NaN();  ///< its standard error [Pa]
  double residual_rms = 0;  ///< [N]
  std::size_t points = 0;   ///< samples fitted
  double position_from = 0, position_to = 0;  ///< the fitted range of the tip position [m]
  int evaluations = 0;      ///< model evaluations of the solver
  std::string solver_status;
};

/// Fits the model to the samples (tip position x [m], force F [N]) from the initial contact point `contact_guess`.
/// The caller chooses the samples (prepare: the approach inside the fit range of docs/spectroscopy.md). Throws
/// InvalidParameter "tip_radius" / "poisson_ratio" for R ≤ 0 or ν outside [0, 0.5], NumericalFailure naming the fit
/// when there are fewer samples than 2 × unknowns, when no sample is indented at the solution, or when the solver
/// fails.
HertzFit fit_hertz(const std::vector<double>& position, const std::vector<double>& force, double contact_guess,
                   const HertzFitOptions& options);

}  // namespace afmkit::spectroscopy
