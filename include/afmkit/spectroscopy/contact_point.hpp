#pragma once
// Step 3 of preparing a measured force curve (docs/spectroscopy.md#contact-point): where the tip meets the sample,
// as a tip position x_c = z + d [m], with its uncertainty.
//   threshold: going out from the deepest sample of the approach, the first sample whose force is within the noise
//              band (F ≤ n·σ); x_c is where the straight line through it and the next sample in crosses n·σ; its
//              uncertainty σ/|dF/dx| + σ/k there (a sample's noise moves it along the slope k: x = z + d, F = k·d).
//              Biased into the sample by the indentation at which the force reaches n·σ.
//   hertz, dmt: the threshold point refined by the Hertz (or DMT) fit of the approach (hertz_fit.hpp); uncertainty
//              the fit's standard error of x_c.
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "afmkit/spectroscopy/hertz_fit.hpp"

namespace afmkit::spectroscopy {

enum class ContactMethod { threshold, hertz, dmt };
const char* to_string(ContactMethod method);

struct ContactPointOptions {
  ContactMethod method = ContactMethod::hertz;
  double noise_multiple = 3.0;  ///< n of the noise band n·σ
  HertzFitOptions fit;          ///< R, ν (model set from the method)
  /// k [N/m] (NaN: not known): the tip position x = z + d carries the deflection's noise σ/k too, which the
  /// threshold's uncertainty adds
  double spring_constant = std::numeric_limits<double>::quiet_NaN();
};

struct ContactPoint {
  ContactMethod method = ContactMethod::hertz;
  double position = 0;         ///< x_c [m]
  double error = 0;            ///< its standard uncertainty [m] (prepare: including baseline_error)
  double baseline_error = 0;   ///< prepare: the part of `error` that comes from the baseline's own uncertainty [m]
  double threshold_position = 0;  ///< the threshold estimate [m]
  std::optional<HertzFit> fit;    ///< hertz, dmt
};

/// The contact point of an approach (samples in recording order: tip position x = z + d [m], baseline-corrected
/// force F [N]) with force noise σ [N]. Throws InputError naming `origin` when the approach never rises above the
/// noise band (no contact: fewer than 3 consecutive samples above n·σ up to the deepest one, so that a noise spike
/// is no contact); InvalidParameter "noise_multiple" when n is not > 0; NumericalFailure when the fit fails.
ContactPoint find_contact_point(const std::vector<double>& position, const std::vector<double>& force, double sigma,
                                const ContactPointOptions& options, const std::string& origin);

}  // namespace afmkit::spectroscopy
