#pragma once
// Private to src/control/spectra: warm-started tracking of the rightmost roots across neighbouring loops
// (charts, tuning). Roots are kept in the closed upper half-plane (conjugates implied).
#include <complex>
#include <optional>
#include <vector>

#include "afmkit/control/loop.hpp"
#include "fast_characteristic.hpp"

namespace afmkit::control::spectra_detail {

struct TrackedSpectrum {
  std::vector<std::complex<double>> roots;  // upper half-plane + real axis, decreasing real part
  std::optional<double> neutral_bound;
  double omega = 1.0;  // Ω (scale for tolerances)

  double abscissa() const;
  /// roots with Re s > 0 (conjugate pairs count 2); −1 if the neutral chain lies in Re s ≥ 0
  int unstable() const;
  /// `keep` roots tracked and at most one of them stable: unstable() is then only a lower bound (more roots
  /// may lie in Re s > 0 beyond the tracked ones, e.g. the whole bank for α < 0)
  bool saturated(std::size_t keep) const {
    if (roots.size() < keep) return false;
    std::size_t stable = 0;
    for (const auto& r : roots) stable += r.real() <= 0.0 ? 1 : 0;
    return stable <= 1;
  }
};

class RootTracker {
 public:
  explicit RootTracker(int keep = 16, double tolerance = 1e-11) : keep_(keep), tolerance_(tolerance) {}
  std::size_t keep() const { return static_cast<std::size_t>(keep_); }

  /// Full initialisation: collocation (finite banks) or certified rightmost roots (N = ∞), plus seeds.
  TrackedSpectrum initial(const LoopSpec& loop) const;
  /// Warm update from `previous` (Newton on the fast characteristic); `with_seeds` adds the asymptotic seeds
  /// (oscillator roots ikΩ shifted by the first-order perturbation, neutral-chain roots).
  TrackedSpectrum update(const LoopSpec& loop, const TrackedSpectrum& previous, bool with_seeds) const;
  /// Merge two lists (e.g. a warm update and a fresh initialisation).
  TrackedSpectrum merge(const TrackedSpectrum& a, const TrackedSpectrum& b) const;

 private:
  bool refine(const FastCharacteristic& f, std::complex<double>& s) const;
  void finish(std::vector<std::complex<double>>& roots, double omega) const;
  void add_seeds(const LoopSpec& loop, std::vector<std::complex<double>>& starts) const;
  int keep_;
  double tolerance_;
};

}  // namespace afmkit::control::spectra_detail
