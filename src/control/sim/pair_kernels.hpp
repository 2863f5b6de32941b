#pragma once
// Internal: the per-sample kernels of RealtimeFilter on 2×2 blocks stored interleaved (q1, q2, q1, q2, …).
//   rotate_pairs: q_j ← c_j ⊙ q_j + s_j ⊙ swap(q_j) + g_j · input   (a damped rotation plus an input, per block)
//   dot_pairs:    Σ_j w_j · q_j;   rotate_pairs_dot: both in one pass (the dot of the old state)
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

/// rotate_pairs that also returns Σ_j w_j · q_j of the OLD state (one pass over the state).
inline double rotate_pairs_dot(double* q, const double* c, const double* s, const double* g, const double* w,
                               double input, int pairs) noexcept {
  const v2d in = {input, input};
  v2d acc = {0.0, 0.0};
  for (int j = 0; j < 2 * pairs; j += 2) {
    const v2d x = load2(q + j);
    const v2d xs = {x[1], x[0]};
    acc += load2(w + j) * x;
    store2(q + j, load2(c + j) * x + load2(s + j) * xs + load2(g + j) * in);
  }
  return acc[0] + acc[1];
}

inline double dot_pairs(const double* w, const double* q, int pairs) noexcept {
  v2d a0 = {0.0, 0.0}, a1 = {0.0, 0.0};
  int j = 0;
  for (; j + 4 <= 2 * pairs; j += 4) {
    a0 += load2(w + j) * load2(q + j);
    a1 += load2(w + j + 2) * load2(q + j + 2);
  }
  if (j < 2 * pairs) a0 += load2(w + j) * load2(q + j);
  a0 += a1;
  return a0[0] + a0[1];
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
inline double rotate_pairs_dot(double* q, const double* c, const double* s, const double* g, const double* w,
                               double input, int pairs) noexcept {
  double a0 = 0.0, a1 = 0.0;
  for (int j = 0; j < 2 * pairs; j += 2) {
    const double a = q[j], b = q[j + 1];
    a0 += w[j] * a;
    a1 += w[j + 1] * b;
    q[j] = c[j] * a + s[j] * b + g[j] * input;
    q[j + 1] = c[j + 1] * b + s[j + 1] * a + g[j + 1] * input;
  }
  return a0 + a1;
}
inline double dot_pairs(const double* w, const double* q, int pairs) noexcept {
  double a0 = 0.0, a1 = 0.0;
  for (int j = 0; j < 2 * pairs; j += 2) {
    a0 += w[j] * q[j];
    a1 += w[j + 1] * q[j + 1];
  }
  return a0 + a1;
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
