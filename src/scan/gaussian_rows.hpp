#pragma once
// The two passes of the rough generator's separable Gaussian filter (sample_generators.cpp), register-blocked.
// Every output is the sum Σ_m k[m]·s[m] accumulated from 0.0 in ascending m with a multiply and an add (no fused
// multiply-add), as the plain loop sums it: the results are bit-identical to that loop, whichever clone runs.
#include <cstddef>

namespace afmkit::scan::detail {

/// dst[i] = Σ_{m<K} k[m]·src[i + m] for i < n (src holds n + K − 1 values).
void convolve_along_row(const double* src, const double* k, std::size_t kernel_size, double* dst, long n);

/// dst[j·n + i] = Σ_{m<K} k[m]·src[(j + m)·n + i] for j < rows, i < n (src holds (rows + K − 1)·n values).
void convolve_down_columns(const double* src, long n, long rows, const double* k, std::size_t kernel_size,
                           double* dst);

}  // namespace afmkit::scan::detail
