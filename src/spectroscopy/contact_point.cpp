#include "afmkit/spectroscopy/contact_point.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::spectroscopy {

const char* to_string(ContactMethod method) {
  switch (method) {
    case ContactMethod::threshold: return "threshold";
    case ContactMethod::dmt: return "dmt";
    case ContactMethod::hertz: break;
  }
  return "hertz";
}

ContactPoint find_contact_point(const std::vector<double>& x, const std::vector<double>& force, double sigma,
                                const ContactPointOptions& options, const std::string& origin) {
  if (!(options.noise_multiple > 0 && std::isfinite(options.noise_multiple)))
    throw InvalidParameter("noise_multiple",
                           fmt::format("noise_multiple = {} is out of range: must be > 0", options.noise_multiple));
  const std::size_t n = x.size();
  const double band = options.noise_multiple * sigma;
  const std::size_t top =
      static_cast<std::size_t>(std::max_element(force.begin(), force.end()) - force.begin());  // deepest
  // threshold: out from the deepest sample to the first one inside the band
  std::size_t j = top;
  while (j > 0 && force[j] > band) --j;
  // a contact is a rise: at least 3 consecutive samples above the band (a noise spike is not)
  const std::size_t run = force[j] > band ? top - j + 1 : top - j;
  if (run < 3)
    throw InputError(fmt::format("{}: the approach never rises above the noise band (largest force {:.4g} nN, {} "
                                 "consecutive samples above {} σ = {:.4g} nN; a contact needs 3): the tip did not reach "
                                 "the sample",
                                 origin, force[top] * 1e9, run, options.noise_multiple, band * 1e9));
  ContactPoint cp;
  cp.method = options.method;
  double xt = x[j];
  if (force[j] <= band && j < top) {
    const double w = (band - force[j]) / (force[j + 1] - force[j]);
    xt = x[j] + w * (x[j + 1] - x[j]);
  }
  // local slope dF/dx of the rise at the crossing: least squares over the samples from the crossing in to where the
  // force reaches 3 n·σ (at least 3 samples)
  const std::size_t a = std::min(j + 1, top);
  std::size_t b = a;
  while (b < top && (force[b] < 3 * band || b < a + 2)) ++b;
  double sx = 0, sf = 0, sxx = 0, sxf = 0, m = 0;
  for (std::size_t i = j; i <= b; ++i) {
    sx += x[i]; sf += force[i]; sxx += x[i] * x[i]; sxf += x[i] * force[i]; m += 1;
  }
  const double det = m * sxx - sx * sx;
  double slope = det > 0 ? (m * sxf - sx * sf) / det : 0.0;
  if (!(std::abs(slope) > 0) && x[top] != xt) slope = (force[top] - band) / (x[top] - xt);
  cp.threshold_position = xt;
  cp.position = xt;
  // a sample's noise moves it along the slope k (x = z + d, F = k·d): the crossing moves by σ/|F'| + σ/k
  const double k = options.spring_constant;
  cp.error = (std::abs(slope) > 0 ? sigma / std::abs(slope) : std::abs(x[top] - xt)) +
             (std::isfinite(k) && k > 0 ? sigma / k : 0.0);
  if (options.method == ContactMethod::threshold) return cp;

  // fit range (docs/spectroscopy.md#contact-point): Hertz: from the deepest sample out to as far beyond the
  // threshold point as the indentation goes in; DMT: the samples inside the approach's force minimum (the bottom
  // of the adhesion well before the repulsive rise)
  std::vector<double> fx, ff;
  fx.reserve(n);
  ff.reserve(n);
  const double deepest = x[top];
  if (options.method == ContactMethod::hertz) {
    const double limit = xt + std::max(xt - deepest, 0.0);
    for (std::size_t i = 0; i < n; ++i)
      if (x[i] <= limit) { fx.push_back(x[i]); ff.push_back(force[i]); }
  } else {
    const std::size_t lowest =
        static_cast<std::size_t>(std::min_element(force.begin(), force.begin() + static_cast<long>(top) + 1) - force.begin());
    const double limit = lowest < top ? x[lowest] : xt;
    for (std::size_t i = 0; i < n; ++i)
      if (x[i] < limit) { fx.push_back(x[i]); ff.push_back(force[i]); }
  }
  HertzFitOptions fit_options = options.fit;
  fit_options.model = options.method == ContactMethod::dmt ? ContactModel::dmt : ContactModel::hertz;
  try {
    cp.fit = fit_hertz(fx, ff, xt, fit_options);
  } catch (const NumericalFailure& e) {
    throw NumericalFailure(fmt::format("{}: contact point: {} (contact_method threshold needs no fit)", origin,
                                       e.what()));
  }
  cp.position = cp.fit->contact_point;
  cp.error = cp.fit->contact_point_error;
  return cp;
}

}  // namespace afmkit::spectroscopy
