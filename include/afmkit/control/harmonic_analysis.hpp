#pragma once
// Harmonic content of periodic signals of the seed-2 loop (docs/theory-control.md#rejection-problem, #oscillator-bank,
// #simulation). Convention: a T-periodic signal s(t) = Re Σ_{k≥0} c_k e^{ikΩt} (c_0 real = mean), i.e. for
// F sin(kΩt + φ) the complex amplitude is c_k = −i F e^{iφ}.
#include <complex>
#include <span>
#include <vector>

#include "afmkit/control/plant.hpp"

namespace afmkit::control {

/// Fourier coefficients c_0..c_{max_order} of one period sampled at M equidistant points t_n = t_0 + nT/M, with
/// the phase referred to t_0: c_0 = mean, c_k = (2/M) Σ s_n e^{−2πikn/M}. Exact (no quadrature error) for a
/// trigonometric polynomial of degree < M/2. Throws InvalidParameter if max_order ≥ M/2 or the span is empty.
std::vector<std::complex<double>> fourier_coefficients(std::span<const double> one_period, int max_order);

/// Complex amplitude of harmonic k of the disturbance f (seed-2 eq. 14): f_0 = c0, f_k = −i F_k e^{iφ_k}. O(K) for
/// K harmonics (a search); the overload for one of f's harmonics is O(1).
std::complex<double> disturbance_harmonic(const Disturbance& f, int k);
std::complex<double> disturbance_harmonic(const Disturbance::Harmonic& h);

/// Harmonic k of the uncontrolled plant output in steady state: f_k (static plant, eq. 3) or
/// γ f_k/(γ + ikΩ) (first-order plant, eq. 1). The overload for one of the disturbance's harmonics is O(1).
std::complex<double> uncontrolled_harmonic(const Plant& plant, int k);
std::complex<double> uncontrolled_harmonic(const Plant& plant, const Disturbance::Harmonic& h);

/// Uncontrolled steady-state output y(t) (the signal the plant produced before the controller was switched on).
double uncontrolled_output(const Plant& plant, double t);

/// Target output of the controlled loop (seed-2 eq. 4, 16a): the uncontrolled output without the rejected
/// harmonics (`rejected` lists k ≥ 1).
double target_output(const Plant& plant, double t, std::span<const int> rejected);

/// Least-squares fit of ln(envelope_p) against the period midpoints t_p = (p + ½)T.
struct EnvelopeFit {
  double growth_rate;  // slope [1/s]: < 0 converging, > 0 diverging; NaN if fewer than 2 usable points
  int first_period;    // fit window (inclusive)
  int last_period;
};
/// Window: a growing envelope (last value above twice the value at the middle of the run) is fitted over the
/// second half; a decaying one from period 1 up to the last period above 100× its floor (minimum), or over the
/// whole run if that leaves fewer than three periods.
EnvelopeFit fit_log_envelope(std::span<const double> envelope, double period);

}  // namespace afmkit::control
