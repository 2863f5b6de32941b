// Register-blocked passes of the separable Gaussian filter (gaussian_rows.hpp). Each block keeps its partial sums in
// registers (GCC vector extensions: four doubles per vector, SSE2 pairs in the default clone) instead of reloading
// and storing the output row once per kernel tap; the summation order of every output is unchanged.
#include "gaussian_rows.hpp"

#include <cstring>

// x86-64 with GCC: an AVX2 clone chosen at run time (the default clone stays baseline SSE2; no FMA in either)
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define AFMKIT_GAUSSIAN_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define AFMKIT_GAUSSIAN_CLONES
#endif

namespace afmkit::scan::detail {

namespace {
typedef double Lanes4 __attribute__((vector_size(32)));  // NOLINT(modernize-use-using): attribute placement
}  // namespace

AFMKIT_GAUSSIAN_CLONES void convolve_along_row(const double* src, const double* k, std::size_t kernel_size,
                                               double* dst, long n) {
  long i = 0;
  for (; i + 16 <= n; i += 16) {
    Lanes4 a0 = {0.0, 0.0, 0.0, 0.0}, a1 = a0, a2 = a0, a3 = a0;
    for (std::size_t m = 0; m < kernel_size; ++m) {
      const double w = k[m];
      const Lanes4 wv = {w, w, w, w};
      const double* s = src + i + static_cast<long>(m);
      Lanes4 s0, s1, s2, s3;
      std::memcpy(&s0, s, sizeof s0);
      std::memcpy(&s1, s + 4, sizeof s1);
      std::memcpy(&s2, s + 8, sizeof s2);
      std::memcpy(&s3, s + 12, sizeof s3);
      a0 += wv * s0;
      a1 += wv * s1;
      a2 += wv * s2;
      a3 += wv * s3;
    }
    std::memcpy(dst + i, &a0, sizeof a0);
    std::memcpy(dst + i + 4, &a1, sizeof a1);
    std::memcpy(dst + i + 8, &a2, sizeof a2);
    std::memcpy(dst + i + 12, &a3, sizeof a3);
  }
  for (; i < n; ++i) {
    double a = 0.0;
    for (std::size_t m = 0; m < kernel_size; ++m) a += k[m] * src[i + static_cast<long>(m)];
    dst[i] = a;
  }
}

// Blocks of 8 columns × 4 output rows: each source row's 8 values are loaded once for the (up to) 4 outputs that
// use it; output row j + q takes source row j + r with tap r − q, so every output still sums its taps in order.
AFMKIT_GAUSSIAN_CLONES void convolve_down_columns(const double* src, long n, long rows, const double* k,
                                                  std::size_t kernel_size, double* dst) {
  const auto taps = static_cast<long>(kernel_size);
  long i = 0;
  for (; i + 8 <= n; i += 8) {
    long j = 0;
    for (; j + 4 <= rows; j += 4) {
      Lanes4 a[4][2];
      for (auto& q : a) q[0] = q[1] = Lanes4{0.0, 0.0, 0.0, 0.0};
      for (long r = 0; r < taps + 3; ++r) {
        const double* s = src + (j + r) * n + i;
        Lanes4 s0, s1;
        std::memcpy(&s0, s, sizeof s0);
        std::memcpy(&s1, s + 4, sizeof s1);
        for (long q = 0; q < 4; ++q) {
          const long m = r - q;
          if (m < 0 || m >= taps) continue;
          const double w = k[m];
          const Lanes4 wv = {w, w, w, w};
          a[q][0] += wv * s0;
          a[q][1] += wv * s1;
        }
      }
      for (long q = 0; q < 4; ++q) {
        std::memcpy(dst + (j + q) * n + i, &a[q][0], sizeof a[q][0]);
        std::memcpy(dst + (j + q) * n + i + 4, &a[q][1], sizeof a[q][1]);
      }
    }
    for (; j < rows; ++j)
      for (long c = i; c < i + 8; ++c) {
        double a = 0.0;
        for (long m = 0; m < taps; ++m) a += k[m] * src[(j + m) * n + c];
        dst[j * n + c] = a;
      }
  }
  for (; i < n; ++i)
    for (long j = 0; j < rows; ++j) {
      double a = 0.0;
      for (long m = 0; m < taps; ++m) a += k[m] * src[(j + m) * n + i];
      dst[j * n + i] = a;
    }
}

}  // namespace afmkit::scan::detail
