#pragma once
// The quasi-static tip engine (docs/theory-tapping.md#quasi-static-imaging): the cantilever is at every instant on
// the steady-state orbit of the separation under the tip (OrbitMap), seen through two first-order lags —
// the cantilever's own amplitude time constant τ_c = 2Q/ω0 and the lock-in's output filter τ_li = 1/(2π f_li) —
// acting on the complex amplitude B e^{iφ} (the lock-in's X + iY). The branch is kept from update to update while it exists
// (OrbitMap::follow). Valid while the separation changes little within τ_c (scan speed × slope × τ_c ≪ the width
// of the features of the amplitude curve) and the orbit does not come near a bifurcation.
#include "afmkit/tapping/image/imaging.hpp"
#include "afmkit/tapping/image/lockin.hpp"
#include "afmkit/tapping/image/orbit_map.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::tapping::image {

/// Where the map's approach from separation_max() first reaches `amplitude` [m] (`metres`: m per model length):
/// the engagement of both engines. InvalidParameter("setpoint") when it never does.
OrbitMap::Engaged engage_on(const OrbitMap& map, double amplitude, double metres);

class QuasiStaticEngine final : public TipEngine {
 public:
  /// `map` in model units; `scales` turns them to SI (physical runs: PhysicalCantilever::scales()); `time_constant`
  /// τ_c [s] and `lockin_bandwidth` [Hz] of the lags (a bandwidth of 0: no lock-in filter).
  QuasiStaticEngine(const OrbitMap& map, const UnitScales& scales, double time_constant, double lockin_bandwidth);

  double free_amplitude() const override { return map_.free_amplitude() * metres_; }
  double drive_frequency() const override { return 1.0 / (map_.drive_period() * scales_.time); }
  double engage(double amplitude) override;
  TipReading advance(const scan::Surface& surface, double z, double x0, double x1, double y, double dt) override;
  double time_constant() const { return cantilever_.time_constant(); }

 private:
  const OrbitMap& map_;
  UnitScales scales_;
  double metres_;        // m per model length
  double newtons_;       // N per model force
  double watts_;         // W per model energy per model period
  int branch_ = 0;
  std::vector<std::size_t> hints_;
  PhasorLag cantilever_;  // B e^{iφ} of the cantilever [m] (X + iY)
  PhasorLag lockin_;      // what the lock-in outputs
};

}  // namespace afmkit::tapping::image
