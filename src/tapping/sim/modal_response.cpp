#include "afmkit/tapping/modal_response.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/system.hpp"

namespace afmkit::tapping {

namespace {
// 8-point Gauss–Legendre rule on [−1, 1]
constexpr std::array<double, 8> kModalGaussNodes = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                          -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                          0.7966664774136267,  0.9602898564975363};
constexpr std::array<double, 8> kModalGaussWeights = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                            0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                            0.2223810344533745, 0.1012285362903763};
}  // namespace

ModalLockIn::ModalLockIn(const MultiModeModel& model, double t_end, int periods)
    : model_(model), t_end_(t_end) {
  validate::in_range("lockin_periods", static_cast<long>(periods), 1L, 1000000000L);
  const double window = periods * model_.drives[0].period();
  begin_[0] = t_end - window;
  for (int d = 1; d < model_.drive_count(); ++d) {
    const double period = model_.drives[d].period();
    const double whole = std::max(1.0, std::floor(window / period * (1.0 + 1e-12)));
    begin_[d] = t_end - whole * period;
  }
}

void ModalLockIn::modal_state(double t, const TipState& s, double* q, double* v, double* f) const {
  const int m = model_.mode_count();
  double y = 0.0, y_rate = 0.0;
  for (int i = 0; i < m; ++i) f[i] = 0.0;
  for (int d = 0; d < model_.drive_count(); ++d) {
    const double w = model_.drives[d].frequency, c = std::cos(w * t), sn = std::sin(w * t);
    for (int i = 0; i < m; ++i) f[i] += model_.forcing(i, d) * c;
    y += model_.base_amplitude(d) * c;
    y_rate -= model_.base_amplitude(d) * w * sn;
  }
  q[0] = s.position - y;
  v[0] = s.velocity - y_rate;
  for (int j = 1; j < m; ++j) {
    q[j] = s.modal[2 * (j - 1)];
    v[j] = s.modal[2 * (j - 1) + 1];
    q[0] -= q[j];
    v[0] -= v[j];
  }
}

double ModalLockIn::stored_energy(int i, double q, double v) const {
  const double w = model_.frequency(i);
  return 0.5 * (v * v + w * w * q * q) / model_.coupling(i);
}

void ModalLockIn::on_segment(const TappingSystem& system, const Segment& segment) {
  const int m = model_.mode_count(), nd = model_.drive_count();
  const double earliest = *std::min_element(begin_.begin(), begin_.begin() + nd);
  const double a = std::max(segment.t_begin(), earliest), b = std::min(segment.t_end(), t_end_);
  if (!(b > a)) return;
  double q[kMaxEigenmodes], v[kMaxEigenmodes], f[kMaxEigenmodes];
  auto energies = [&](double t, bool start) {
    const TipState s = segment.state(t);
    modal_state(t, s, q, v, f);
    for (int i = 0; i < m; ++i) energy_[i].energy_change += (start ? -1.0 : 1.0) * stored_energy(i, q[i], v[i]);
  };
  if (!have_start_[0] && b > begin_[0]) {
    energies(std::max(a, begin_[0]), true);
    have_start_[0] = true;
  }
  if (b == t_end_) energies(b, false);
  // panels: 1/16 of the shortest period present
  double shortest = model_.shortest_mode_period();
  for (int d = 0; d < nd; ++d) shortest = std::min(shortest, model_.drives[d].period());
  // the windows' starts cut the interval: every quadrature panel lies inside or outside each window
  std::array<double, 4> cuts{a, b, b, b};
  int n_cuts = 1;
  for (int d = 0; d < nd; ++d)
    if (begin_[d] > a && begin_[d] < b) cuts[n_cuts++] = begin_[d];
  cuts[n_cuts++] = b;
  std::sort(cuts.begin(), cuts.begin() + n_cuts);
  for (int c = 0; c + 1 < n_cuts; ++c) integrate(system, segment, cuts[c], cuts[c + 1], shortest);
}

void ModalLockIn::integrate(const TappingSystem& system, const Segment& segment, double a, double b,
                            double shortest) {
  if (!(b > a)) return;
  const int m = model_.mode_count(), nd = model_.drive_count();
  const Mode mode = segment.mode();
  double q[kMaxEigenmodes], v[kMaxEigenmodes], f[kMaxEigenmodes];
  const double middle = 0.5 * (a + b);
  const int panels = std::max(1, static_cast<int>(std::ceil((b - a) / (shortest / 16.0))));
  const double width = (b - a) / panels;
  for (int p = 0; p < panels; ++p) {
    const double lo = a + p * width, hi = p + 1 == panels ? b : lo + width;
    const double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo);
    for (int k = 0; k < 8; ++k) {
      const double t = mid + half * kModalGaussNodes[k], w = half * kModalGaussWeights[k];
      const TipState s = segment.state(t);
      modal_state(t, s, q, v, f);
      double h = 0.0;  // the tip force on the modes (while a multi-mode tip sticks: the force that holds it)
      if (system.modal())
        system.modal_accelerations(mode.branch, mode.region, t, s, nullptr, &h);
      else
        h = system.interaction(mode.branch, s.position, s.velocity, mode.region);
      for (int d = 0; d < nd; ++d) {
        if (middle < begin_[d]) continue;
        const std::complex<double> e = std::polar(w, -model_.drives[d].frequency * t);
        for (int i = 0; i < m; ++i) mode_[i][d] += q[i] * e;
        tip_[d] += s.position * e;
      }
      min_gap_ = std::min(min_gap_, s.position + model_.separation);
      peak_force_ = std::max(peak_force_, -h);
      if (middle < begin_[0]) continue;
      mean_ += w * s.position;
      for (int i = 0; i < m; ++i) {
        const double inv = 1.0 / model_.coupling(i);
        energy_[i].drive_work += w * f[i] * v[i] * inv;
        energy_[i].damping_loss += w * model_.damping(i) * v[i] * v[i] * inv;
        energy_[i].tip_work -= w * h * v[i];
      }
    }
  }
}

TipState free_steady_state(const MultiModeModel& model, double t) {
  TipState s;
  for (int d = 0; d < model.drive_count(); ++d) {
    const double w = model.drives[d].frequency;
    const std::complex<double> e = std::polar(1.0, w * t), de = std::complex<double>(0.0, w) * e;
    const std::complex<double> tip = model.free_tip_response(d);
    s.position += (tip * e).real();
    s.velocity += (tip * de).real();
    for (int j = 1; j < model.mode_count(); ++j) {
      const std::complex<double> c = model.free_response(j, d);
      s.modal[2 * (j - 1)] += (c * e).real();
      s.modal[2 * (j - 1) + 1] += (c * de).real();
    }
  }
  return s;
}

void ModalResponseOptions::validate() const {
  validate::in_range("settle_periods", settle_periods, 0L, 100000000L);
  validate::in_range("lockin_periods", lockin_periods, 1L, 100000000L);
  simulation.validate();
}

long ModalResponseOptions::settle_periods_for(const MultiModeModel& model) const {
  if (settle_periods > 0) return settle_periods;
  double worst = 0.0;
  for (int i = 0; i < model.mode_count(); ++i)
    worst = std::max(worst, 2.0 * model.quality_factor(i) * model.drives[0].frequency / model.frequency(i));
  return std::max(10L, static_cast<long>(std::ceil(worst)));
}

ModalResponse modal_response(const MultiModeModel& model, double t_begin, TipState start,
                             const ModalResponseOptions& options) {
  options.validate();
  const double period = model.drives[0].period();
  const double t1 = t_begin + static_cast<double>(options.settle_periods_for(model)) * period;
  const SimulationResult settled = simulate(model, t_begin, start, t1, options.simulation);
  long lockin = options.lockin_periods;
  TipState from = settled.state;
  ModalResponse r;
  r.orbit_residual = std::numeric_limits<double>::quiet_NaN();
  if (options.periodic) {
    ModalShootingOptions shooting = options.shooting;
    shooting.simulation = options.simulation;
    const ModalOrbit orbit = modal_periodic_orbit(model, t1, settled.state, shooting);
    r.orbit_residual = orbit.residual;
    if (orbit.converged) {
      r.periodic = true;
      from = orbit.state;
      const long multiple = std::lround(orbit.period / period);  // drive-1 periods per common period
      lockin = (lockin + multiple - 1) / multiple * multiple;
    }
  }
  const double t2 = t1 + static_cast<double>(lockin) * period;
  ModalLockIn lock(model, t2, static_cast<int>(lockin));
  const SimulationResult end = simulate(model, t1, from, t2, options.simulation, &lock);
  r.separation = model.separation;
  for (int i = 0; i < model.mode_count(); ++i) {
    for (int d = 0; d < model.drive_count(); ++d) r.mode[i][d] = lock.mode(i, d);
    r.energy[i] = lock.energy(i);
  }
  for (int d = 0; d < model.drive_count(); ++d) r.tip[d] = lock.tip(d);
  r.mean = lock.mean();
  r.min_gap = lock.min_gap();
  r.peak_force = lock.peak_force();
  r.time = end.time;
  r.state = end.state;
  r.stats = settled.stats;
  r.stats.events += end.stats.events;
  r.stats.impacts += end.stats.impacts;
  r.stats.sticking_count += end.stats.sticking_count;
  r.stats.sticking_duration += end.stats.sticking_duration;
  r.stats.steps += end.stats.steps;
  return r;
}

std::vector<ModalResponse> modal_sweep(const MultiModeModel& model, const std::vector<double>& separations,
                                       const ModalResponseOptions& options,
                                       const std::function<void(long)>& progress) {
  options.validate();
  std::vector<ModalResponse> out;
  out.reserve(separations.size());
  double t = 0.0;
  TipState state = free_steady_state(model, 0.0);
  for (double l : separations) {
    out.push_back(modal_response(model.with_separation(l), t, state, options));
    t = out.back().time;
    state = out.back().state;
    if (progress) progress(1);
  }
  return out;
}

}  // namespace afmkit::tapping
