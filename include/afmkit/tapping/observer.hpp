#pragma once
// What is recorded during a simulation. The integrator hands every smooth piece of trajectory (one mode, no
// event inside) to the observer as a Segment that can be evaluated anywhere in [t_begin, t_end], and every
// event. Observers never influence the integration.
#include <array>
#include <complex>
#include <utility>
#include <vector>

#include "afmkit/tapping/events.hpp"

namespace afmkit::tapping {

class TappingSystem;

/// The nodes of a quadrature rule over a segment: node(t, weight, state) for each (Segment::stage_quadrature).
class StageVisitor {
 public:
  virtual void node(double t, double weight, const TipState& state) = 0;

 protected:
  ~StageVisitor() = default;
};

/// A smooth piece of the trajectory in one mode over [t_begin, t_end].
class Segment {
 public:
  Segment(double t_begin, double t_end, Mode mode) : t_begin_(t_begin), t_end_(t_end), mode_(mode) {}
  virtual ~Segment() = default;
  double t_begin() const { return t_begin_; }
  double t_end() const { return t_end_; }
  Mode mode() const { return mode_; }
  /// State at t ∈ [t_begin, t_end] (exact for the closed-form flow, dense output for the adaptive one).
  virtual TipState state(double t) const = 0;
  /// When the segment is one whole step of the adaptive integrator's DOP853: visits its stages with nonzero weight
  /// (t_j, h b_j, state Y_j) and returns true — Σ h b_j g(t_j, Y_j) is ∫ g(t, state) dt over the step to the
  /// method's order 8 (the quadrature the method applies to g as one more component of the ODE), without building
  /// the dense output. Otherwise (closed-form flow, Dopri5, a step cut by an event) false and no visit.
  virtual bool stage_quadrature(StageVisitor& /*visitor*/) const { return false; }

 protected:
  Segment(const Segment&) = default;
  Segment& operator=(const Segment&) = default;

 private:
  double t_begin_, t_end_;
  Mode mode_;
};

class TrajectoryObserver {
 public:
  virtual ~TrajectoryObserver() = default;
  virtual void on_segment(const TappingSystem& /*system*/, const Segment& /*segment*/) {}
  virtual void on_event(const TappingSystem& /*system*/, const Event& /*event*/) {}
};

/// Samples the trajectory at the given increasing times (those inside the simulated interval).
class SampleRecorder : public TrajectoryObserver {
 public:
  explicit SampleRecorder(std::vector<double> times);
  void on_segment(const TappingSystem& system, const Segment& segment) override;
  const std::vector<double>& times() const& { return times_; }
  std::vector<double> times() && { return std::move(times_); }
  const std::vector<TipState>& states() const& { return states_; }
  std::vector<TipState> states() && { return std::move(states_); }
  const std::vector<Mode>& modes() const& { return modes_; }
  std::vector<Mode> modes() && { return std::move(modes_); }

 private:
  std::vector<double> times_;
  std::vector<TipState> states_;
  std::vector<Mode> modes_;
  std::size_t next_ = 0;
};

/// Records every event.
class EventRecorder : public TrajectoryObserver {
 public:
  void on_event(const TappingSystem& /*system*/, const Event& event) override { events_.push_back(event); }
  const std::vector<Event>& events() const& { return events_; }
  std::vector<Event> events() && { return std::move(events_); }

 private:
  std::vector<Event> events_;
};

/// Integrals over the trajectory: on a whole step of DOP853 no longer than `max_panel` by its own stages
/// (Segment::stage_quadrature), else by Gauss–Legendre quadrature on the dense output (sub-intervals no longer than
/// `max_panel`): Fourier coefficients of x at kω (k = 0..5), energy terms, contact time, extrema.
class OrbitIntegrals : public TrajectoryObserver {
 public:
  explicit OrbitIntegrals(double max_panel);
  void on_segment(const TappingSystem& system, const Segment& segment) override;
  void on_event(const TappingSystem& system, const Event& event) override;

  double duration = 0.0;
  std::array<std::complex<double>, 6> fourier{};  // ∫ x e^{−ikωt} dt, k = 0..5
  double drive_work = 0.0;           // ∫ Γ cos(ωt) ẋ dt
  double viscous_dissipation = 0.0;  // ∫ 2ξω_n ẋ² dt
  double contact_dissipation = 0.0;  // ∫ h ẋ dt
  double contact_time = 0.0;         // time with gap below the lowest switching gap
  double min_gap = 1e300;
  double peak_force = -1e300;        // max of H = −h

 private:
  double max_panel_;
  void extremum(const TappingSystem& system, const Segment& segment, double a, double b);
  bool stage_integrals(const TappingSystem& system, const Segment& segment);
};

}  // namespace afmkit::tapping
