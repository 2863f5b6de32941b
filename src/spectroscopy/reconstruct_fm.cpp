// FM-AFM force reconstruction and its round trip (reconstruct_fm.hpp, docs/reconstruction.md#fm).
#include "afmkit/spectroscopy/reconstruct_fm.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <boost/math/special_functions/bessel.hpp>
#include <fmt/format.h>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/io/quantity.hpp"
#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/spectroscopy/reconstruct_law.hpp"
#include "afmkit/tapping/fm.hpp"
#include "afmkit/tapping/units.hpp"
#include "afmkit/tapping/cantilever_limits.hpp"
#include "reconstruct_checks.hpp"

namespace afmkit::spectroscopy {

const char* to_string(FmMethod method) { return method == FmMethod::matrix ? "matrix" : "sader_jarvis"; }
const char* to_string(TailModel tail) { return tail == TailModel::exponential ? "exponential" : "zero"; }

FmMethod fm_method_from(const std::string& name) {
  if (name == "sader_jarvis") return FmMethod::sader_jarvis;
  if (name == "matrix") return FmMethod::matrix;
  throw InvalidParameter("method", fmt::format("method = '{}' is not an FM method: one of sader_jarvis, matrix", name));
}

TailModel tail_model_from(const std::string& name) {
  if (name == "zero") return TailModel::zero;
  if (name == "exponential") return TailModel::exponential;
  throw InvalidParameter("tail", fmt::format("tail = '{}' is not a tail model: one of zero, exponential", name));
}

FmSettings::FmSettings(double k, double f0, double a) : spring_constant(k), resonance_frequency(f0), amplitude(a) {
  tapping::check_cantilever_setting("spring_constant", tapping::CantileverSetting::spring_constant, k);
  tapping::check_cantilever_setting("resonance_frequency", tapping::CantileverSetting::resonance_frequency, f0);
  tapping::check_cantilever_setting("amplitude", tapping::CantileverSetting::amplitude, a);
}

double exponential_force_frequency_shift(double z, double f0_force, double lambda, const FmSettings& s) {
  const double a = s.amplitude;
  return -s.resonance_frequency * f0_force / (s.spring_constant * a) * std::exp(-(z + a) / lambda) *
         boost::math::cyl_bessel_i(1, a / lambda);
}

double inverse_square_force_frequency_shift(double z, double c, const FmSettings& s) {
  const double a = s.amplitude;
  return -s.resonance_frequency * c / (s.spring_constant * std::pow(z * (z + 2.0 * a), 1.5));
}

namespace {

/// F at the measured points for Ω (= Δf/f0) at the points, by the chosen method and tail.
std::vector<std::vector<double>> invert(const std::vector<double>& z, const std::vector<std::vector<double>>& omegas,
                                        const FmSettings& s, FmMethod method, const ExponentialTail& tail) {
  const std::size_t n = z.size();
  std::vector<std::vector<double>> out;
  if (method == FmMethod::sader_jarvis) {
    const std::vector<double> amp(n, s.amplitude);
    return sader_jarvis_forces(z, omegas, amp, s.spring_constant, {}, tail);
  }
  // matrix: the grid continued over the tail (2A + 10λ beyond the last point, at most 500 more nodes)
  std::vector<double> grid = z;
  std::vector<std::vector<double>> rhs = omegas;
  if (tail.active) {
    const double length = 2.0 * s.amplitude + 10.0 * tail.decay_length;
    const double h = std::max(z[n - 1] - z[n - 2], length / 500.0);
    for (double x = z.back() + h; x <= z.back() + length + 0.5 * h; x += h) {
      grid.push_back(x);
      const double v = tail.value * std::exp(-(x - z.back()) / tail.decay_length);
      for (std::size_t k = 0; k < rhs.size(); ++k) rhs[k].push_back(v * omegas[k].back() / tail.value);
    }
  }
  out = matrix_method_force(grid, rhs, s.amplitude, s.spring_constant);
  for (auto& f : out) f.resize(n);
  return out;
}

}  // namespace

namespace {

/// The round trip through afmkit's exact FM orbits (tapping::sweep_fm at the measured closest distances, the
/// table law in physical units nm and nN on the normalised cantilever ω_n = 1): Δf = (ω − 1)·f0.
void fm_exact_round_trip(FmReconstruction& r, const std::vector<double>& z, const FmSettings& s,
                         const FmOptions& options) {
  const std::size_t n = z.size();
  const tapping::PhysicalCantilever pc(s.spring_constant, s.resonance_frequency * 1e-3, options.quality_factor,
                                       s.amplitude * 1e9, 1.0);
  const impact::ForceLaw physical = impact::make_law<impact::TableLaw>(r.law, true);
  const tapping::FmSetting setting(pc.cantilever(), pc.normalised_law(physical), s.amplitude * 1e9);
  // the distances visited, largest first (an approach): every one, or `round_trip_points` evenly spread
  std::vector<std::size_t> visit;
  const std::size_t m = options.round_trip_points > 0 ? std::min<std::size_t>(n, options.round_trip_points) : n;
  for (std::size_t j = 0; j < m; ++j)
    visit.push_back(m == n ? j : static_cast<std::size_t>(std::llround(static_cast<double>(j) * (n - 1) / (m - 1))));
  visit.erase(std::unique(visit.begin(), visit.end()), visit.end());
  std::reverse(visit.begin(), visit.end());
  std::vector<double> targets;
  for (std::size_t i : visit) targets.push_back(z[i] * 1e9);
  tapping::FmSweepOptions o;
  o.axis = tapping::FmAxis::min_gap;
  const tapping::FmSweepResult sweep = tapping::sweep_fm(setting, targets, o);
  double sum2 = 0.0, mx = 0.0;
  std::size_t count = 0;
  for (std::size_t j = 0; j < visit.size(); ++j) {
    const tapping::FmPoint& point = sweep.points[j];
    if (point.status != tapping::FmStatus::converged || !point.orbit) continue;
    const std::size_t i = visit[j];
    r.round_trip_frequency_shift[i] = point.orbit->frequency_shift() * s.resonance_frequency;
    r.residual[i] = r.round_trip_frequency_shift[i] - r.frequency_shift[i];
    sum2 += r.residual[i] * r.residual[i];
    mx = std::max(mx, std::abs(r.residual[i]));
    ++count;
  }
  r.residual_rms = count ? std::sqrt(sum2 / static_cast<double>(count)) : std::numeric_limits<double>::quiet_NaN();
  r.residual_max = count ? mx : std::numeric_limits<double>::quiet_NaN();
  r.round_trip_orbits = static_cast<int>(count);
  r.round_trip_simulations = sweep.evaluations;
  r.round_trip_model = fmt::format("exact FM orbits of the table law (tapping fm: self-excited cantilever, ideal "
                                   "loops, Q = {:g}) at {} of the {} measured distances",
                                   options.quality_factor, count, n);
  if (count < visit.size())
    r.notes.push_back(fmt::format("the round trip found no FM orbit at {} of the {} distances it visited (the "
                                  "reconstructed law holds no orbit of amplitude {} there: residual nan)",
                                  visit.size() - count, visit.size(), io::quantity(s.amplitude, "m")));
}

}  // namespace

FmReconstruction reconstruct_fm(const FmCurve& curve, const FmSettings& s, const FmOptions& options) {
  const std::size_t n0 = curve.distance.size();
  if (curve.frequency_shift.size() != n0)
    throw InvalidParameter("frequency_shift", fmt::format("frequency_shift has {} values for {} distances: one per "
                                                          "distance",
                                                          curve.frequency_shift.size(), n0));
  if (n0 < 5)
    throw InvalidParameter("distance", fmt::format("the curve has {} points: at least 5 are needed", n0));
  detail::require_finite("distance", curve.distance);
  detail::require_finite("frequency_shift", curve.frequency_shift);
  if (options.noise_realisations < 0 || options.noise_realisations > 1000)
    throw InvalidParameter("noise_realisations", "noise_realisations must be in [0, 1000]");
  // the round trip's cantilever: the user's Q, in the range the command line declares (not an internal failure)
  tapping::check_cantilever_setting("quality_factor", tapping::CantileverSetting::quality_factor,
                                    options.quality_factor);
  const auto order = detail::monotone_order("distance", curve.distance);

  FmReconstruction r;
  r.method = to_string(options.method);
  r.distance = detail::permuted(curve.distance, order);
  r.frequency_shift = detail::permuted(curve.frequency_shift, order);
  const std::size_t n = n0;
  const std::vector<double>& z = r.distance;
  std::vector<double> omega(n);
  for (std::size_t i = 0; i < n; ++i) omega[i] = r.frequency_shift[i] / s.resonance_frequency;

  return computed("force reconstruction (FM)", [&] {
    const ExponentialTail fitted = fit_exponential_tail(z, omega);
    if (options.tail == TailModel::exponential) {
      r.tail = fitted;
      if (!fitted.active)
        r.notes.push_back("tail = exponential: the last points do not decay exponentially (a sign change or growth); "
                          "Δf is taken as 0 beyond the last point instead");
    }
    r.force = invert(z, {omega}, s, options.method, r.tail).front();

    // what the tail changes: the other tail model's force
    r.tail_sensitivity = std::numeric_limits<double>::quiet_NaN();
    if (fitted.active) {
      const ExponentialTail other = r.tail.active ? ExponentialTail{} : fitted;
      const auto alt = invert(z, {omega}, s, options.method, other).front();
      r.tail_sensitivity = 0.0;
      for (std::size_t i = 0; i < n; ++i) r.tail_sensitivity = std::max(r.tail_sensitivity, std::abs(alt[i] - r.force[i]));
    }

    // noise: estimated in Δf, propagated through the (linear) inversion by synthetic realisations
    r.noise = estimate_noise(r.frequency_shift);
    r.force_uncertainty.assign(n, 0.0);
    if (r.noise > 0.0 && options.noise_realisations > 0) {
      std::mt19937_64 rng(options.seed);
      std::normal_distribution<double> normal(0.0, r.noise / s.resonance_frequency);
      std::vector<std::vector<double>> noisy;
      for (int k = 0; k < options.noise_realisations; ++k) {
        std::vector<double> e(n);
        for (double& v : e) v = normal(rng);
        noisy.push_back(std::move(e));
      }
      ExponentialTail none;  // noise alone: the inversion is linear in Ω without a tail
      const auto fs = invert(z, noisy, s, options.method, none);
      for (std::size_t i = 0; i < n; ++i) {
        double sum2 = 0.0;
        for (const auto& f : fs) sum2 += f[i] * f[i];
        r.force_uncertainty[i] = std::sqrt(sum2 / static_cast<double>(fs.size()));
      }
    }

    // the interaction length: from the largest |Δf| to where it first falls below 1/e of it
    std::size_t peak = 0;
    for (std::size_t i = 1; i < n; ++i)
      if (std::abs(r.frequency_shift[i]) > std::abs(r.frequency_shift[peak])) peak = i;
    const double df_max = std::abs(r.frequency_shift[peak]);
    r.interaction_length = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t i = peak; i < n; ++i)
      if (std::abs(r.frequency_shift[i]) < df_max / std::numbers::e) {
        r.interaction_length = z[i] - z[peak];
        break;
      }

    // the law: the force at the points, and the exponential tail continued over 10 λ (F decays as Δf does)
    std::vector<double> lz = z, lf = r.force;
    if (r.tail.active) {
      for (int k = 1; k <= 20; ++k) {
        const double x = z.back() + 0.5 * k * r.tail.decay_length;
        lz.push_back(x);
        lf.push_back(r.force.back() * std::exp(-(x - z.back()) / r.tail.decay_length));
      }
    }
    r.law = force_curve_from_si(lz, lf, lf, "reconstructed force");
    // energy: U(z) = ∫_z^∞ F dt over the law (trapezoid; 0 beyond the law's end)
    r.energy.assign(n, 0.0);
    {
      std::vector<double> cum(lz.size(), 0.0);
      for (std::size_t i = lz.size() - 1; i-- > 0;) cum[i] = cum[i + 1] + 0.5 * (lf[i] + lf[i + 1]) * (lz[i + 1] - lz[i]);
      if (r.tail.active) for (double& c : cum) c += lf.back() * r.tail.decay_length;
      for (std::size_t i = 0; i < n; ++i) r.energy[i] = cum[i];
    }

    r.round_trip_model = "first-order large-amplitude formula (Giessibl 2001) by quadrature of the table law";
    r.round_trip_frequency_shift.assign(n, std::numeric_limits<double>::quiet_NaN());
    r.residual.assign(n, std::numeric_limits<double>::quiet_NaN());
    r.residual_rms = r.residual_max = std::numeric_limits<double>::quiet_NaN();
    if (options.round_trip && options.exact_round_trip) {
      fm_exact_round_trip(r, z, s, options);
    } else if (options.round_trip) {
      const impact::TableLaw law(r.law, true);
      const double end = r.law.approach_gap.back() * 1e-9;
      const auto force = [&law](double x) { return law.approach(x * 1e9) * 1e-9; };
      double sum2 = 0.0, mx = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        r.round_trip_frequency_shift[i] =
            forward_frequency_shift(force, z[i], s.spring_constant, s.resonance_frequency, s.amplitude, {end});
        r.residual[i] = r.round_trip_frequency_shift[i] - r.frequency_shift[i];
        sum2 += r.residual[i] * r.residual[i];
        mx = std::max(mx, std::abs(r.residual[i]));
      }
      r.residual_rms = std::sqrt(sum2 / static_cast<double>(n));
      r.residual_max = mx;
      r.notes.push_back("round trip through the first-order large-amplitude formula (Giessibl 2001) by quadrature, not "
                        "an exact orbit of the self-excited cantilever");
    }

    // ill-posedness
    double f_max = 0.0, sigma_max = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      f_max = std::max(f_max, std::abs(r.force[i]));
      sigma_max = std::max(sigma_max, r.force_uncertainty[i]);
    }
    if (std::abs(r.frequency_shift.back()) > 0.05 * df_max && options.tail == TailModel::zero)
      r.notes.push_back(fmt::format(
          "the curve does not reach the free region: |Δf| at the largest distance is {:.0f} % of its largest value, "
          "and Δf is taken as 0 beyond it; the force is biased near the end (an exponential tail changes it by up to "
          "{})",
          100.0 * std::abs(r.frequency_shift.back()) / df_max, io::quantity(r.tail_sensitivity, "N")));
    if (sigma_max > 0.05 * f_max)
      r.notes.push_back(fmt::format("noisy data: the noise estimated in Δf ({}) makes the force uncertain by up to {} "
                                    "(1σ, {:.0f} % of its largest value): the inversion differentiates the data",
                                    io::quantity(r.noise, "Hz"), io::quantity(sigma_max, "N"),
                                    100.0 * sigma_max / f_max));
    if (std::isfinite(r.interaction_length) && r.interaction_length > 0.0) {
      const double ratio = s.amplitude / r.interaction_length;
      if (ratio > 0.1 && ratio < 10.0)
        r.notes.push_back(fmt::format(
            "the amplitude ({}) is neither small nor large compared with the interaction length ({}; A/λ = {:.2g}): "
            "{}",
            io::quantity(s.amplitude, "m"), io::quantity(r.interaction_length, "m"), ratio,
            options.method == FmMethod::sader_jarvis
                ? "the Sader–Jarvis formula interpolates between the small- and large-amplitude limits there (within "
                  "about 5 %), and the inversion may be ill-posed where the force has an inflection point within the "
                  "oscillation"
                : "the inversion may be ill-posed where the force has an inflection point within the oscillation"));
    } else if (!std::isfinite(r.interaction_length)) {
      r.notes.push_back("the interaction length could not be estimated: |Δf| never falls below 1/e of its largest "
                        "value within the curve");
    }
    if (s.amplitude < z[1] - z[0] && options.method == FmMethod::matrix)
      r.notes.push_back("the amplitude is smaller than the point spacing: the matrix method resolves nothing finer "
                        "than the spacing");
    return r;
  });
}

}  // namespace afmkit::spectroscopy
