// AM-AFM force reconstruction: the equivalent frequency shift of the in-phase balance inverted by the method the
// user picks, the dissipation as a branch difference, the round trip through exact orbits (reconstruct_am.hpp).
#include "afmkit/spectroscopy/reconstruct_am.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/spectroscopy/reconstruct_law.hpp"
#include "reconstruct_am_round_trip.hpp"
#include "afmkit/tapping/cantilever_limits.hpp"
#include "reconstruct_checks.hpp"

namespace afmkit::spectroscopy {

const char* to_string(AmMethod method) {
  switch (method) {
    case AmMethod::katan: return "katan";
    case AmMethod::hoelscher: return "hoelscher";
    default: return "payam";
  }
}

AmMethod am_method_from(const std::string& name) {
  if (name == "katan") return AmMethod::katan;
  if (name == "payam") return AmMethod::payam;
  if (name == "hoelscher") return AmMethod::hoelscher;
  throw InvalidParameter("method", fmt::format("method = '{}' is not an AM method: one of katan, payam, hoelscher", name));
}

AmSettings::AmSettings(double k, double f0, double q, double a0, double f)
    : spring_constant(k), resonance_frequency(f0), quality_factor(q), free_amplitude(a0),
      drive_frequency(f == 0.0 ? f0 : f) {
  tapping::check_cantilever_setting("spring_constant", tapping::CantileverSetting::spring_constant, k);
  tapping::check_cantilever_setting("resonance_frequency", tapping::CantileverSetting::resonance_frequency, f0);
  tapping::check_cantilever_setting("quality_factor", tapping::CantileverSetting::quality_factor, q);
  tapping::check_cantilever_setting("free_amplitude", tapping::CantileverSetting::amplitude, a0);
  tapping::check_cantilever_setting("drive_frequency", tapping::CantileverSetting::resonance_frequency,
                                    drive_frequency);
}

namespace {
/// The Sader–Jarvis terms of each method (docs/reconstruction.md#am).
SaderJarvisTerms terms_of(AmMethod m) {
  switch (m) {
    case AmMethod::katan: return {true, false};      // local amplitude in front of dΩ/dt
    case AmMethod::hoelscher: return {false, true};  // large-amplitude limit: −√2 d/dD ∫ γ/√(t − D), γ = k A^{3/2} Ω
    default: return {true, true};                    // amplitude inside the derivative: d(A^{3/2} Ω)/dt
  }
}
/// The equivalent Ω each method inverts (docs/reconstruction.md#am). payam and hoelscher: the first-order Ω_eq,
/// linear in the virial, which the Sader–Jarvis/Abel integrals invert. katan: the frequency of the equivalent FM
/// oscillator, Ω = √(1 + (A0/(Q A)) cos φ) − 1 at r = 1 (Katan, van Es & Oosterkamp 2009), i.e. √(1 + 2 Ω_eq) − 1;
/// it differs from Ω_eq at second order (−Ω_eq²/2).
double method_frequency_shift(double a, double phase, const AmSettings& s, AmMethod m) {
  const double omega = equivalent_frequency_shift(a, phase, s);
  if (m != AmMethod::katan) return omega;
  // 1 + 2 Ω_eq = (ω_eq/ω0)² of the equivalent oscillator: ≤ 0 means no real frequency (refused as a numerical
  // failure by the caller's check of finite values)
  const double x = 2.0 * omega;
  return x / (std::sqrt(1.0 + x) + 1.0);  // √(1 + x) − 1 without cancellation
}

/// The points whose lower turning point D = l − A increases with l (from the free end inwards), at least 1/2000
/// of the range of D apart; l ascending.
std::vector<std::size_t> used_points(const std::vector<double>& l, const std::vector<double>& a) {
  const std::size_t n = l.size();
  double d_lo = std::numeric_limits<double>::infinity(), d_hi = -d_lo;
  for (std::size_t i = 0; i < n; ++i) {
    d_lo = std::min(d_lo, l[i] - a[i]);
    d_hi = std::max(d_hi, l[i] - a[i]);
  }
  const double min_step = (d_hi - d_lo) / 2000.0;
  std::vector<std::size_t> kept;
  double d_last = std::numeric_limits<double>::infinity();
  for (std::size_t i = n; i-- > 0;) {
    const double d = l[i] - a[i];
    if (d < d_last - min_step) {
      kept.push_back(i);
      d_last = d;
    }
  }
  std::reverse(kept.begin(), kept.end());
  return kept;
}

/// Linear interpolation of (x, y) (x ascending) at t, constant beyond the ends.
double interpolate(const std::vector<double>& x, const std::vector<double>& y, double t) {
  if (t <= x.front()) return y.front();
  if (t >= x.back()) return y.back();
  const std::size_t j = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), t) - x.begin());
  const double w = (t - x[j - 1]) / (x[j] - x[j - 1]);
  return y[j - 1] + w * (y[j] - y[j - 1]);
}
}  // namespace

AmReconstruction reconstruct_am(const AmCurve& curve, const AmSettings& s, const AmOptions& options) {
  const std::size_t n = curve.separation.size();
  if (curve.amplitude.size() != n || curve.phase.size() != n)
    throw InvalidParameter("amplitude", fmt::format("the curve has {} separations, {} amplitudes and {} phases: one "
                                                    "of each per point",
                                                    n, curve.amplitude.size(), curve.phase.size()));
  if (n < 5) throw InvalidParameter("separation", fmt::format("the curve has {} points: at least 5 are needed", n));
  detail::require_finite("separation", curve.separation);
  detail::require_finite("amplitude", curve.amplitude);
  detail::require_finite("phase", curve.phase);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(curve.amplitude[i] > 0.0))
      throw InvalidParameter("amplitude", fmt::format("amplitude[{}] = {} m is out of range: must be > 0", i,
                                                      curve.amplitude[i]));
    if (!(curve.phase[i] > 0.0 && curve.phase[i] < std::numbers::pi))
      throw InvalidParameter("phase", fmt::format("phase[{}] = {} rad ({}°) is out of range: must be in (0, π) rad, "
                                                  "the lag of the response behind the drive (afmkit's convention, "
                                                  "docs/conventions.md; π/2 for the free cantilever at resonance)",
                                                  i, curve.phase[i], curve.phase[i] * 180.0 / std::numbers::pi));
  }
  if (options.method == AmMethod::katan)
    for (std::size_t i = 0; i < n; ++i)
      if (!(1.0 + 2.0 * equivalent_frequency_shift(curve.amplitude[i], curve.phase[i], s) > 0.0))
        throw InvalidParameter("phase", fmt::format("phase[{}] = {}° with amplitude[{}] = {} m has no equivalent "
                                                    "oscillator for method katan: 1 + (A0/(Q A)) cos φ must be > 0 "
                                                    "(the amplitude is below A0/Q; use payam or hoelscher)",
                                                    i, curve.phase[i] * 180.0 / std::numbers::pi, i,
                                                    curve.amplitude[i]));
  if (options.round_trip_points < 0 || options.round_trip_points == 1 || options.round_trip_points > 100000)
    throw InvalidParameter("round_trip_points", fmt::format("round_trip_points = {} is out of range: 0 (all) or an "
                                                            "integer in [2, 100000]",
                                                            options.round_trip_points));
  const auto order = detail::monotone_order("separation", curve.separation);

  AmReconstruction r;
  r.method = to_string(options.method);
  r.separation = detail::permuted(curve.separation, order);
  r.amplitude = detail::permuted(curve.amplitude, order);
  r.phase = detail::permuted(curve.phase, order);
  return computed("force reconstruction (AM)", [&] {
    for (std::size_t i = 0; i < n; ++i) r.dissipation.push_back(dissipated_energy(r.amplitude[i], r.phase[i], s));
    // the points whose lower turning point D = l − A increases with l (from the free end inwards), at least
    // 1/2000 of the range of D apart: nearly coincident D (the repulsive regime, dense sampling) would turn the
    // orbits' or the instrument's noise into huge derivatives
    const std::vector<std::size_t> kept = used_points(r.separation, r.amplitude);
    r.dropped = n - kept.size();
    if (kept.size() < 5)
      throw InvalidParameter("separation", fmt::format("only {} points have a lower turning point D = l − A that "
                                                       "increases with l: at least 5 are needed",
                                                       kept.size()));
    std::vector<double> amp;
    for (std::size_t i : kept) {
      r.gap.push_back(r.separation[i] - r.amplitude[i]);
      amp.push_back(r.amplitude[i]);
      r.omega.push_back(method_frequency_shift(r.amplitude[i], r.phase[i], s, options.method));
      r.gap_dissipation.push_back(r.dissipation[i]);
    }
    ExponentialTail tail;
    if (options.tail == TailModel::exponential) {
      tail = fit_exponential_tail(r.gap, r.omega);
      if (!tail.active)
        r.notes.push_back("tail = exponential: the last points do not decay exponentially; the equivalent Δf is "
                          "taken as 0 beyond the last point instead");
    }
    r.force = sader_jarvis_force(r.gap, r.omega, amp, s.spring_constant, terms_of(options.method), tail);

    // dissipation → branch difference over the contact part
    double e_max = 0.0;
    for (double e : r.gap_dissipation) e_max = std::max(e_max, e);
    // below the noise of E_dis, 0.1 % of its largest value, or what a phase error of 2e-4 rad makes of the drive
    // work π k A0²/Q: no dissipation
    const double drive_work = std::numbers::pi * s.spring_constant * s.free_amplitude * s.free_amplitude / s.quality_factor;
    const double threshold = std::max({3.0 * estimate_noise(r.gap_dissipation), 1e-3 * e_max, 2e-4 * drive_work});
    std::vector<double> delta = branch_difference(r.gap, r.gap_dissipation, threshold, r.contact_gap);
    // E_dis < 0 beyond the same threshold: a conservative curve gives E_dis = 0 up to the rounding of
    // A0 sin φ − A (a difference of nearly equal numbers), which is no sign of a wrong setting
    std::size_t negative = 0;
    for (double e : r.dissipation)
      if (e < -threshold) ++negative;
    // the same difference at the three deepest points: both branches then have the same end slope, and their
    // straight continuations below the table stay parallel (the law dissipates there too, never creates energy)
    const double deep = (delta[0] + delta[1] + delta[2]) / 3.0;
    delta[0] = delta[1] = delta[2] = deep;
    for (std::size_t i = 0; i < r.gap.size(); ++i) {
      r.approach_force.push_back(r.force[i] + 0.5 * delta[i]);
      r.retract_force.push_back(r.force[i] - 0.5 * delta[i]);
    }
    {
      // the law: the points used, and an exponential tail continued over 10 λ (F decays as Ω_eq does)
      std::vector<double> lz = r.gap, la = r.approach_force, lr = r.retract_force;
      if (tail.active)
        for (int k = 1; k <= 20; ++k) {
          const double x = r.gap.back() + 0.5 * k * tail.decay_length;
          const double f = r.force.back() * std::exp(-(x - r.gap.back()) / tail.decay_length);
          lz.push_back(x);
          la.push_back(f);
          lr.push_back(f);
        }
      r.law = force_curve_from_si(lz, la, lr, "reconstructed force");
    }
    bool dissipative = true;
    try {
      impact::TableLaw(r.law, false).require_dissipative();
    } catch (const InvalidParameter& e) {
      dissipative = false;
      r.notes.push_back(fmt::format("the interpolated branches cross (the retract force exceeds the approach force "
                                    "somewhere): the law needs allow_energy_gain to be used ({})",
                                    e.what()));
    }

    // notes: ill-posedness and what was assumed
    if (r.dropped > 0)
      r.notes.push_back(fmt::format("{} of {} points left out: the lower turning point D = l − A did not increase "
                                    "with l there by 1/2000 of its range (the tip barely indents in the repulsive "
                                    "regime, or the response jumped between branches)",
                                    r.dropped, n));
    if (negative > 0)
      r.notes.push_back(fmt::format("{} points dissipate less than the free cantilever (E_dis < 0: a phase offset, a "
                                    "wrong Q or A0, or a phase convention other than afmkit's lag): set to 0",
                                    negative));
    const double a_ratio_far = r.amplitude.back() / s.free_amplitude;
    if (std::abs(a_ratio_far - 1.0) > 0.02)
      r.notes.push_back(fmt::format("the curve does not reach the free region: A/A0 = {:.3f} at the largest "
                                    "separation; the force is biased near the end of the curve",
                                    a_ratio_far));
    double a_min = amp.front(), a_max = amp.front();
    for (double a : amp) a_min = std::min(a_min, a), a_max = std::max(a_max, a);
    if (options.method == AmMethod::katan) {
      // the amplitude outside the derivative: biased where A changes faster than D (the term (1/√2) Ω dA^{3/2}/dD
      // that payam keeps and katan drops)
      double rate = 0.0;
      for (std::size_t i = 0; i + 1 < amp.size(); ++i)
        rate = std::max(rate, std::abs(amp[i + 1] - amp[i]) / (r.gap[i + 1] - r.gap[i]));
      if (rate > 1.0)
        r.notes.push_back(fmt::format("the amplitude changes up to {:.3g} times faster than the lower turning point "
                                      "D: katan (amplitude outside the derivative) is biased there; payam keeps the "
                                      "amplitude inside it",
                                      rate));
    }
    if (options.method == AmMethod::hoelscher) {
      // interaction length: where |Ω| falls to 1/e of its largest value
      std::size_t peak = 0;
      for (std::size_t i = 1; i < r.omega.size(); ++i)
        if (std::abs(r.omega[i]) > std::abs(r.omega[peak])) peak = i;
      double length = std::numeric_limits<double>::quiet_NaN();
      for (std::size_t i = peak; i < r.omega.size(); ++i)
        if (std::abs(r.omega[i]) < std::abs(r.omega[peak]) / std::numbers::e) {
          length = r.gap[i] - r.gap[peak];
          break;
        }
      if (!(a_min > 10.0 * length))
        r.notes.push_back(fmt::format("the large-amplitude limit (hoelscher) needs A ≫ the interaction length: A "
                                      "goes down to {}, the interaction length is {}",
                                      io::quantity(a_min, "m"), io::quantity(length, "m")));
    }
    // noise: estimated in A and φ along the measured (evenly stepped) separations, propagated through the whole
    // inversion (D = l − A, the points used, Ω_eq, the integral) by 8 synthetic realisations with a fixed seed
    const double noise_a = estimate_noise(r.amplitude), noise_p = estimate_noise(r.phase);
    r.force_uncertainty.assign(r.gap.size(), 0.0);
    if (noise_a > 0.0 || noise_p > 0.0) {
      std::mt19937_64 rng(1);
      std::normal_distribution<double> na(0.0, noise_a > 0.0 ? noise_a : 1e-300), np(0.0, noise_p > 0.0 ? noise_p : 1e-300);
      const int realisations = 8;
      for (int k = 0; k < realisations; ++k) {
        std::vector<double> a2 = r.amplitude, p2 = r.phase;
        for (double& v : a2) v = std::max(v + na(rng), 1e-3 * v);
        for (double& v : p2) v = std::clamp(v + np(rng), 1e-6, std::numbers::pi - 1e-6);
        const auto kept2 = used_points(r.separation, a2);
        if (kept2.size() < 5) continue;
        std::vector<double> g2, o2, amp2;
        for (std::size_t i : kept2) {
          g2.push_back(r.separation[i] - a2[i]);
          amp2.push_back(a2[i]);
          o2.push_back(method_frequency_shift(a2[i], p2[i], s, options.method));
        }
        const auto f2 = sader_jarvis_force(g2, o2, amp2, s.spring_constant, terms_of(options.method), tail);
        for (std::size_t i = 0; i < r.gap.size(); ++i) {
          const double d = interpolate(g2, f2, r.gap[i]) - r.force[i];
          r.force_uncertainty[i] += d * d / realisations;
        }
      }
      for (double& u : r.force_uncertainty) u = std::sqrt(u);
    }
    double f_abs = 0.0, sigma_max = 0.0;
    for (std::size_t i = 0; i < r.force.size(); ++i) {
      f_abs = std::max(f_abs, std::abs(r.force[i]));
      sigma_max = std::max(sigma_max, r.force_uncertainty[i]);
    }
    if (sigma_max > 0.05 * f_abs)
      r.notes.push_back(fmt::format("noisy data: the noise estimated in the amplitude ({}) and phase ({:.2g}°) makes "
                                    "the force uncertain by up to {} (1σ, {:.0f} % of its largest value): the "
                                    "inversion differentiates the data, and D = l − A moves with the amplitude's noise",
                                    io::quantity(noise_a, "m"), noise_p * 180.0 / std::numbers::pi,
                                    io::quantity(sigma_max, "N"), 100.0 * sigma_max / f_abs));

    if (options.round_trip) {
      am_round_trip(r, s, dissipative, options.round_trip_points);
    } else {
      const double nan = std::numeric_limits<double>::quiet_NaN();
      r.rms_amplitude_ratio = r.rms_phase = nan;
    }
    return r;
  });
}

}  // namespace afmkit::spectroscopy
