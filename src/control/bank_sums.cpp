// Vectorised bank sums (bank_sums.hpp).
#include "bank_sums.hpp"

#include <cmath>

// x86-64 with GCC: an AVX2 clone chosen at run time (the default clone stays baseline SSE2)
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define AFMKIT_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define AFMKIT_VECTOR_CLONES
#endif

namespace afmkit::control::detail {

SplitBank split_bank(const OscillatorBank& bank) {
  SplitBank out;
  out.a0 = bank.a0();
  const double omega = bank.rotation_frequency();
  const int n = bank.harmonics();
  out.inv_kw2.resize(static_cast<std::size_t>(n));
  for (int k = 1; k <= n; ++k) {
    const double kw = k * omega;
    BankArrays& t = bank.is_rejected(k) ? out.rejected : out.kept;
    t.a.push_back(bank.a(k));
    t.bkw.push_back(bank.b(k) * kw);
    t.kw2.push_back(kw * kw);
    out.inv_kw2[static_cast<std::size_t>(k - 1)] = 1.0 / (kw * kw);
  }
  return out;
}

namespace {
AFMKIT_VECTOR_CLONES BankSums sums(const double* a, const double* bkw, const double* kw2, std::size_t n, double x,
                                   double y) {
  const double s2r = x * x - y * y, s2i = 2.0 * x * y;
  double gr = 0, gi = 0, air = 0, aii = 0, gir = 0, gii = 0, ir = 0, ii = 0;
#pragma omp simd reduction(+ : gr, gi, air, aii, gir, gii, ir, ii)
  for (std::size_t k = 0; k < n; ++k) {
    const double zr = s2r + kw2[k];
    const double m = 1.0 / (zr * zr + s2i * s2i);
    const double vr = zr * m, vi = -s2i * m;  // v_k = 1/(s² + k²Ω²)
    const double ur = a[k] * x - bkw[k], ui = a[k] * y;
    const double pr = ur * vr - ui * vi, pi = ur * vi + ui * vr;  // G_k
    gr += pr;
    gi += pi;
    air += a[k] * vr;
    aii += a[k] * vi;
    gir += pr * vr - pi * vi;
    gii += pr * vi + pi * vr;
    ir += vr;
    ii += vi;
  }
  return {{gr, gi}, {air, aii}, {gir, gii}, {ir, ii}};
}

AFMKIT_VECTOR_CLONES std::complex<double> distances(const double* re, const double* im, std::size_t n, double x,
                                                    double y) {
  double sr = 0, si = 0;
#pragma omp simd reduction(+ : sr, si)
  for (std::size_t k = 0; k < n; ++k) {
    const double dr = x - re[k], di = y - im[k];
    const double m = 1.0 / (dr * dr + di * di);
    sr += dr * m;
    si -= di * m;
  }
  return {sr, si};
}
}  // namespace

std::complex<double> normaliser_product(const std::vector<double>& inv_kw2, std::complex<double> s2,
                                        std::complex<double> q) {
  const double xr = s2.real(), xi = s2.imag();
  double qr = q.real(), qi = q.imag();
  const auto mul = [](double ar, double ai, double br, double bi, double& cr, double& ci) {
    cr = ar * br - ai * bi;
    ci = ar * bi + ai * br;
  };
  const std::size_t n = inv_kw2.size();
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4) {  // two independent pairs, then one product into q
    double pr, pi, rr, ri, tr, ti;
    mul(1.0 + xr * inv_kw2[k], xi * inv_kw2[k], 1.0 + xr * inv_kw2[k + 1], xi * inv_kw2[k + 1], pr, pi);
    mul(1.0 + xr * inv_kw2[k + 2], xi * inv_kw2[k + 2], 1.0 + xr * inv_kw2[k + 3], xi * inv_kw2[k + 3], rr, ri);
    mul(pr, pi, rr, ri, tr, ti);
    mul(qr, qi, tr, ti, pr, pi);
    qr = pr;
    qi = pi;
    const double size = std::abs(qr) + std::abs(qi);
    if (size > 1e150) {
      qr *= 0x1p-500;
      qi *= 0x1p-500;
    } else if (size < 1e-150 && size > 0.0) {  // the factors k > |s|/Ω are below 1: no underflow either
      qr *= 0x1p500;
      qi *= 0x1p500;
    }
  }
  for (; k < n; ++k) {
    double pr, pi;
    mul(qr, qi, 1.0 + xr * inv_kw2[k], xi * inv_kw2[k], pr, pi);
    qr = pr;
    qi = pi;
  }
  return {qr, qi};
}

BankSums bank_sums(const BankArrays& t, std::complex<double> s) {
  return sums(t.a.data(), t.bkw.data(), t.kw2.data(), t.a.size(), s.real(), s.imag());
}

std::complex<double> inverse_distance_sum(const double* re, const double* im, std::size_t n, std::complex<double> z) {
  return distances(re, im, n, z.real(), z.imag());
}

}  // namespace afmkit::control::detail
