#pragma once
// Internal: the per-sample kernels of RealtimeFilter's block form on 2×2 blocks stored interleaved (q1, q2, …)
// (the modal form has its own, modal_kernel.hpp).
//   rotate_pairs: q_j ← c_j ⊙ q_j + s_j ⊙ swap(q_j) + g_j · input   (a rotation plus an input, per block)
//   accumulate_first: Σ_j kw_j · q_j[0]
// Two-lane vectors (GCC/Clang vector extensions) when available, plain loops otherwise. noexcept, no allocation.
#include <cstring>

namespace afmkit::control::detail {

#if defined(__GNUC__) || defined(__clang__)
typedef double v2d __attribute__((vector_size(16)));
inline v2d load2(const double* p) noexcept {
  v2d v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store2(double* p, v2d v) noexcept { std::memcpy(p, &v, sizeof v); }

inline void rotate_pairs(double* q, const double* c, const double* s, const double* g, double input,
                         int pairs) noexcept {
  const v2d in = {input, input};
  for (int j = 0; j < 2 * pairs; j += 2) {
    const v2d x = load2(q + j);
    const v2d xs = {x[1], x[0]};
    store2(q + j, load2(c + j) * x + load2(s + j) * xs + load2(g + j) * in);
  }
}

/// acc += kw_j · q_j[0] for each block (broadcast of the first component), returns both lanes.
inline void accumulate_first(const double* kw, const double* q, int pairs, double& lane0, double& lane1) noexcept {
  v2d a = {0.0, 0.0};
  for (int j = 0; j < 2 * pairs; j += 2) {
    const v2d x = {q[j], q[j]};
    a += load2(kw + j) * x;
  }
  lane0 = a[0];
  lane1 = a[1];
}
#else
inline void rotate_pairs(double* q, const double* c, const double* s, const double* g, double input,
                         int pairs) noexcept {
  for (int j = 0; j < 2 * pairs; j += 2) {
    const double a = q[j], b = q[j + 1];
    q[j] = c[j] * a + s[j] * b + g[j] * input;
    q[j + 1] = c[j + 1] * b + s[j + 1] * a + g[j + 1] * input;
  }
}
inline void accumulate_first(const double* kw, const double* q, int pairs, double& lane0, double& lane1) noexcept {
  lane0 = lane1 = 0.0;
  for (int j = 0; j < 2 * pairs; j += 2) {
    lane0 += kw[j] * q[j];
    lane1 += kw[j + 1] * q[j];
  }
}
#endif

}  // namespace afmkit::control::detail
