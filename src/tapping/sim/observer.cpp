#include "afmkit/tapping/observer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <type_traits>


#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/gauss_panels.hpp"
#include "afmkit/tapping/system.hpp"
#include "small_angle.hpp"

namespace afmkit::tapping {

SampleRecorder::SampleRecorder(std::vector<double> times) : times_(std::move(times)) {
  states_.reserve(times_.size());
  modes_.reserve(times_.size());
}

void SampleRecorder::on_segment(const TappingSystem&, const Segment& segment) {
  while (next_ < times_.size() && times_[next_] < segment.t_begin()) {
    // times before the simulated interval: skip
    ++next_;
    states_.push_back({std::nan(""), std::nan("")});
    modes_.push_back(segment.mode());
  }
  while (next_ < times_.size() && times_[next_] <= segment.t_end()) {
    states_.push_back(segment.state(times_[next_]));
    modes_.push_back(segment.mode());
    ++next_;
  }
}

namespace {

/// e^{iu}: by its Taylor series (small_angle.hpp) where u is small, else std::polar.
std::complex<double> small_phasor(double u) {
  if (!(std::abs(u) <= detail::small_angle_limit)) return std::polar(1.0, u);
  return detail::small_angle_phasor(u);
}

}  // namespace

OrbitIntegrals::OrbitIntegrals(double max_panel) : max_panel_(validate::positive("max_panel", max_panel)) {}

void OrbitIntegrals::extremum(const TappingSystem& system, const Segment& segment, double a, double b) {
  // the gap has an interior minimum where ẋ rises through 0, a maximum where it falls through 0 (the force of a
  // law monotone in the gap peaks at one of them: in contact at the deepest point, outside at the highest)
  const TipState sa = segment.state(a), sb = segment.state(b);
  const bool rising = sa.velocity < 0.0 && sb.velocity > 0.0, falling = sa.velocity > 0.0 && sb.velocity < 0.0;
  if (!rising && !falling) return;
  auto rate = [&](double t) { return segment.state(t).velocity; };
  const double tm = isolate_crossing(rate, a, b, rising ? CrossingDirection::rising : CrossingDirection::falling,
                                     1e-15 * std::max(1.0, std::abs(b)));
  const TipState sm = segment.state(tm);
  min_gap = std::min(min_gap, system.gap(sm.position));
  peak_force = std::max(peak_force, 0.0 - system.interaction(segment.mode().branch, sm.position, sm.velocity, segment.mode().region));
}

bool OrbitIntegrals::stage_integrals(const TappingSystem& system, const Segment& segment) {
  // A whole DOP853 step no longer than a panel: the integrals by the method's own stages and weights (order 8, as
  // if they were more components of the ODE: Segment::stage_quadrature), without building the dense output (only a
  // step where ẋ changes sign builds it, to locate the extremum). e^{−ikωt} = e^{−ikω mid} r^k, r = e^{−iω(t − mid)}
  // at the stages (|ω(t − mid)| ≤ ωh/2: the short series): Σ w x r^k per step, times e^{−ikω mid} once. The stage
  // states are not points of the trajectory (their errors are not controlled): the largest force and the smallest
  // gap are not taken there but at the step's ends and its located extremum — where they are for a law without
  // Kelvin–Voigt term (H monotone in the gap, or with one extremum, on each branch); a law with one keeps the
  // Gauss nodes on the dense output (its force may peak where ẋ ≠ 0).
  const double t0 = segment.t_begin(), t1 = segment.t_end();
  if (!(t1 - t0 <= max_panel_) || system.model().law.has_damping()) return false;
  struct Stages final : StageVisitor {
    const TappingSystem& system;
    Mode mode;
    double omega, mid, contact_gap;
    bool count_contact;
    double cos_mid, sin_mid;                 // e^{−iω mid}
    std::array<double, 6> re{}, im{};        // Σ w x r^k
    double drive = 0.0, square = 0.0, dissipated = 0.0, contact = 0.0;
    Stages(const TappingSystem& s, Mode m, double w, double c)
        : system(s), mode(m), omega(w), mid(c), contact_gap(s.contact_gap()), count_contact(!s.contact_is_region_zero()),
          cos_mid(std::cos(w * c)), sin_mid(-std::sin(w * c)) {}
    void node(double t, double w, const TipState& s) override {
      const std::complex<double> r = detail::stage_rotation(-omega * (t - mid));
      const double x = s.position, v = s.velocity, wx = w * x;
      double pr = 1.0, pi = 0.0;
      for (int k = 0; k < 6; ++k) {
        re[k] += wx * pr;
        im[k] += wx * pi;
        const double next = pr * r.real() - pi * r.imag();
        pi = pr * r.imag() + pi * r.real();
        pr = next;
      }
      drive += w * v * (cos_mid * r.real() - sin_mid * r.imag());  // Re e^{−iωt} = cos ωt
      square += w * v * v;
      if (mode.branch != ContactBranch::sticking) dissipated += w * v * system.interaction(mode.branch, x, v, mode.region);
      if (count_contact && system.gap(x) < contact_gap) contact += w;
    }
  } stages(system, segment.mode(), system.model().drive.frequency, 0.5 * (t0 + t1));
  if (!segment.stage_quadrature(stages)) return false;
  const std::complex<double> e_mid(stages.cos_mid, stages.sin_mid);
  std::complex<double> ek = 1.0;
  for (int k = 0; k < 6; ++k) {
    fourier[k] += ek * std::complex<double>(stages.re[k], stages.im[k]);
    ek *= e_mid;
  }
  drive_work += system.model().drive.amplitude * stages.drive;
  viscous_dissipation += system.damping() * stages.square;
  contact_dissipation += stages.dissipated;
  contact_time += stages.contact;
  extremum(system, segment, t0, t1);
  return true;
}

void OrbitIntegrals::on_segment(const TappingSystem& system, const Segment& segment) {
  // 10 nodes: exact to degree 19, above the adaptive steps' dense output (degree ≤ 7) times the phasors; on a panel
  // of width w ≤ 1/12 of the shortest period the error of x e^{−5iωt} is ~ (5ωw/2)^20/20! ≈ 1e-16 (20 nodes cost
  // twice the law evaluations for nothing: a third of a sweep's time, measured)
  const double t0 = segment.t_begin(), t1 = segment.t_end();
  if (!(t1 > t0)) return;
  const Mode mode = segment.mode();
  const double omega = system.model().drive.frequency;
  const double drive_amplitude = system.model().drive.amplitude;
  const bool exact_contact = system.contact_is_region_zero();  // else: counted at the quadrature nodes
  const bool in_contact_region = exact_contact && mode.region == 0;
  duration += t1 - t0;
  if (in_contact_region) contact_time += t1 - t0;
  auto accumulate = [&](double t, double w, std::complex<double> e1) {  // e1 = e^{−iωt}
    const TipState s = segment.state(t);
    const double x = s.position, v = s.velocity;
    std::complex<double> ek = 1.0;
    for (int k = 0; k < 6; ++k) {
      fourier[k] += w * x * ek;
      ek *= e1;
    }
    const double h = system.interaction(mode.branch, x, v, mode.region);
    drive_work += w * drive_amplitude * e1.real() * v;  // Γ cos ωt = Γ Re e^{−iωt}
    viscous_dissipation += w * system.damping() * v * v;
    if (mode.branch != ContactBranch::sticking) contact_dissipation += w * h * v;
    if (!exact_contact && system.gap(x) < system.contact_gap()) contact_time += w;
    peak_force = std::max(peak_force, 0.0 - h);
    min_gap = std::min(min_gap, system.gap(x));
  };
  if (!stage_integrals(system, segment))
    gauss_panels<10>(t0, t1, max_panel_, omega, small_phasor, accumulate,
                     [&](double a, double b) { extremum(system, segment, a, b); });
  for (double t : {t0, t1}) {
    const TipState s = segment.state(t);
    min_gap = std::min(min_gap, system.gap(s.position));
    peak_force = std::max(peak_force, 0.0 - system.interaction(mode.branch, s.position, s.velocity, mode.region));
  }
}

void OrbitIntegrals::on_event(const TappingSystem& system, const Event& event) {
  min_gap = std::min(min_gap, system.gap(event.state.position));
}

}  // namespace afmkit::tapping
