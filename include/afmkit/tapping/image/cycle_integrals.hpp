#pragma once
// What the time-domain imaging engine needs of one drive cycle [t_a, t_b] (model units), integrated on the
// trajectory's smooth segments: the lock-in's ∫ x e^{−iωt} dt and ∫ ẋ² dt by 7-point Gauss–Legendre panels no
// longer than a 16th of the drive period (exact for polynomials of degree 13: the degree-7 dense output of DOP853
// times e^{−iωt} to about (ωh)^7/7!), the largest tip–sample force (at the segments' ends and where ẋ rises through
// 0: the bottom of the motion). Lighter than OrbitIntegrals (observer.hpp), which evaluates the force law and six
// harmonics at 20 nodes per panel: the energy the sample takes follows from the energy balance of eq. 8 instead,
//   ∫ h ẋ dt = Γ ∫ cos(ωt) ẋ dt − 2ξω_n ∫ ẋ² dt − [½ẋ² + ½ω_n² x²]_a^b,
//   Γ ∫ cos(ωt) ẋ dt = Γ (Re[x e^{−iωt}]_a^b − ω Im ∫ x e^{−iωt} dt)   (by parts).
#include <complex>

#include <limits>

#include "afmkit/tapping/events.hpp"
#include "afmkit/tapping/observer.hpp"

namespace afmkit::tapping::image {

class CycleIntegrals final : public TrajectoryObserver {
 public:
  explicit CycleIntegrals(double drive_period) : panel_(drive_period / 16.0) {}
  void on_segment(const TappingSystem& system, const Segment& segment) override;

  std::complex<double> first_harmonic{};  // ∫ x e^{−iωt} dt
  double velocity_square = 0.0;           // ∫ ẋ² dt
  double peak_force = -1e300;             // max of H = −h (positive = repulsive)

 private:
  double panel_;
  double last_end_ = std::numeric_limits<double>::quiet_NaN();  // the end of the last segment and its mode
  Mode last_mode_;
  void force_at(const TappingSystem& system, const Mode& m, const TipState& s);
};

}  // namespace afmkit::tapping::image
