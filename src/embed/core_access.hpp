#pragma once
// Internal: the host builds of the C core seen from C++ without its macros (one translation unit per precision:
// core_float.cpp links the C-compiled afmkit_embed_core; core_double.cpp compiles the same source in double with
// the prefix afmkit_embed_hostd_ so that it never clashes with afmkit_embed_core_double).
#include <cstddef>
#include <vector>

namespace afmkit::embed::detail {

struct CoreSizes {
  std::size_t coefficients, filter, real;
};
CoreSizes float_core_sizes();
CoreSizes double_core_sizes();

struct CoreArrays {
  int pairs = 0, circles = 0, reals = 0;
  double input_limit = 0.0;
  const std::vector<double>* pair = nullptr;
  const std::vector<double>* circle = nullptr;
  const std::vector<double>* real = nullptr;
};
/// Closed loop m_n = in_n + u_{n−1}/gain through the core; returns max |m_n − expected_n| (NaN if init fails).
double float_core_loop(const CoreArrays& a, const std::vector<double>& in, double gain,
                       const std::vector<double>& expected);
double double_core_loop(const CoreArrays& a, const std::vector<double>& in, double gain,
                        const std::vector<double>& expected);

}  // namespace afmkit::embed::detail
