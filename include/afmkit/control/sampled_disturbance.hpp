#pragma once
// The disturbance f of the seed-2 loop (seed-2 eq. 14: f = c0 + Σ F_k sin(kθ + φ_k), θ = Ωt) from a user's samples
// of it: f at t = 0, h, 2h, … over whole rotation periods (h = T/S, S samples per period). The periods are averaged
// (f is periodic with T in the model, docs/theory-control.md#rejection-problem) and the harmonics k < S/2 of the
// average are its exact discrete Fourier coefficients: the Disturbance returned reproduces the averaged samples
// exactly (to rounding) when the samples hold no Nyquist term (k = S/2, for even S) and no harmonic above the kept ones.
#include <vector>

#include "afmkit/control/plant.hpp"

namespace afmkit::control {

struct SampledDisturbance {
  Disturbance disturbance;          ///< c0 and F_k, φ_k for k = 1 … harmonics (F_k ≤ 1e-13 rms, rounding, left out)
  int samples_per_period = 0;       ///< S
  int periods = 0;                  ///< P = samples / S
  int harmonics = 0;                ///< highest k kept
  double rms = 0;                   ///< RMS of the samples [signal]
  double non_periodic_rms = 0;      ///< RMS of the samples minus their period average (what the model cannot hold)
  double unrepresented_rms = 0;     ///< RMS of the period average minus the Disturbance at the samples (k above
                                    ///< `harmonics`, the Nyquist term)
};

/// `samples`: f at t = j h, j = 0 … P·S − 1 (finite; P ≥ 1). `samples_per_period` S ≥ 2; `max_harmonic` 0: every
/// k < S/2, else at most that. InvalidParameter naming `parameter` ("signal") when the samples are not finite or
/// do not cover whole periods. Cost: O(P·S) averaging plus O(S·K) for the K harmonics.
SampledDisturbance disturbance_from_samples(const std::vector<double>& samples, int samples_per_period,
                                            int max_harmonic = 0, const char* parameter = "signal");

}  // namespace afmkit::control
