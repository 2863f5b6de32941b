#include "afmkit/tapping/modes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::tapping {

namespace {
// roots of 1 + cos λ cosh λ = 0 (clamped-free beam)
constexpr std::array<double, kMaxEigenmodes> kLambda = {1.8751040687119611, 4.6940911329741745, 7.8547574382376126};
}  // namespace

Eigenmode::Eigenmode(double wn, double q, double beta, double gamma)
    : natural_frequency(validate::positive("mode natural_frequency", wn)),
      quality_factor(validate::positive("mode quality_factor", q)),
      mass_ratio(validate::positive("mode mass_ratio", beta)),
      participation(validate::finite("mode participation", gamma)) {}

Eigenmode Eigenmode::from_ratios(const Cantilever& first, double frequency_ratio, double stiffness_ratio,
                                 double quality_factor, double participation) {
  validate::positive("mode frequency_ratio", frequency_ratio);
  validate::positive("mode stiffness_ratio", stiffness_ratio);
  return {first.natural_frequency * frequency_ratio, quality_factor,
          frequency_ratio * frequency_ratio / stiffness_ratio, participation};
}

double euler_bernoulli_eigenvalue(int mode) {
  validate::in_range("mode", static_cast<long>(mode), 1L, static_cast<long>(kMaxEigenmodes));
  return kLambda[mode - 1];
}

double euler_bernoulli_participation(int mode) {
  const double l = euler_bernoulli_eigenvalue(mode);
  const double sigma = (std::cosh(l) + std::cos(l)) / (std::sinh(l) + std::sin(l));
  return (mode % 2 == 1 ? 4.0 : -4.0) * sigma / l;
}

std::vector<Eigenmode> euler_bernoulli_modes(const Cantilever& first, int count,
                                             const std::vector<double>& quality_factors) {
  validate::in_range("modes", static_cast<long>(count), 1L, static_cast<long>(kMaxEigenmodes));
  if (!quality_factors.empty() && static_cast<int>(quality_factors.size()) != count - 1)
    throw InvalidParameter("mode_quality_factors",
                           fmt::format("mode_quality_factors holds {} values: give one per higher mode ({})",
                                       quality_factors.size(), count - 1));
  std::vector<Eigenmode> modes{{first.natural_frequency, first.quality_factor, 1.0, euler_bernoulli_participation(1)}};
  for (int i = 2; i <= count; ++i) {
    const double r = kLambda[i - 1] / kLambda[0];
    const double q = quality_factors.empty() ? first.quality_factor * r * r : quality_factors[i - 2];
    modes.push_back(Eigenmode::from_ratios(first, r * r, r * r * r * r, q, euler_bernoulli_participation(i)));
  }
  return modes;
}

const char* excitation_name(Excitation excitation) {
  return excitation == Excitation::direct ? "direct" : "base";
}

void Medium::validate() const {
  validate::non_negative("added_mass_ratio", added_mass_ratio);
  if (!(fluid_quality_factor > 0))  // +inf allowed: no fluid damping
    validate::require(false, "fluid_quality_factor", fluid_quality_factor, "> 0 (inf: no fluid damping)");
}

MultiModeModel::MultiModeModel(std::vector<Eigenmode> m, std::vector<Drive> d, Excitation e, Medium med,
                               impact::ForceLaw f, double l)
    : modes(std::move(m)), drives(std::move(d)), excitation(e), medium(med), law(std::move(f)),
      separation(validate::finite("separation", l)) {
  validate::in_range("modes", static_cast<long>(modes.size()), 1L, static_cast<long>(kMaxEigenmodes));
  validate::in_range("drives", static_cast<long>(drives.size()), 1L, 2L);
  if (modes.front().mass_ratio != 1.0)
    validate::require(false, "mode mass_ratio", modes.front().mass_ratio, "= 1 for the first mode (m_1/m_1)");
  medium.validate();
}

MultiModeModel MultiModeModel::from_single(const TappingModel& m) {
  return {{Eigenmode(m.cantilever.natural_frequency, m.cantilever.quality_factor, 1.0, 1.0)},
          {m.drive},
          Excitation::direct,
          Medium{},
          m.law,
          m.separation};
}

bool MultiModeModel::single_mode() const {
  return modes.size() == 1 && drives.size() == 1 && excitation == Excitation::direct && medium.vacuum();
}

TappingModel MultiModeModel::first_mode() const {
  const double rho = force_factor();
  return {Cantilever(frequency(0), quality_factor(0)), Drive(rho * drives[0].amplitude, drives[0].frequency),
          rho == 1.0 ? law : law.scaled(rho), separation};
}

MultiModeModel MultiModeModel::with_separation(double l) const {
  MultiModeModel m = *this;
  m.separation = validate::finite("separation", l);
  return m;
}

double MultiModeModel::frequency(int i) const {
  if (medium.added_mass_ratio == 0.0) return modes[i].natural_frequency;  // bit for bit in vacuum
  return modes[i].natural_frequency / std::sqrt(1.0 + medium.added_mass_ratio);
}

double MultiModeModel::quality_factor(int i) const {
  if (medium.vacuum()) return modes[i].quality_factor;  // bit for bit in vacuum
  // 1/Q_i' = 1/(Q_i √(1+μ)) + (ω_1'/ω_i')/Q_f (a fluid damping coefficient per unit mass common to all modes)
  const double inv = 1.0 / (modes[i].quality_factor * std::sqrt(1.0 + medium.added_mass_ratio)) +
                     (frequency(0) / frequency(i)) / medium.fluid_quality_factor;
  return 1.0 / inv;
}

double MultiModeModel::forcing(int i, int d) const {
  const double rho = force_factor();
  if (excitation == Excitation::direct) return rho * modes[i].mass_ratio * drives[d].amplitude;
  const double w = drives[d].frequency;
  return rho * modes[i].participation * w * w * drives[d].amplitude;
}

std::complex<double> MultiModeModel::transfer(int i, std::complex<double> s) const {
  const double w = frequency(i);
  return 1.0 / (s * s + damping(i) * s + w * w);
}

std::complex<double> MultiModeModel::free_response(int i, int d) const {
  return forcing(i, d) * transfer(i, {0.0, drives[d].frequency});
}

std::complex<double> MultiModeModel::free_tip_response(int d) const {
  std::complex<double> c = base_amplitude(d);
  for (int i = 0; i < mode_count(); ++i) c += free_response(i, d);
  return c;
}

double MultiModeModel::shortest_mode_period() const {
  double w = 0.0;
  for (int i = 0; i < mode_count(); ++i) w = std::max(w, frequency(i));
  return 2.0 * std::numbers::pi / w;
}

double drive_for_mode_amplitude(const std::vector<Eigenmode>& modes, Excitation excitation, const Medium& medium,
                                int mode, double frequency, double amplitude) {
  validate::positive("frequency", frequency);
  validate::positive("amplitude", amplitude);
  validate::in_range("mode", static_cast<long>(mode), 0L, static_cast<long>(modes.size()) - 1);
  // a unit drive, then scale: the response is linear in the drive amplitude
  const MultiModeModel unit(modes, {Drive(1.0, frequency)}, excitation, medium,
                            impact::ForceLaw(impact::PiecewiseLinearLaw(0.0, 0.0)), 0.0);
  const double gain = std::abs(unit.free_response(mode, 0));
  if (!(gain > 0.0))
    throw InvalidParameter("excitation", fmt::format("mode {} does not respond to {} excitation (zero participation)",
                                                     mode + 1, excitation_name(excitation)));
  return amplitude / gain;
}

}  // namespace afmkit::tapping
