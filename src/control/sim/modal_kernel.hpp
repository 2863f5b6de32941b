#pragma once
// Internal: the per-sample recursion of RealtimeFilter's modal (ZeroOrderHold) form, vectorised across modes.
//
// The modes (damped rotations, then real modes) sit in lanes of four: mode j in group j/4, lane j%4. A group holds
// the coefficients of its four modes as ten four-lane vectors and its state as two (q1, q2); a real mode uses q1
// only (c2 = s1 = s2 = g2 = w2 = e2 = 0, so its q2 stays 0), unused lanes are all zero. Per sample, with the input m:
//   acc += w1 q1 + w2 q2                                   (output from the old state)
//   q1 ← (c1 q1 + s1 q2) + g1 m,   q2 ← (c2 q2 + s2 q1) + g2 m
//   u = (acc0 + acc2) + (acc1 + acc3)
// Every lane does the same IEEE operations in the same order whatever the vector width the compiler uses (two SSE2
// halves, one AVX register, half of an AVX-512 register, NEON pairs) and no multiply-add is fused (the library
// compiles this with -ffp-contract=off, and the AVX-512 build, whose target has FMA, says so itself), so the block
// path (state in registers across samples) and the per-sample path (state in memory) give the same bits.
// Fusing (FMA) would cut the operations per mode and sample from 14 to 8 and one rounding of three on the chain
// that carries the state from sample to sample, but every fused result differs in its last bits from the separate
// ones (a processor without FMA, x86-64's SSE2 baseline, cannot reproduce them but by a slow software fma), so the
// builds would no longer agree bit for bit with step() and with each other: docs/embedding.md.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace afmkit::control::detail {

#if !(defined(__GNUC__) || defined(__clang__))
#error "modal_kernel.hpp needs the GCC/Clang vector extensions"
#endif
#define AFMKIT_ALWAYS_INLINE [[gnu::always_inline]] inline
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // 32-byte vectors pass between inlined helpers only, never across an ABI
#endif

// Coefficients of group g: kGroupDoubles doubles from 32·g, eight runs of four lanes in this order.
enum Coef { kC, kS, kG1, kG2, kW1, kW2, kE1, kE2, kCoefs };
inline constexpr int kGroupDoubles = 4 * kCoefs;

// Four lanes of doubles, in two spellings with the same per-lane arithmetic and the same lane sum
// (a0 + a2) + (a1 + a3): Pair2 = two 16-byte halves (SSE2 on any x86-64, NEON on 64-bit ARM), Wide4 = one 32-byte
// register (AVX; used when the processor has AVX2, chosen at run time).
typedef double v2d __attribute__((vector_size(16)));
typedef double v4d __attribute__((vector_size(32)));
struct Pair2 {
  v2d lo, hi;
  AFMKIT_ALWAYS_INLINE static Pair2 load(const double* p) noexcept {
    Pair2 v;
    std::memcpy(&v.lo, p, sizeof v.lo);
    std::memcpy(&v.hi, p + 2, sizeof v.hi);
    return v;
  }
  AFMKIT_ALWAYS_INLINE void store(double* p) const noexcept {
    std::memcpy(p, &lo, sizeof lo);
    std::memcpy(p + 2, &hi, sizeof hi);
  }
  AFMKIT_ALWAYS_INLINE static Pair2 broadcast(double x) noexcept {
    Pair2 v;
    v.lo = v2d{x, x};
    v.hi = v.lo;
    return v;
  }
  AFMKIT_ALWAYS_INLINE friend Pair2 operator+(Pair2 a, Pair2 b) noexcept {
    a.lo += b.lo;
    a.hi += b.hi;
    return a;
  }
  AFMKIT_ALWAYS_INLINE friend Pair2 operator-(Pair2 a, Pair2 b) noexcept {
    a.lo -= b.lo;
    a.hi -= b.hi;
    return a;
  }
  AFMKIT_ALWAYS_INLINE friend Pair2 operator*(Pair2 a, Pair2 b) noexcept {
    a.lo *= b.lo;
    a.hi *= b.hi;
    return a;
  }
  AFMKIT_ALWAYS_INLINE double lane_sum() const noexcept {
    const v2d t = lo + hi;  // (a0 + a2, a1 + a3)
    return t[0] + t[1];
  }
};
struct Wide4 {
  v4d v;
  AFMKIT_ALWAYS_INLINE static Wide4 load(const double* p) noexcept {
    Wide4 x;
    std::memcpy(&x.v, p, sizeof x.v);
    return x;
  }
  AFMKIT_ALWAYS_INLINE void store(double* p) const noexcept { std::memcpy(p, &v, sizeof v); }
  AFMKIT_ALWAYS_INLINE static Wide4 broadcast(double x) noexcept {
    Wide4 w;
    w.v = v4d{x, x, x, x};
    return w;
  }
  AFMKIT_ALWAYS_INLINE friend Wide4 operator+(Wide4 a, Wide4 b) noexcept {
    a.v += b.v;
    return a;
  }
  AFMKIT_ALWAYS_INLINE friend Wide4 operator-(Wide4 a, Wide4 b) noexcept {
    a.v -= b.v;
    return a;
  }
  AFMKIT_ALWAYS_INLINE friend Wide4 operator*(Wide4 a, Wide4 b) noexcept {
    a.v *= b.v;
    return a;
  }
  AFMKIT_ALWAYS_INLINE double lane_sum() const noexcept { return (v[0] + v[2]) + (v[1] + v[3]); }
};

struct ModalRun {  // the coefficients, and what one call updates (held output, skipped count)
  const double* groups;  // group_count · kGroupDoubles coefficients
  int group_count;
  double input_limit;
  double held;
  std::uint64_t skipped;
};

/// The state of the groups, q1 of every group first, then q2 (8·G doubles), read and written group by group.
template <class V>
struct MemoryState {
  double* s;
  int groups;
  AFMKIT_ALWAYS_INLINE V a(int g) const noexcept { return V::load(s + 4 * g); }
  AFMKIT_ALWAYS_INLINE V b(int g) const noexcept { return V::load(s + 4 * (groups + g)); }
  AFMKIT_ALWAYS_INLINE void set(int g, V x, V y) noexcept {
    x.store(s + 4 * g);
    y.store(s + 4 * (groups + g));
  }
};

template <class V>
AFMKIT_ALWAYS_INLINE V coef(const double* cf, int g, Coef k) noexcept {
  return V::load(cf + kGroupDoubles * g + 4 * k);
}

/// Σ e·q of the current state (the coasting input for a skipped sample).
template <class V, class State>
AFMKIT_ALWAYS_INLINE double coast_input(const double* cf, const State& st, int groups) noexcept {
  V acc = V::broadcast(0.0);
#pragma GCC unroll 4
  for (int g = 0; g < groups; ++g) acc = acc + (coef<V>(cf, g, kE1) * st.a(g) + coef<V>(cf, g, kE2) * st.b(g));
  return acc.lane_sum();
}

/// One sample: returns u_n from the old state and advances the state with the input m.
template <class V, class State>
AFMKIT_ALWAYS_INLINE double modal_sample(const double* cf, State& st, int groups, double m) noexcept {
  const V mv = V::broadcast(m);
  V acc = V::broadcast(0.0);
#pragma GCC unroll 4  // G known (LocalState): unrolled whole, so the state stays in registers, never on the stack
  for (int g = 0; g < groups; ++g) {
    const V a = st.a(g), b = st.b(g), c = coef<V>(cf, g, kC), s = coef<V>(cf, g, kS);
    acc = acc + (coef<V>(cf, g, kW1) * a + coef<V>(cf, g, kW2) * b);
    st.set(g, (c * a - s * b) + coef<V>(cf, g, kG1) * mv, (c * b + s * a) + coef<V>(cf, g, kG2) * mv);
  }
  return acc.lane_sum();
}

/// n samples from in to out (may alias), with the skip rule of RealtimeFilter::step (a non-finite sample or one
/// beyond the input limit is replaced by the coasting input and the previous output is held).
template <class V, class State>
AFMKIT_ALWAYS_INLINE void modal_block(ModalRun& run, State& st, int groups, const double* in, double* out,
                                      std::size_t n) noexcept {
  double held = run.held;
  std::uint64_t skipped = run.skipped;
  for (std::size_t i = 0; i < n; ++i) {
    double m = in[i];
    const bool skip = !(std::abs(m) <= run.input_limit);  // NaN, ±inf, |m| > limit
    if (skip) m = coast_input<V>(run.groups, st, groups);
    const double u = modal_sample<V>(run.groups, st, groups, m);
    if (skip) ++skipped;
    else held = u;
    out[i] = held;
  }
  run.held = held;
  run.skipped = skipped;
}

/// The state of G groups (G known at compile time) in local vectors, so that it can stay in registers.
template <int G, class V>
struct LocalState {
  V s1[G], s2[G];
  AFMKIT_ALWAYS_INLINE V a(int g) const noexcept { return s1[g]; }
  AFMKIT_ALWAYS_INLINE V b(int g) const noexcept { return s2[g]; }
  AFMKIT_ALWAYS_INLINE void set(int g, V x, V y) noexcept {
    s1[g] = x;
    s2[g] = y;
  }
};

template <int G, class V>
AFMKIT_ALWAYS_INLINE void modal_block_local(ModalRun& run, double* state, const double* in, double* out,
                                            std::size_t n) noexcept {
  LocalState<G, V> st;
#pragma GCC unroll 8
  for (int g = 0; g < G; ++g) {
    st.s1[g] = V::load(state + 4 * g);
    st.s2[g] = V::load(state + 4 * (G + g));
  }
  modal_block<V>(run, st, G, in, out, n);  // G a constant: the group loops unroll and the state stays in registers
#pragma GCC unroll 8
  for (int g = 0; g < G; ++g) {
    st.s1[g].store(state + 4 * g);
    st.s2[g].store(state + 4 * (G + g));
  }
}

/// n samples on the state in memory (8·groups doubles).
template <class V>
AFMKIT_ALWAYS_INLINE void modal_block_memory(ModalRun& run, double* state, const double* in, double* out,
                                             std::size_t n) noexcept {
  MemoryState<V> st{state, run.group_count};
  modal_block<V>(run, st, run.group_count, in, out, n);
}

/// modal_block_memory on a 64-byte aligned copy of the state (up to kAlignedGroups groups, N ≤ 511: 8 KiB of
/// stack): the state is read and written every sample, and the caller's array (a std::vector) is only 16-byte
/// aligned, so a 32-byte access could straddle two cache lines (measured: 10 % slower at N = 50 for one alignment).
inline constexpr int kAlignedGroups = 128;
template <class V>
AFMKIT_ALWAYS_INLINE void modal_block_memory_aligned(ModalRun& run, double* state, const double* in, double* out,
                                                     std::size_t n) noexcept {
  const int groups = run.group_count;
  if (groups > kAlignedGroups) {
    modal_block_memory<V>(run, state, in, out, n);
    return;
  }
  alignas(64) double local[8 * kAlignedGroups];
  const std::size_t bytes = 8 * static_cast<std::size_t>(groups) * sizeof(double);
  std::memcpy(local, state, bytes);
  modal_block_memory<V>(run, local, in, out, n);
  std::memcpy(state, local, bytes);
}

// Entry points: the portable spelling (inlined into the caller) and, on x86-64 with GCC, the AVX2 build.
inline void modal_block_portable(ModalRun& run, double* state, const double* in, double* out, std::size_t n) noexcept {
  modal_block_memory<Pair2>(run, state, in, out, n);
}
[[gnu::noinline]] inline void modal_block_portable_registers(ModalRun& run, double* state, const double* in,
                                                             double* out, std::size_t n) noexcept {
  // two 16-byte registers per four lanes: up to 2 groups in registers on x86-64 (16 registers: with 3 groups the
  // coefficients spill and the aligned state in memory is faster, 108 against 87 MS/s at N = 10), 3 elsewhere (NEON
  // has 32)
  switch (run.group_count) {
    case 1: modal_block_local<1, Pair2>(run, state, in, out, n); return;
    case 2: modal_block_local<2, Pair2>(run, state, in, out, n); return;
#if !defined(__x86_64__)
    case 3: modal_block_local<3, Pair2>(run, state, in, out, n); return;
#endif
    default: modal_block_memory_aligned<Pair2>(run, state, in, out, n);
  }
}
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define AFMKIT_MODAL_AVX2 1
[[gnu::target("avx2"), gnu::noinline]] inline void modal_block_avx2(ModalRun& run, double* state, const double* in,
                                                                    double* out, std::size_t n) noexcept {
  // up to 3 groups the state stays in registers (with 4 groups in 16 registers the coefficients spill and the
  // aligned state in memory is faster: 135 against 70 MS/s at N = 13)
  switch (run.group_count) {
    case 1: modal_block_local<1, Wide4>(run, state, in, out, n); return;
    case 2: modal_block_local<2, Wide4>(run, state, in, out, n); return;
    case 3: modal_block_local<3, Wide4>(run, state, in, out, n); return;
    default: modal_block_memory_aligned<Wide4>(run, state, in, out, n);
  }
}
#endif

#ifdef AFMKIT_MODAL_AVX2
// The AVX-512 build. Up to 4 groups (N ≤ 15) one 32-byte register per group as Wide4, but state and coefficients
// all in registers (AVX-512 has 32 of them; the coefficients are copied into local vectors once per block, so the
// stores to `out` cannot alias them). From 5 to 8 groups two groups side by side in one 64-byte register (lanes 0-3
// group 2p, lanes 4-7 group 2p + 1), an odd last group in a 32-byte one (measured faster there; below 5 groups the
// 32-byte form is, on a core that splits 64-byte operations in two, AMD Zen 4). The per-lane operations are those of
// Wide4; the output sum keeps Wide4's order (acc ← acc + t_g for g = 0, 1, …, then (a0 + a2) + (a1 + a3)) by adding
// the two 32-byte halves of a pair's terms one after the other.
typedef double v8d __attribute__((vector_size(64)));
#define AFMKIT_AVX512_TARGET gnu::target("avx512f,avx512vl,avx512dq,avx512bw")
[[AFMKIT_AVX512_TARGET]] AFMKIT_ALWAYS_INLINE v4d lo4(v8d x) noexcept {
  return __builtin_shufflevector(x, x, 0, 1, 2, 3);
}
[[AFMKIT_AVX512_TARGET]] AFMKIT_ALWAYS_INLINE v4d hi4(v8d x) noexcept {
  return __builtin_shufflevector(x, x, 4, 5, 6, 7);
}
/// (a0 + a2) + (a1 + a3), as Wide4::lane_sum, in two additions and two shuffles.
[[AFMKIT_AVX512_TARGET]] AFMKIT_ALWAYS_INLINE double lane_sum4(v4d a) noexcept {
  const v2d t = __builtin_shufflevector(a, a, 0, 1) + __builtin_shufflevector(a, a, 2, 3);  // (a0 + a2, a1 + a3)
  return t[0] + t[1];
}
[[AFMKIT_AVX512_TARGET]] AFMKIT_ALWAYS_INLINE v8d join(v4d a, v4d b) noexcept {
  return __builtin_shufflevector(a, b, 0, 1, 2, 3, 4, 5, 6, 7);
}
[[AFMKIT_AVX512_TARGET]] AFMKIT_ALWAYS_INLINE v4d load4(const double* p) noexcept {
  v4d x;
  std::memcpy(&x, p, sizeof x);
  return x;
}
[[AFMKIT_AVX512_TARGET]] AFMKIT_ALWAYS_INLINE void store4(double* p, v4d x) noexcept { std::memcpy(p, &x, sizeof x); }

/// G groups: with Pairs, P = G / 2 pairs in 64-byte vectors and an odd last group in a 32-byte one; without, all G
/// in 32-byte vectors (Q of them), groups 2P … G − 1 after the pairs.
template <int G, bool Pairs>
struct Local512 {
  static constexpr int P = Pairs ? G / 2 : 0, Q = G - 2 * P;
  v8d k8[kCoefs][P > 0 ? P : 1];
  v4d k4[kCoefs][Q > 0 ? Q : 1];
  v8d s1[P > 0 ? P : 1], s2[P > 0 ? P : 1];
  v4d t1[Q > 0 ? Q : 1], t2[Q > 0 ? Q : 1];
};

template <int G, bool Pairs>
[[AFMKIT_AVX512_TARGET]] AFMKIT_ALWAYS_INLINE double coast_input_512(const Local512<G, Pairs>& L) noexcept {
  using Lc = Local512<G, Pairs>;
  v4d acc = v4d{0.0, 0.0, 0.0, 0.0};
#pragma GCC unroll 8
  for (int p = 0; p < Lc::P; ++p) {
    const v8d t = L.k8[kE1][p] * L.s1[p] + L.k8[kE2][p] * L.s2[p];
    acc = acc + lo4(t);
    acc = acc + hi4(t);
  }
#pragma GCC unroll 8
  for (int q = 0; q < Lc::Q; ++q) acc = acc + (L.k4[kE1][q] * L.t1[q] + L.k4[kE2][q] * L.t2[q]);
  return lane_sum4(acc);
}

template <int G, bool Pairs>
[[AFMKIT_AVX512_TARGET]] AFMKIT_ALWAYS_INLINE double modal_sample_512(Local512<G, Pairs>& L, double m) noexcept {
  using Lc = Local512<G, Pairs>;
  const v8d m8 = v8d{m, m, m, m, m, m, m, m};
  const v4d m4 = lo4(m8);
  v4d acc = v4d{0.0, 0.0, 0.0, 0.0};
#pragma GCC unroll 8
  for (int p = 0; p < Lc::P; ++p) {
    const v8d a = L.s1[p], b = L.s2[p], c = L.k8[kC][p], s = L.k8[kS][p];
    const v8d t = L.k8[kW1][p] * a + L.k8[kW2][p] * b;
    acc = acc + lo4(t);  // group 2p, then group 2p + 1: Wide4's order
    acc = acc + hi4(t);
    L.s1[p] = (c * a - s * b) + L.k8[kG1][p] * m8;
    L.s2[p] = (c * b + s * a) + L.k8[kG2][p] * m8;
  }
#pragma GCC unroll 8
  for (int q = 0; q < Lc::Q; ++q) {
    const v4d a = L.t1[q], b = L.t2[q], c = L.k4[kC][q], s = L.k4[kS][q];
    acc = acc + (L.k4[kW1][q] * a + L.k4[kW2][q] * b);
    L.t1[q] = (c * a - s * b) + L.k4[kG1][q] * m4;
    L.t2[q] = (c * b + s * a) + L.k4[kG2][q] * m4;
  }
  return lane_sum4(acc);
}

template <int G, bool Pairs>
[[AFMKIT_AVX512_TARGET]] AFMKIT_ALWAYS_INLINE void modal_block_local_512(ModalRun& run, double* state,
                                                                           const double* in, double* out,
                                                                           std::size_t n) noexcept {
  using Lc = Local512<G, Pairs>;
  constexpr int P = Lc::P, Q = Lc::Q;
  const double* cf = run.groups;
  Lc L;
#pragma GCC unroll 8
  for (int k = 0; k < kCoefs; ++k) {
#pragma GCC unroll 8
    for (int p = 0; p < P; ++p)
      L.k8[k][p] = join(load4(cf + kGroupDoubles * (2 * p) + 4 * k), load4(cf + kGroupDoubles * (2 * p + 1) + 4 * k));
#pragma GCC unroll 8
    for (int q = 0; q < Q; ++q) L.k4[k][q] = load4(cf + kGroupDoubles * (2 * P + q) + 4 * k);
  }
#pragma GCC unroll 8
  for (int p = 0; p < P; ++p) {  // q1 of groups 2p, 2p + 1 are adjacent in memory, and so are their q2
    L.s1[p] = join(load4(state + 8 * p), load4(state + 8 * p + 4));
    L.s2[p] = join(load4(state + 4 * G + 8 * p), load4(state + 4 * G + 8 * p + 4));
  }
#pragma GCC unroll 8
  for (int q = 0; q < Q; ++q) {
    L.t1[q] = load4(state + 4 * (2 * P + q));
    L.t2[q] = load4(state + 4 * (G + 2 * P + q));
  }
  const double limit = run.input_limit;
  double held = run.held;
  std::uint64_t skipped = run.skipped;
  for (std::size_t i = 0; i < n; ++i) {  // as modal_block
    double m = in[i];
    const bool skip = !(std::abs(m) <= limit);
    if (skip) m = coast_input_512<G, Pairs>(L);
    const double u = modal_sample_512<G, Pairs>(L, m);
    if (skip) ++skipped;
    else held = u;
    out[i] = held;
  }
  run.held = held;
  run.skipped = skipped;
#pragma GCC unroll 8
  for (int p = 0; p < P; ++p) {
    store4(state + 8 * p, lo4(L.s1[p]));
    store4(state + 8 * p + 4, hi4(L.s1[p]));
    store4(state + 4 * G + 8 * p, lo4(L.s2[p]));
    store4(state + 4 * G + 8 * p + 4, hi4(L.s2[p]));
  }
#pragma GCC unroll 8
  for (int q = 0; q < Q; ++q) {
    store4(state + 4 * (2 * P + q), L.t1[q]);
    store4(state + 4 * (G + 2 * P + q), L.t2[q]);
  }
}

[[AFMKIT_AVX512_TARGET, gnu::optimize("fp-contract=off"), gnu::noinline]] inline void modal_block_avx512(ModalRun& run, double* state, const double* in,
                                                                      double* out, std::size_t n) noexcept {
  switch (run.group_count) {  // the state (and up to 4 groups the coefficients) in registers up to 8 groups, N ≤ 31
    case 1: modal_block_local_512<1, false>(run, state, in, out, n); return;
    case 2: modal_block_local_512<2, false>(run, state, in, out, n); return;
    case 3: modal_block_local_512<3, false>(run, state, in, out, n); return;
    case 4: modal_block_local_512<4, false>(run, state, in, out, n); return;
    case 5: modal_block_local_512<5, true>(run, state, in, out, n); return;
    case 6: modal_block_local_512<6, true>(run, state, in, out, n); return;
    case 7: modal_block_local_512<7, true>(run, state, in, out, n); return;
    case 8: modal_block_local_512<8, true>(run, state, in, out, n); return;
    default:  // state in memory: 64-byte vectors gain nothing on a core that splits them in two 32-byte halves
      modal_block_avx2(run, state, in, out, n);  // (AMD Zen 4; measured: bench_control_sim BM_RealtimeFilterBuilds)
  }
}
#endif

/// The builds of the block kernel, narrowest first; every one gives the same bits.
enum class ModalPath { Portable, Avx2, Avx512 };

/// Whether this processor runs the build `p` (and this compiler made it).
inline bool modal_path_available(ModalPath p) noexcept {
  switch (p) {
    case ModalPath::Portable: return true;
#ifdef AFMKIT_MODAL_AVX2
    case ModalPath::Avx2: return __builtin_cpu_supports("avx2");
    case ModalPath::Avx512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
#endif
    default: return false;
  }
}

/// The widest build this processor runs.
inline ModalPath modal_best_path() noexcept {
  if (modal_path_available(ModalPath::Avx512)) return ModalPath::Avx512;
  if (modal_path_available(ModalPath::Avx2)) return ModalPath::Avx2;
  return ModalPath::Portable;
}

/// A block through the build `path` (which must be available): the same bits whichever.
inline void modal_block_dispatch(ModalPath path, ModalRun& run, double* state, const double* in, double* out,
                                 std::size_t n) noexcept {
#ifdef AFMKIT_MODAL_AVX2
  if (path == ModalPath::Avx512) {
    modal_block_avx512(run, state, in, out, n);
    return;
  }
  if (path == ModalPath::Avx2) {
    modal_block_avx2(run, state, in, out, n);
    return;
  }
#else
  (void)path;
#endif
  modal_block_portable_registers(run, state, in, out, n);
}

#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace afmkit::control::detail
