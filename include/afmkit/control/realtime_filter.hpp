#pragma once
// Real-time first-harmonic-rejection filter for instruments (seed-2 controller, eqs. 15, 6, 20).
//
// One call per sample: u_n = step(m_n). The controller ż = A z + b m, u = −K c_rᵀ z (oscillator_bank.hpp) is
// sampled at f_s (h = 1/f_s) in one of two forms (SampledForm, discretisation.hpp):
//
// ZeroOrderHold (default) — exact for a sample held over the interval:
//   z_{n+1} = Φ z_n + Γ m_n,   u_n = −K c_rᵀ z_n     (Φ = e^{Ah}, Γ = ∫₀ʰ e^{As} ds b)
// so step() returns the continuous controller's output at the sampling instant (no direct feed-through) and then
// advances the state with the new sample. Φ = e^{(A0 − b c_eᵀ)h} is dense in the oscillator coordinates (the
// rank-1 coupling does not commute with the rotations), but A is diagonalisable with well separated eigenvalues
// (≈ ikΩ − α for (20)), so the filter runs in real modal coordinates q (z = V q): each complex pair σ ± iω is a
// damped rotation e^{σh}R(ωh) of two numbers, a real eigenvalue a scalar, u = w·q — O(N) per sample and equal to
// e^{Ah} up to rounding. Set-up without any N×N matrix: the eigenvalues by the Aberth iteration
// (bank_eigenvalues, O(N²)), then per mode in O(N) the eigenvectors of the rank-1 perturbation A = A0 − b c_eᵀ
// in closed form (docs/theory-control.md#oscillator-bank): right v = (λ − A0)⁻¹ b, left u = (λ − A0)⁻ᵀ c_e (the 2×2 blocks of A0 inverted
// one oscillator at a time; the rejected oscillators' exact modes ±ikΩ separately). O(N²) time, O(N) memory;
// V is never stored (physical ↔ modal maps are recomputed, O(N²), outside the per-sample path). Checked per
// mode: residual and ‖V‖_F‖V⁻¹‖_F < 1e8. If the check fails (near-defective couplings, a0 = 0) the filter falls
// back to the dense Φ (O(N³) set-up, O(N²) per sample), allowed only for N ≤ kMaxDenseHarmonics; beyond that the
// constructor throws InvalidParameter("harmonics"). See uses_modal_form().
// Range of N: 1 … kMaxHarmonics (ZeroOrderHold; set-up ≈ 4 s at the upper end, O(N²)) and 1 … kMaxHarmonicsBlock
// (BlockZeroOrderHold, O(N) set-up); larger N → InvalidParameter("harmonics").
//
// BlockZeroOrderHold — the block scheme sampled: e_n = m_n − x0 − Σ_kept x_k held over the interval, each
// oscillator rotated exactly by kΩh and driven by e_n (rotations plus a rank-1 coupling, O(N), no eigenvectors).
// Exact rejection of harmonic 1 and exact pass-through of harmonics 0, 2..N in the samples.
//
// step() is noexcept, lock-free and allocation-free. A sample that is non-finite or larger in magnitude than
// input_limit() (default kDefaultInputLimit = 1e150) is skipped (rejected, not clamped): the returned output is the
// previous one (held), skipped_samples() is incremented, and the state advances as if the sample had equalled the
// controller's own reconstruction of the kept harmonics (m = x0 + Σ_{k kept} x_k, i.e. e = 0 at that instant), so
// the oscillators keep their phase and no NaN/Inf ever enters the state.
// Why 1e150 cannot overflow: the state is linear in the samples, z_n = Σ_j Φ^{n−1−j} Γ m_j. For a controller
// that is not exponentially unstable (every |e^{λh}| ≤ 1, as for the couplings (20) in their stable range) each
// modal coordinate is bounded by n · max|Γ_modal| · max|m| with n < 2⁶⁴ ≈ 1.8e19 samples, so with |m| ≤ 1e150
// and coefficients below 1e100 the state stays below ≈ 1e270 < DBL_MAX ≈ 1.8e308, and so does u = w·q for
// N ≤ 1e5. A physical signal (ADC counts, volts, nm) is never near 1e150, so the default rejects only garbage. An
// exponentially unstable controller overflows from any input; no input limit can prevent that.
//
// reconfigure() changes any parameter while running without a jump: the oscillator states (x0, x_k, z_k) are
// kept (new oscillators start at 0, removed ones are dropped), the rejected oscillators are rescaled by
// K_old/K_new so that u = −K Σ_rej x_k is continuous, and the discretisation is recomputed. Strong guarantee: on
// InvalidParameter the filter is unchanged.
//
// save_state()/restore_state(): a flat array of doubles (layout below); restoring into a filter with the same
// configuration reproduces the future outputs bit for bit; into a different configuration the physical state is
// carried over as in reconfigure() (no gain rescaling).
#include <complex>
#include <cstddef>
#include <cstdint>
#include <new>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include "afmkit/control/discretisation.hpp"
#include "afmkit/control/oscillator_bank.hpp"

namespace afmkit::control {

/// The ZeroOrderHold filter in real modal coordinates, as the per-sample recursion runs it (for exporters such as
/// the embedded C core). With the input m_n, per sample:
///   u_n = Σ_pairs (w1 q1 + w2 q2) + Σ_reals w q                     (output from the old state)
///   pair:  q1 ← c1 q1 + s1 q2 + g1 m,   q2 ← c2 q2 + s2 q1 + g2 m    (a damped rotation, c1 = c2 = Re e^{μh},
///          s2 = −s1 = Im e^{μh}, μ = conj λ)
///   real:  q ← r q + g m
/// A skipped sample is replaced by the coasting input m = Σ_pairs (e1 q1 + e2 q2) + Σ_reals e q.
struct ModalCoefficients {
  struct Pair {
    double c1, s1, c2, s2, g1, g2, w1, w2, e1, e2;
    std::complex<double> eigenvalue;  // λ of the continuous controller [rad/s], Im λ > 0
    int rejected_harmonic;            // k when λ = ikΩ is the exact mode of a rejected oscillator, else 0
  };
  struct Real {
    double r, g, w, e;
    double eigenvalue;  // λ [1/s]
  };
  std::vector<Pair> pairs;
  std::vector<Real> reals;
  double sample_rate = 0.0;  // f_s [samples/s]
};

class RealtimeFilter {
 public:
  /// sample_rate f_s [samples/s] with Ω in rad/s. Validated: f_s finite and N Ω < π f_s (Nyquist for the highest
  /// oscillator) → InvalidParameter("sample_rate", …allowed range…).
  RealtimeFilter(const OscillatorBank& controller, double sample_rate,
                 SampledForm form = SampledForm::ZeroOrderHold);
  /// Couplings (20): a0 = α, a_k = 2α, b_k = −2β/k; only harmonic 1 rejected.
  static RealtimeFilter with_couplings(double sample_rate, double rotation_frequency, int harmonics, double alpha,
                                       double beta, double gain, SampledForm form = SampledForm::ZeroOrderHold);

  static constexpr double kDefaultInputLimit = 1e150;  // largest accepted |sample| by default (see above)
  static constexpr double kMaxStateMagnitude = 1e270;  // largest |coordinate| or |output| of a restored state
  static constexpr int kMaxHarmonics = 10000;          // ZeroOrderHold: N range 1 … kMaxHarmonics
  static constexpr int kMaxHarmonicsBlock = 100000;    // BlockZeroOrderHold: N range 1 … kMaxHarmonicsBlock
  static constexpr int kMaxDenseHarmonics = 200;       // dense ZOH fallback only up to this N

  /// Output u_n for the measured sample m_n (see above). noexcept, O(N).
  double step(double measured) noexcept;
  /// step() for each sample, with the same result bit for bit; in and out may alias; processes
  /// min(in.size(), out.size()) samples. For the modal form the modes are updated four lanes at a time and the state
  /// stays in registers across the block (N ≤ 31 with AVX-512, N ≤ 11 with AVX2; docs/embedding.md,
  /// bench/bench_control_sim.cpp).
  void step_block(std::span<const double> in, std::span<double> out) noexcept;

  /// Build of the modal block kernel: Auto = the widest this processor runs (Avx512 = 64-byte vectors on x86-64
  /// with AVX-512 F/VL/DQ/BW, Avx2 = 32-byte vectors, else Portable = 16-byte vectors, plain C++ on every target).
  /// Every lane does the same operations in the same order and the output sum keeps one order, so the outputs are
  /// the same bits whichever build runs (tests/control_sim/test_realtime_block.cpp); for timing and such checks. A
  /// build this processor (or compiler) lacks is not chosen: the filter runs the widest one below it instead
  /// (vectorisation() says which runs; vectorisation_available() says beforehand).
  enum class Vectorisation { Auto, Portable, Avx2, Avx512 };
  void set_vectorisation(Vectorisation v) noexcept;
  /// The build step_block() runs (never Auto; step() always runs the 16-byte one, inlined).
  Vectorisation vectorisation() const noexcept { return path_; }
  /// Whether this processor runs the build v (Auto and Portable: always).
  static bool vectorisation_available(Vectorisation v) noexcept;
  /// Whether step_block() runs a build wider than the 16-byte one.
  bool uses_wide_vectors() const noexcept { return path_ != Vectorisation::Portable; }

  /// Bumpless change of all parameters (see above).
  void reconfigure(const OscillatorBank& controller, double sample_rate);
  void reconfigure(const OscillatorBank& controller, double sample_rate, SampledForm form);
  /// Bumpless change of K only.
  void set_gain(double gain);
  /// Zero state, zero held output, counters cleared (the input limit is kept).
  void reset() noexcept;
  /// Largest accepted |sample|: samples with |m| > limit are skipped like NaN. Kept by reset(), reconfigure() and
  /// restore_state(). Throws InvalidParameter("input_limit") unless 0 < limit ≤ kDefaultInputLimit.
  void set_input_limit(double limit);
  double input_limit() const noexcept { return input_limit_; }

  // ---- state ------------------------------------------------------------------------------------------------
  /// Layout: [0] magic 0x41464D4B, [1] layout version (1), [2] N, [3] internal size n_i, [4..5] configuration
  /// fingerprint (two 32-bit halves), [6] held output, [7] skipped samples, [8] samples processed, [9] physical
  /// size n = 2N+1, then n_i internal (modal or physical) coordinates, then the n physical coordinates
  /// (x0, x1, z1, …, xN, zN).
  std::size_t state_size() const noexcept;
  /// Throws InvalidParameter("state") if the buffer is smaller than state_size().
  void save_state(std::span<double> out) const;
  std::vector<double> save_state() const;
  /// Throws InvalidParameter("state") for a malformed buffer (magic, version, sizes out of range, non-finite values,
  /// counters that are not whole numbers in 0 … 2^64 − 1 or more skipped than processed samples, a held output or
  /// coordinate beyond ±kMaxStateMagnitude); the filter is then unchanged.
  void restore_state(std::span<const double> in);

  /// Physical controller state (x0, x1, z1, …, xN, zN).
  Eigen::VectorXd controller_state() const;
  /// Replace the physical state (size 2N+1, finite), e.g. to start from the steady state.
  void set_controller_state(const Eigen::VectorXd& z);

  std::uint64_t skipped_samples() const noexcept { return skipped_; }
  std::uint64_t samples() const noexcept { return samples_; }
  double last_output() const noexcept { return held_; }
  const OscillatorBank& controller() const& noexcept { return bank_; }
  OscillatorBank controller() const&& { return bank_; }
  double sample_rate() const noexcept { return sample_rate_; }
  SampledForm form() const noexcept { return form_; }
  /// ZeroOrderHold form running in modal coordinates (O(N)); false for the dense fallback and for the block form.
  bool uses_modal_form() const noexcept { return disc_.kind == Kind::Modal; }
  /// The modal recursion's coefficients (see ModalCoefficients). Throws InvalidParameter("form") unless
  /// uses_modal_form().
  ModalCoefficients modal_coefficients() const;
  /// The internal modal state (pairs (q1, q2), then reals), the q of ModalCoefficients; same precondition.
  std::vector<double> modal_state() const;

  /// The sampled controller in the oscillator coordinates, z_{n+1} = Φ z_n + Γ m_n, u_n = C z_n (dense Φ, Γ, C),
  /// reconstructed from the internal form; for tests and inspection (O(N³) time, O(N²) memory).
  Eigen::MatrixXd transition_matrix() const;
  Eigen::VectorXd input_vector() const;
  Eigen::RowVectorXd output_vector() const;

 private:
  enum class Kind { Modal, Dense, Block };
  template <class T>
  struct Aligned64 {  // std::allocator on 64-byte boundaries (C++17 aligned new)
    using value_type = T;
    Aligned64() noexcept = default;
    template <class U>
    Aligned64(const Aligned64<U>&) noexcept {}
    T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{64})); }
    void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t{64}); }
    friend bool operator==(const Aligned64&, const Aligned64&) noexcept { return true; }
  };
  struct Discretisation {
    Kind kind = Kind::Modal;
    int n = 0;       // 2N+1
    int offset = 0;  // first index of the 2×2 blocks in the internal state (block form: 1, after x0)
    int pairs = 0;   // number of 2×2 blocks: modal pairs σ ± iω, or oscillators (block form)
    int reals = 0;   // modal real eigenvalues (stored after the pairs)
    // 2×2 blocks, interleaved two doubles per block: q ← c ⊙ q + s ⊙ swap(q) + g·input
    std::vector<double> c, s, g;
    std::vector<double> w, e;   // modal: u = w·q, coasting input m = e·q (pairs, then reals)
    std::vector<double> r, gr;  // modal real modes: q ← r q + gr m
    double g0 = 0.0;            // block form: x0 ← x0 + g0·e
    std::vector<double> kw;     // block form, per oscillator: (1 if kept, −K if rejected), interleaved
    std::vector<double> phi, gamma, out, err;  // dense fallback: row-major Φ, Γ, output row, c_e
    struct Mode {                // modal: eigenvalue λ (pairs: Im λ > 0) and the eigenvector scales
      std::complex<double> lambda;
      double v_scale = 0.0;            // v̂ = v_scale (λ − A0)⁻¹ b (unit norm); rejected: v̂ = (1, −i)/√2 in block k
      std::complex<double> u_scale;    // û = u_scale (λ − A0)⁻ᵀ c_e (ûᵀv̂ = 1); rejected: û = (1, i)/√2 − u_scale (…)
      int rejected = 0;                // k for the exact mode ikΩ of a rejected oscillator, else 0
    };
    std::vector<Mode> modes;    // modal: pairs, then reals (physical z = V q, V never stored)
    // modal, as the per-sample kernel runs it (src/control/sim/modal_kernel.hpp): the modes in groups of four lanes,
    // 32 coefficients per group, 64-byte aligned (a 32-byte load never straddles two cache lines: with the state in
    // memory every coefficient is read every sample); the state q_ is then q1 of every lane, then q2 (8·groups doubles)
    int groups = 0;
    std::vector<double, Aligned64<double>> packed;
    std::uint64_t fingerprint = 0;
  };
  static Discretisation discretise(const OscillatorBank& bank, double sample_rate, SampledForm form);
  static Discretisation modal(const OscillatorBank& bank, double sample_rate, bool& ok);
  static Eigen::VectorXd to_physical(const OscillatorBank& bank, const Discretisation& d, const double* q);
  static Eigen::VectorXd to_internal(const OscillatorBank& bank, const Discretisation& d, const Eigen::VectorXd& z);
  double advance(double m) noexcept;             // block form and dense fallback, one sample
  void run_modal(const double* in, double* out, std::size_t n) noexcept;  // modal form, n samples
  double coast_input() const noexcept;
  void load_physical(const Eigen::VectorXd& z);  // q = V⁻¹ z
  // internal coordinates in the documented order (pairs (q1, q2), then reals) ↔ the kernel's layout of q_
  static std::vector<double> pack(const Discretisation& d, const double* internal);
  std::vector<double> internal_state() const;

  OscillatorBank bank_;
  double sample_rate_;
  SampledForm form_;
  Discretisation disc_;
  std::vector<double> q_, q_tmp_;  // internal coordinates: modal (the kernel's layout, see pack()) or physical
  double held_ = 0.0;
  double input_limit_ = kDefaultInputLimit;
  Vectorisation path_ = Vectorisation::Portable;  // modal block kernel build (set_vectorisation; never Auto)
  std::uint64_t skipped_ = 0, samples_ = 0;
};

}  // namespace afmkit::control
