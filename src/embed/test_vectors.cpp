#include "afmkit/embed/test_vectors.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/core/validate.hpp"
#include "core_access.hpp"

namespace afmkit::embed {

double test_tolerance(Precision precision, double peak) {
  return (precision == Precision::Float ? 2e-4 : 1e-9) * peak;
}

TestVectors make_test_vectors(const ExportedDesign& design, std::size_t samples) {
  validate::in_range("test_vectors", static_cast<long>(samples), 1L, 1000000L);
  const ExportSpec& s = design.spec();
  const double h = 1.0 / s.sample_rate, omega = s.rotation_frequency;
  constexpr double golden_angle = 2.399963229728653;  // rad
  TestVectors tv;
  tv.input.resize(samples);
  tv.expected.resize(samples);
  double peak = 0.0;
  for (std::size_t n = 0; n < samples; ++n) {
    // phase of the first harmonic reduced mod 2π from the integer sample count (no loss for long runs)
    const double t = static_cast<double>(n) * h;
    double d = 0.2 + std::sin(omega * t);
    for (int k = 2; k <= s.harmonics; ++k) d += (0.5 / k) * std::sin(k * omega * t + golden_angle * k);
    d = s.precision == Precision::Float ? static_cast<double>(static_cast<float>(d)) : d;
    tv.input[n] = d;
    peak = std::max(peak, std::abs(d));
  }
  control::RealtimeFilter filter(s.bank(), s.sample_rate);
  double u = 0.0;
  for (std::size_t n = 0; n < samples; ++n) {
    const double m = tv.input[n] + u / s.gain;
    tv.expected[n] = m;
    u = filter.step(m);
  }
  tv.tolerance = test_tolerance(s.precision, peak);
  return tv;
}

double run_core_closed_loop(const ExportedDesign& design, const TestVectors& vectors) {
  detail::CoreArrays a;
  a.pairs = design.pairs();
  a.circles = design.circles();
  a.reals = design.reals();
  a.input_limit = design.input_limit();
  a.pair = &design.pair_coefficients();
  a.circle = &design.circle_coefficients();
  a.real = &design.real_coefficients();
  return design.spec().precision == Precision::Float
             ? detail::float_core_loop(a, vectors.input, design.spec().gain, vectors.expected)
             : detail::double_core_loop(a, vectors.input, design.spec().gain, vectors.expected);
}

}  // namespace afmkit::embed
