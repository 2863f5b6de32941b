#include "afmkit/spectroscopy/calibration.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/cantilever_limits.hpp"

namespace afmkit::spectroscopy {

namespace {

using io::curves::Segment;
using io::curves::SegmentKind;

/// The kind of a segment: the file's, or from the height's direction (approach: z decreases).
SegmentKind kind_of(const Segment& s) {
  if (s.kind != SegmentKind::unknown || s.height.size() < 2) return s.kind;
  return s.height.back() < s.height.front() ? SegmentKind::approach : SegmentKind::retract;
}

void require_finite(const std::vector<double>& v, const char* channel, const char* what, const std::string& origin) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw InputError(fmt::format("{}: the {} segment's {} is not finite at sample {} ({})", origin, what, channel,
                                   i + 1, v[i]));
}

/// A piezo height that goes back against the segment's direction by more than 1 % of its range is not one
/// approach (or retract): refused.
void require_monotone(const std::vector<double>& z, bool decreasing, const char* what, const std::string& origin) {
  const auto [lo, hi] = std::minmax_element(z.begin(), z.end());
  const double range = *hi - *lo;
  if (!(range > 0))
    throw InputError(fmt::format("{}: the {} segment's piezo height does not move (constant {} m)", origin, what,
                                 z.front()));
  double extreme = z.front();
  for (std::size_t i = 1; i < z.size(); ++i) {
    extreme = decreasing ? std::min(extreme, z[i]) : std::max(extreme, z[i]);
    const double back = decreasing ? z[i] - extreme : extreme - z[i];
    if (back > 0.01 * range)
      throw InputError(fmt::format(
          "{}: the {} segment's piezo height is not monotone: at sample {} it goes back by {:.4g} nm ({:.2g} % of "
          "its range) — it must {} throughout the segment",
          origin, what, i + 1, back * 1e9, 100 * back / range, decreasing ? "decrease (approach the sample)"
                                                                          : "increase (leave the sample)"));
  }
}

}  // namespace

CalibratedCurve calibrate(const io::curves::RawCurve& raw, const Calibration& user) {
  CalibratedCurve out;
  out.origin = raw.origin.empty() ? std::string("curve") : raw.origin;
  const Segment* approach = nullptr;
  const Segment* retract = nullptr;
  for (const Segment& s : raw.segments) {
    const SegmentKind kind = kind_of(s);
    if (kind == SegmentKind::approach && approach == nullptr) approach = &s;
    else if (kind == SegmentKind::retract && approach != nullptr && retract == nullptr) retract = &s;
    else if (kind == SegmentKind::approach || kind == SegmentKind::retract)
      out.notes.push_back(fmt::format("a further {} segment was ignored", io::curves::to_string(kind)));
  }
  if (approach == nullptr)
    throw InputError(fmt::format("{}: the curve has no approach segment (a segment whose height decreases)", out.origin));
  if (retract == nullptr)
    throw InputError(fmt::format("{}: the curve has no retract part (no segment after the approach whose height "
                                 "increases); a force curve needs both to make a table law",
                                 out.origin));

  // k: needed always (F = k·d, or d = F/k); InvOLS: only for a segment with the detector signal alone
  const bool user_k = std::isfinite(user.spring_constant), user_s = std::isfinite(user.invols);
  // the range of tapping/cantilever_limits.hpp (the command line and the fit's settings take the same)
  if (!std::isnan(user.spring_constant))
    tapping::check_cantilever_setting("spring_constant", tapping::CantileverSetting::spring_constant,
                                      user.spring_constant);
  if (!std::isnan(user.invols) && !(user.invols > 0 && std::isfinite(user.invols)))
    throw InvalidParameter("invols", fmt::format("invols = {} m/V is out of range: must be > 0", user.invols));
  const double k = user_k ? user.spring_constant : raw.metadata.spring_constant;
  if (std::isnan(k))
    throw InvalidParameter("spring_constant", fmt::format("{}: the file gives no spring constant: give it with "
                                                          "--spring-constant (N/m)", out.origin));
  const tapping::CantileverLimit k_max = tapping::cantilever_limit(tapping::CantileverSetting::spring_constant);
  if (!(k > 0) || !(k <= k_max.upper))
    throw InvalidParameter("spring_constant", fmt::format("{}: the file's spring constant {} {} is out of range "
                                                          "(must be > 0 and <= {:g} {}): give the right one with "
                                                          "--spring-constant", out.origin, k, k_max.unit.name,
                                                          k_max.upper, k_max.unit.name));
  out.spring_constant = k;
  out.spring_constant_source = user_k ? "option" : "file";

  auto convert = [&](const Segment& s, const char* what, bool decreasing) {
    ForceSegment f;
    const std::size_t n = s.height.size();
    if (n < 2) throw InputError(fmt::format("{}: the {} segment has {} samples of height (needs ≥ 2)", out.origin, what, n));
    require_finite(s.height, "height", what, out.origin);
    require_monotone(s.height, decreasing, what, out.origin);
    f.height = s.height;
    auto same_length = [&](const std::vector<double>& v, const char* channel) {
      if (v.size() != n)
        throw InputError(fmt::format("{}: the {} segment's {} has {} samples, its height {}", out.origin, what,
                                     channel, v.size(), n));
      require_finite(v, channel, what, out.origin);
    };
    if (!s.deflection.empty()) {
      same_length(s.deflection, "deflection");
      f.deflection = s.deflection;
    } else if (!s.deflection_volts.empty()) {
      same_length(s.deflection_volts, "deflection signal");
      double invols = user_s ? user.invols : raw.metadata.invols;
      if (std::isnan(invols))
        throw InvalidParameter("invols", fmt::format("{}: the file gives the deflection in volts but no InvOLS: give "
                                                     "it with --invols", out.origin));
      if (!(invols > 0) || !std::isfinite(invols))
        throw InvalidParameter("invols", fmt::format("{}: the file's InvOLS {} m/V is out of range (must be > 0): "
                                                     "give the right one with --invols", out.origin, invols));
      out.invols = invols;
      out.invols_source = user_s ? "option" : "file";
      f.deflection.resize(n);
      for (std::size_t i = 0; i < n; ++i) f.deflection[i] = invols * s.deflection_volts[i];
    } else if (!s.force.empty()) {
      same_length(s.force, "force");
      f.force = s.force;
      f.deflection.resize(n);
      for (std::size_t i = 0; i < n; ++i) f.deflection[i] = s.force[i] / k;
      return f;
    } else {
      throw InputError(fmt::format("{}: the {} segment has no deflection, deflection signal or force", out.origin, what));
    }
    f.force.resize(n);
    for (std::size_t i = 0; i < n; ++i) f.force[i] = k * f.deflection[i];
    return f;
  };
  out.approach = convert(*approach, "approach", true);
  out.retract = convert(*retract, "retract", false);
  return out;
}

}  // namespace afmkit::spectroscopy
