#include "afmkit/embed/design.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/control/loop.hpp"
#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/control/settings.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "core_access.hpp"

namespace afmkit::embed {

const char* to_string(Precision p) { return p == Precision::Float ? "float" : "double"; }

Precision precision_from(std::string_view name, const std::string& parameter) {
  if (name == "float") return Precision::Float;
  if (name == "double") return Precision::Double;
  throw InvalidParameter(parameter, fmt::format("{} = {} is not a precision: must be float or double", parameter, name));
}

CoreFootprint footprint_for(Precision precision, int pairs, int circles, int reals) {
  const detail::CoreSizes s = precision == Precision::Float ? detail::float_core_sizes() : detail::double_core_sizes();
  CoreFootprint f;
  f.coefficient_struct = s.coefficients;
  f.coefficient_arrays = s.real * static_cast<std::size_t>(8 * pairs + 7 * circles + 4 * reals);
  f.state = s.real * static_cast<std::size_t>(2 * (pairs + circles) + reals);
  f.filter_struct = s.filter;
  return f;
}

namespace {
double limit_max(Precision p) { return p == Precision::Float ? 1e30 : kDefaultInputLimitDouble; }
double round_to(Precision p, double x) { return p == Precision::Float ? static_cast<double>(static_cast<float>(x)) : x; }
}  // namespace

void ExportSpec::validate() const {
  validate::positive("sample_rate", sample_rate);
  validate::positive("rotation_frequency", rotation_frequency);
  validate::in_range("harmonics", static_cast<long>(harmonics), 1L, static_cast<long>(kMaxHarmonics));
  validate::finite("alpha", alpha);
  validate::finite("beta", beta);
  validate::positive("gain", gain);
  validate::positive("plant_rate", plant_rate);
  validate::non_negative("delay", delay);
  if (rejected.empty())
    throw InvalidParameter("rejected", fmt::format("rejected is empty: must list harmonic numbers in [1, {}]", harmonics));
  for (std::size_t i = 0; i < rejected.size(); ++i) {
    validate::in_range("rejected", static_cast<long>(rejected[i]), 1L, static_cast<long>(harmonics));
    if (std::find(rejected.begin(), rejected.begin() + static_cast<long>(i), rejected[i]) !=
        rejected.begin() + static_cast<long>(i))
      throw InvalidParameter("rejected", fmt::format("rejected lists {} twice: every harmonic at most once", rejected[i]));
  }
  if (input_limit != 0.0) validate::in_range("input_limit", input_limit, std::numeric_limits<double>::min(),
                                             limit_max(precision));
}

double ExportSpec::resolved_input_limit() const {
  if (input_limit != 0.0) return input_limit;
  return precision == Precision::Float ? kDefaultInputLimitFloat : kDefaultInputLimitDouble;
}

control::OscillatorBank ExportSpec::bank() const {
  return control::OscillatorBank::with_couplings(rotation_frequency, harmonics, alpha, beta, gain, rejected);
}

ExportedDesign::ExportedDesign(const ExportSpec& spec) : spec_(spec) {
  spec_.validate();
  const Precision prec = spec_.precision;
  const control::OscillatorBank bank = spec_.bank();
  // (c) Nyquist N Ω < π f_s: the filter's own check (InvalidParameter("sample_rate"))
  const control::RealtimeFilter filter(bank, spec_.sample_rate);
  if (!filter.uses_modal_form())
    throw InvalidParameter("alpha", fmt::format("alpha = {} rad/s, beta = {} rad/s: these couplings make the modal "
                                                "basis of the controller ill-conditioned (dense fallback), which the "
                                                "embedded core does not run: use couplings with alpha != 0",
                                                spec_.alpha, spec_.beta));
  const double h = 1.0 / spec_.sample_rate;

  // (b) memory, before the O(N²) stability check
  const control::ModalCoefficients mc = filter.modal_coefficients();
  int n_circles = 0;
  for (const auto& p : mc.pairs) n_circles += p.rejected_harmonic != 0;
  const int n_pairs = static_cast<int>(mc.pairs.size()) - n_circles, n_reals = static_cast<int>(mc.reals.size());
  const CoreFootprint fp = footprint_for(prec, n_pairs, n_circles, n_reals);
  if (spec_.target_memory != 0 && fp.total() > spec_.target_memory) {
    // largest N that fits with the same structure (N − r damped pairs + r undamped pairs + 1 real mode)
    const int r = static_cast<int>(spec_.rejected.size());
    int n_max = 0;
    for (int n = std::max(1, r); n <= kMaxHarmonics; ++n) {
      if (footprint_for(prec, n - r, r, 1).total() > spec_.target_memory) break;
      n_max = n;
    }
    throw InvalidParameter(
        "harmonics",
        fmt::format("harmonics = {} does not fit in target_memory = {} bytes: the {} core needs {} bytes (coefficient "
                    "struct {} + arrays {} + state {} + filter handle {}); allowed range: harmonics in [1, {}] for "
                    "this target memory{}",
                    spec_.harmonics, spec_.target_memory, to_string(prec), fp.total(), fp.coefficient_struct,
                    fp.coefficient_arrays, fp.state, fp.filter_struct, n_max,
                    n_max == 0 ? " (none: raise target_memory)" : ""));
  }

  // (a) closed-loop stability, declared plant and delay plus one sample
  {
    const control::LoopSpec loop(bank, spec_.plant, spec_.plant_rate, spec_.delay + h);
    abscissa_ = control::spectral_abscissa(loop);
    if (!(abscissa_ < 0.0)) {
      const double undelayed = control::spectral_abscissa(loop.with_delay(0.0));
      const bool delay_is_cause = undelayed < 0.0;
      throw InvalidParameter(
          delay_is_cause ? "delay" : "alpha",
          fmt::format("the closed loop ({}) is not stable with delay = {} s + one sample ({} s): spectral abscissa "
                      "{:.6g} 1/s = {:.6g} Omega, must be < 0; {}",
                      loop.describe(), spec_.delay, h, abscissa_, abscissa_ / spec_.rotation_frequency,
                      delay_is_cause ? "the loop is stable without delay: reduce delay below the delay margin "
                                       "(`afmkit control margin`) or retune alpha, beta (`afmkit control tune`)"
                                     : "the loop is unstable even without delay: choose alpha, beta in the stable "
                                       "region (`afmkit control chart`, `afmkit control tune`)"));
    }
  }

  // the coefficients in the C layout, rounded to the precision
  input_limit_ = round_to(prec, spec_.resolved_input_limit());
  const auto rd = [&](double x) { return round_to(prec, x); };
  double slowest_rate = std::numeric_limits<double>::infinity();  // min |Re λ| over damped modes [1/s]
  for (const auto& p : mc.pairs)
    if (p.rejected_harmonic == 0) slowest_rate = std::min(slowest_rate, std::abs(p.eigenvalue.real()));
  for (const auto& r : mc.reals) slowest_rate = std::min(slowest_rate, std::abs(r.eigenvalue));
  for (const auto& p : mc.pairs) {
    if (p.rejected_harmonic == 0) {
      const double c = rd(p.c1), s = rd(p.s2);
      pair_.insert(pair_.end(), {c, s, rd(p.g1), rd(p.g2), rd(p.w1), rd(p.w2), rd(p.e1), rd(p.e2)});
      const double decay = 1.0 - std::hypot(c, s);
      smallest_decay_ = std::min(smallest_decay_, decay);
      continue;
    }
    // undamped: q ← R(φ) q, R = [[c, −s], [s, c]]; magic circle y = S q (header comment)
    const double phi = std::atan2(p.s2, p.c1);
    const double eps = rd(2.0 * std::sin(0.5 * phi));
    const double cos_half = std::sqrt(1.0 - 0.25 * eps * eps);  // cos(φ'/2) of the map with the rounded ε
    const double a = p.g1, sg2 = 0.5 * eps * p.g1 + cos_half * p.g2;
    const double b = sg2 - eps * a;
    // w S⁻¹, S⁻¹ = [[1, 0], [−ε/(2 cos), 1/cos]]
    const double w1 = p.w1 - p.w2 * eps / (2.0 * cos_half), w2 = p.w2 / cos_half;
    const double e1 = p.e1 - p.e2 * eps / (2.0 * cos_half), e2 = p.e2 / cos_half;
    circle_.insert(circle_.end(), {eps, rd(a), rd(b), rd(w1), rd(w2), rd(e1), rd(e2)});
    circle_k_.push_back(p.rejected_harmonic);
  }
  for (const auto& r : mc.reals) {
    const double rr = rd(r.r);
    real_.insert(real_.end(), {rr, rd(r.g), rd(r.w), rd(r.e)});
    smallest_decay_ = std::min(smallest_decay_, 1.0 - std::abs(rr));
  }

  // (d) float: the damping must be resolved by float
  if (prec == Precision::Float) {
    const double need = kFloatDecayUlps * std::ldexp(1.0, -24);
    if (smallest_decay_ < need)
      throw InvalidParameter(
          "sample_rate",
          fmt::format("sample_rate = {} samples/s is too high for the float core: the slowest damped controller mode "
                      "decays by 1 - |e^(lambda h)| = {:.3g} per sample, below {} float ulps of 1 ({:.3g}), so float "
                      "rounding of its coefficients would change (or cancel) its damping; allowed range: a sample "
                      "rate at which every damped mode decays by >= {:.3g} per sample, i.e. sample_rate <= about {:.4g} "
                      "samples/s (slowest decay rate {:.4g} 1/s) — lower the sample rate or decimate the measurement "
                      "before the filter — or use precision = double",
                      spec_.sample_rate, smallest_decay_, kFloatDecayUlps, need, need, slowest_rate / need,
                      slowest_rate));
  }
}

}  // namespace afmkit::embed
