#include "afmkit/spectroscopy/prepare.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::spectroscopy {

const char* const law_columns[4] = {"approach distance (nm)", "approach force (nN)", "retract distance (nm)",
                                    "retract force (nN)"};

namespace {

/// span / 400 rounded down to 1, 2 or 5 × 10^k.
double automatic_bin_width(double span) {
  const double raw = span / 400.0;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  const double m = raw / decade;
  return (m >= 5 ? 5.0 : m >= 2 ? 2.0 : 1.0) * decade;
}

/// The largest bin centre whose mean force, and that of the bin before it, leave the band ±n·σ/√count on the same
/// side (two in a row: a lone noise excursion among hundreds of bins does not count) (−inf: none).
double interaction_range(const BinnedBranch& b, double band) {
  auto side = [&](std::size_t i) {
    const double limit = band / std::sqrt(static_cast<double>(b.count[i]));
    return b.force[i] > limit ? 1 : b.force[i] < -limit ? -1 : 0;
  };
  for (std::size_t i = b.size(); i-- > 1;)
    if (side(i) != 0 && side(i) == side(i - 1)) return b.centre[i];
  return -std::numeric_limits<double>::infinity();
}

/// Keeps the bins whose centre is ≤ limit (at least `minimum` when there are).
void keep_up_to(BinnedBranch& b, double limit, std::size_t minimum = 0) {
  std::size_t keep = 0;
  while (keep < b.size() && b.centre[keep] <= limit) ++keep;
  keep = std::max<std::size_t>(keep, std::min<std::size_t>(minimum, b.size()));
  b.distance.resize(keep);
  b.centre.resize(keep);
  b.force.resize(keep);
  b.force_error.resize(keep);
  b.count.resize(keep);
}

/// The baseline's own uncertainty (its level at the mean height and its slope, independent there) moves the contact
/// point and the modulus: found by preparing the contact point again with the baseline shifted by one standard error
/// of each (the whole procedure, threshold and fit range included), added in quadrature to their errors.
void propagate_baseline_error(ContactPoint& cp, const ForceSegment& approach, const std::vector<double>& x,
                              const BaselineFit& base, double k, const ContactPointOptions& options,
                              const std::string& origin) {
  double dx2 = 0, de2 = 0;
  for (const auto& [level, slope] : {std::pair{base.level_error, 0.0}, std::pair{0.0, base.slope_error}}) {
    if (level == 0 && slope == 0) continue;
    std::vector<double> f(approach.force), xs(x);
    for (std::size_t i = 0; i < f.size(); ++i) {
      const double shift = level + slope * (approach.height[i] - base.mean_height);
      f[i] -= shift;
      xs[i] -= shift / k;  // d = F/k follows the levelled force
    }
    try {
      const ContactPoint moved = find_contact_point(xs, f, base.residual_rms, options, origin);
      dx2 += (moved.position - cp.position) * (moved.position - cp.position);
      if (cp.fit && moved.fit)
        de2 += (moved.fit->youngs_modulus - cp.fit->youngs_modulus) * (moved.fit->youngs_modulus - cp.fit->youngs_modulus);
    } catch (const NumericalFailure&) {
      // the shifted fit fails where the fit itself succeeded: leave the fit's own errors
    }
  }
  cp.baseline_error = std::sqrt(dx2);
  cp.error = std::hypot(cp.error, cp.baseline_error);
  if (cp.fit) {
    cp.fit->contact_point_error = cp.error;
    if (std::isfinite(cp.fit->youngs_modulus_error))
      cp.fit->youngs_modulus_error = std::hypot(cp.fit->youngs_modulus_error, std::sqrt(de2));
  }
}

}  // namespace

PreparedCurve prepare(const std::vector<io::curves::RawCurve>& curves, const PrepareOptions& options) {
  if (curves.empty()) throw InputError("no force curve to prepare (the input holds none)");
  PreparedCurve out;
  std::vector<double> ad, af, rd, rf;  // pooled samples
  double noise2 = 0;
  for (const io::curves::RawCurve& raw : curves) {
    CalibratedCurve cal = calibrate(raw, options.calibration);
    CurvePreparation c;
    c.origin = cal.origin;
    c.spring_constant = cal.spring_constant;
    c.invols = cal.invols;
    c.spring_constant_source = cal.spring_constant_source;
    c.invols_source = cal.invols_source;
    c.notes = std::move(cal.notes);
    c.approach_raw_force = cal.approach.force;
    c.retract_raw_force = cal.retract.force;
    c.baseline = fit_baseline(cal.approach, options.baseline_fraction, options.baseline_min_points);
    subtract_baseline(cal.approach, c.baseline, cal.spring_constant);
    subtract_baseline(cal.retract, c.baseline, cal.spring_constant);
    std::vector<double> ax(cal.approach.size()), rx(cal.retract.size());
    for (std::size_t i = 0; i < ax.size(); ++i) ax[i] = cal.approach.height[i] + cal.approach.deflection[i];
    for (std::size_t i = 0; i < rx.size(); ++i) rx[i] = cal.retract.height[i] + cal.retract.deflection[i];
    ContactPointOptions contact = options.contact;
    contact.spring_constant = cal.spring_constant;
    c.contact = find_contact_point(ax, cal.approach.force, c.baseline.residual_rms, contact, c.origin);
    propagate_baseline_error(c.contact, cal.approach, ax, c.baseline, cal.spring_constant, contact, c.origin);
    if (c.contact.fit && c.contact.fit->residual_rms > 10 * c.baseline.residual_rms)
      c.notes.push_back(fmt::format(
          "the {} fit leaves residuals of {:.4g} nN RMS, {:.3g} times the noise: the model does not describe this "
          "contact (its E and contact point are doubtful; contact_method threshold assumes no model)",
          c.contact.fit->model == ContactModel::dmt ? "DMT" : "Hertz", c.contact.fit->residual_rms * 1e9,
          c.contact.fit->residual_rms / c.baseline.residual_rms));
    for (double& v : ax) v -= c.contact.position;
    for (double& v : rx) v -= c.contact.position;
    ad.insert(ad.end(), ax.begin(), ax.end());
    af.insert(af.end(), cal.approach.force.begin(), cal.approach.force.end());
    rd.insert(rd.end(), rx.begin(), rx.end());
    rf.insert(rf.end(), cal.retract.force.begin(), cal.retract.force.end());
    noise2 += c.baseline.residual_rms * c.baseline.residual_rms;
    c.approach_samples = cal.approach.size();
    c.retract_samples = cal.retract.size();
    c.approach_distance = std::move(ax);
    c.retract_distance = std::move(rx);
    c.approach = std::move(cal.approach);
    c.retract = std::move(cal.retract);
    out.curves.push_back(std::move(c));
  }
  out.noise = std::sqrt(noise2 / static_cast<double>(curves.size()));

  if (options.bin_width > 0 && std::isfinite(options.bin_width)) out.bin_width = options.bin_width;
  else if (options.bin_width == 0) {
    const auto [lo, hi] = std::minmax_element(ad.begin(), ad.end());
    out.bin_width = automatic_bin_width(*hi - *lo);
  } else {
    throw InvalidParameter("bin_width", fmt::format("bin_width = {} m is out of range: must be ≥ 0 (0: automatic)",
                                                    options.bin_width));
  }
  out.approach = bin_branch(ad, af, out.bin_width);
  out.retract = bin_branch(rd, rf, out.bin_width);
  const double band = options.contact.noise_multiple * out.noise;
  out.snap_in = adhesion_minimum(out.approach, band);
  out.pull_off = adhesion_minimum(out.retract, band);
  out.trimmed_at = std::numeric_limits<double>::infinity();
  if (options.trim_baseline) {
    const double range = std::max(interaction_range(out.approach, band), interaction_range(out.retract, band));
    if (std::isfinite(range)) {
      out.trimmed_at = range + 2 * out.bin_width;
      keep_up_to(out.approach, out.trimmed_at, 4);  // the trimming leaves a table law's 4 points
      keep_up_to(out.retract, out.trimmed_at, 4);
    }
  }
  // both branches end in the same bin, at its centre: above its table a branch is 0, so a branch ending earlier
  // would be compared with the other's (noisy, or attractive) values there
  if (out.approach.size() > 0 && out.retract.size() > 0) {
    const double end = std::min(out.approach.centre.back(), out.retract.centre.back());
    keep_up_to(out.approach, end);
    keep_up_to(out.retract, end);
    for (BinnedBranch* b : {&out.approach, &out.retract})
      if (b->centre.back() == end && (b->size() < 2 || (*b).distance[b->size() - 2] < end)) b->distance.back() = end;
    out.trimmed_at = std::min(out.trimmed_at, end);
  }
  for (auto [branch, what] : {std::pair{&out.approach, "approach"}, std::pair{&out.retract, "retract"}})
    if (branch->size() < 4)
      throw InvalidParameter("bin_width", fmt::format("bin_width = {:.4g} nm leaves the {} branch {} bins, fewer than "
                                                      "the 4 points a table law needs: give a smaller bin_width (or a curve with more samples near the contact)",
                                                      out.bin_width * 1e9, what, branch->size()));
  return out;
}

impact::ForceCurve to_force_curve(const PreparedCurve& p, const std::string& origin) {
  impact::ForceCurve c;
  c.origin = origin;
  auto nm = [](const std::vector<double>& v) {
    std::vector<double> o(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) o[i] = v[i] * 1e9;
    return o;
  };
  c.approach_gap = nm(p.approach.distance);
  c.approach_force = nm(p.approach.force);  // N → nN: the same factor
  c.retract_gap = nm(p.retract.distance);
  c.retract_force = nm(p.retract.force);
  return c;
}

}  // namespace afmkit::spectroscopy
