#pragma once
// Robust tuning of the couplings (docs/theory-control.md#tuning: the paper's "universal" values α ≈ 0.1Ω, β ≈ −0.1Ω,
// computed): maximise over (x, y) = (α, β) (or (a, b) for one oscillator) the worst-case decay rate
//   J(x, y) = min_{τ ∈ [0, τ_max], ρ ∈ [ρ_min, ρ_max]} ( −spectral abscissa of the loop at (x, y, τ, ρ) ),
// ρ = K/γ the gain-estimate error (the controller K is fixed, the plant rate is γ = K/ρ), on a grid of delays
// and gain ratios. Coarse grid over the window, then Nelder–Mead from the best grid point. The spectral
// abscissae come from Newton tracking along τ (warm starts); the optimum is re-evaluated with certified spectra
// (spectrum.hpp) and its delay margins τ_c(ρ) are reported.
#include <functional>
#include <vector>

#include "afmkit/control/loop_family.hpp"
#include "afmkit/core/cancellation.hpp"

namespace afmkit::control {

struct RobustTuningSpec {
  LoopFamily family;
  double delay_max = 0.0;  ///< τ_max ≥ 0 [s]
  int delay_points = 6;    ///< τ grid on [0, τ_max] (≥ 1)
  double gain_ratio_min = 1.0, gain_ratio_max = 1.0;  ///< ρ range, 0 < ρ_min ≤ ρ_max
  int gain_points = 3;     ///< ρ grid (geometric; ≥ 1)
  double x_min = 0.01, x_max = 1.0, y_min = -0.3, y_max = 0.5;  ///< search window [rad/s]
  int coarse_points = 12;        ///< coarse grid per axis (≥ 2)
  int max_evaluations = 150;     ///< Nelder–Mead budget
  double tolerance = 1e-4;       ///< stop when the simplex is smaller than tolerance·Ω
  int threads = 0;               ///< OpenMP threads for the coarse grid (0: default)
  Cancellation cancellation;     ///< checked once per objective evaluation (core/cancellation.hpp)
};

struct GainMargin {
  double gain_ratio;           ///< ρ
  double critical_delay;       ///< τ_c at this ρ (+inf: no crossing; NaN: unstable at τ = 0)
  double crossing_frequency;   ///< ν at τ_c
};

struct RobustTuning {
  double x = 0, y = 0;                 ///< optimum (α, β) or (a, b) [rad/s]
  double worst_decay = 0;              ///< J at the optimum (tracked spectra)
  double certified_worst_decay = 0;    ///< J at the optimum from certified spectra
  double worst_delay = 0, worst_gain_ratio = 1;  ///< where the minimum over the grid is attained
  std::vector<GainMargin> margins;     ///< τ_c at ρ_min, ρ = 1 (if inside the range), ρ_max
  std::vector<double> coarse_x, coarse_y, coarse_worst_decay;  ///< coarse grid (row-major [iy·nx + ix])
  int evaluations = 0;                 ///< objective evaluations (coarse + Nelder–Mead)
  bool converged = false;              ///< Nelder–Mead met the tolerance within the budget
};

/// J(x, y) (tracked spectra). Optionally returns the grid point of the minimum.
double worst_case_decay(const RobustTuningSpec& spec, double x, double y, double* worst_delay = nullptr,
                        double* worst_gain_ratio = nullptr);

/// `progress(increment, total)` over the coarse grid and the Nelder–Mead budget (thread-safe callback).
RobustTuning robust_tuning(const RobustTuningSpec& spec, const std::function<void(long, long)>& progress = {});

}  // namespace afmkit::control
