#pragma once
// Closed-loop spectrum of the seed-2 harmonic-rejection loop under delay (docs/theory-control.md#spectrum), computed on
// the exact characteristic function Δ(s) of loop.hpp (no Padé approximation):
//   * initial guesses: Chebyshev collocation of the infinitesimal generator (finite banks, dde_collocation.hpp)
//     or argument-principle subdivision (N = ∞ neutral form, and as a fallback);
//   * every root refined by Newton on Δ until the correction is ≤ tolerance·max(Ω, |s|);
//   * certification: the number of roots in the search box from the argument principle (winding number of Δ
//     along the box boundary, adaptive steps keeping the phase increments ≤ 0.5 rad and consistent with
//     Δ'/Δ) must equal the number of refined roots (with multiplicity) found inside.
// For the N = ∞ bank the spectrum of the neutral equation has a chain of roots accumulating at
//   Re s = ln|B4/A4| / T   (B4/A4 = (Ω − πα)/(Ω + πα), seed-2 eq. 31; the difference-equation spectrum bound),
// reported as `neutral_bound`; the spectral abscissa is then max(rightmost root, bound). The realisation (32)–(33)
// of that controller has additional roots exactly on the imaginary axis (docs/theory-control.md#neutral-realisation),
// reported in `structural`.
#include <complex>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "afmkit/control/loop.hpp"

namespace afmkit::control {

/// Closed axis-aligned box of the complex plane.
struct Box {
  double real_min, real_max, imag_min, imag_max;
};

struct CharacteristicRoot {
  std::complex<double> value;
  int multiplicity = 1;      // from the argument principle in a small box around the root (1 if not counted)
  double correction = 0.0;   // size of the last Newton correction |Δ/Δ'| (accuracy estimate)
  bool certified = false;    // multiplicity confirmed by a root count in a box isolating the root
};

/// A root of a realisation that is not a pole of the reduced closed loop (cancelled factor).
struct StructuralRoot {
  std::complex<double> value;
  int multiplicity;
  std::string origin;
};

struct SpectrumOptions {
  /// Left edge of the search box [rad/s]. NaN: automatic (below the `count` rightmost collocation roots, and
  /// right of the neutral bound + gap for N = ∞).
  double min_real = std::numeric_limits<double>::quiet_NaN();
  /// Half-height of the box [rad/s]. NaN: the proven root-free bound (capped at `max_imag_cap`).
  double max_imag = std::numeric_limits<double>::quiet_NaN();
  double max_imag_cap_periods = 60.0;  ///< cap of the automatic half-height, in units of Ω (finite banks: at
                                       ///< least 2(N + 1), above every oscillator frequency)
  int count = 12;                  ///< automatic box: aim at about this many rightmost roots
  int collocation_nodes = 0;       ///< Chebyshev nodes per delay (0: automatic)
  double tolerance = 1e-12;        ///< Newton: stop when |Δ/Δ'| ≤ tolerance·max(Ω, |s|)
  bool multiplicities = true;      ///< certify each root's multiplicity with a small-box count
};

struct Spectrum {
  std::vector<CharacteristicRoot> roots;  ///< all roots in `box` (both members of conjugate pairs),
                                          ///< decreasing real part
  Box box{};
  int box_count = 0;            ///< argument-principle count in `box` (with multiplicity)
  bool complete = false;        ///< box_count equals the sum of the multiplicities of `roots`
  bool box_is_proven = false;   ///< no root with Re s ≥ box.real_min lies outside the box (proven bounds)
  double spectral_abscissa = 0; ///< max Re over roots (and the neutral bound for N = ∞)
  int unstable_count = 0;       ///< roots with Re s ≥ 0 in the box (−1: infinitely many, neutral chain in Re ≥ 0)
  std::optional<double> neutral_bound;      ///< ln|B4/A4|/T for the N = ∞ bank
  /// N = ∞: roots between the neutral bound and box.real_min found by Newton from the chain asymptotics
  /// s_m ≈ bound + i(m [+ ½])Ω (not certified; they enter the spectral abscissa)
  std::vector<std::complex<double>> near_chain;
  std::vector<StructuralRoot> structural;   ///< diagnosis of the neutral realisation (theory-control.md)
  std::vector<std::string> notes;
};

/// Rightmost characteristic roots of the closed loop. Throws NumericalFailure if the count cannot be certified.
Spectrum rightmost_roots(const LoopSpec& loop, const SpectrumOptions& options = {});

/// Number of zeros of Δ in the box (argument principle). Throws NumericalFailure if a root lies on (or within
/// rounding of) the boundary.
int count_roots(const LoopSpec& loop, const Box& box);

/// Newton refinement of one root. Throws NumericalFailure if it does not converge.
CharacteristicRoot refine_root(const LoopSpec& loop, std::complex<double> guess, double tolerance = 1e-12);

/// Spectral abscissa (max Re over the spectrum) = −(decay rate).
double spectral_abscissa(const LoopSpec& loop);

/// Number of closed-loop roots with Re s ≥ 0, proven by the argument principle on the right half-plane box
/// bounded by the root-free bounds. −1: infinitely many (N = ∞ with α ≤ 0). Marginal roots (on the imaginary
/// axis) are reported through `marginal`.
struct UnstableCount {
  int count = 0;
  bool marginal = false;  ///< a root lies on (or within 1e-9 Ω of) the imaginary axis
};
UnstableCount unstable_roots(const LoopSpec& loop);

/// ln|B4/A4|/T for a loop whose bank is N = ∞ (plain or inside a Smith predictor); nullopt otherwise.
/// +inf if B4/A4 is undefined (α = −Ω/π), −inf if B4 = 0 (α = Ω/π).
std::optional<double> neutral_spectrum_bound(const LoopSpec& loop);

/// Root-free bounds: every root with Re s ≥ min_real has Re s < real_max and |Im s| < imag_max.
/// `proven` is false when no bound could be established (then the values are NaN).
struct RootBounds {
  double real_max = 0, imag_max = 0;
  bool proven = false;
};
RootBounds root_bounds(const LoopSpec& loop, double min_real);

/// Roots of the neutral realisation (32)–(33) on the imaginary axis (double root at 0, ±iΩ;
/// docs/theory-control.md#neutral-realisation), counted with the argument principle on γ(𝒜 − ℬe^{−sT}) + e^{−sτ}𝒩(1 − e^{−sT}) built from the InfiniteBank
/// coefficients. Empty for finite banks.
std::vector<StructuralRoot> neutral_realisation_roots(const LoopSpec& loop);

}  // namespace afmkit::control
