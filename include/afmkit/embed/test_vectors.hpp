#pragma once
// Test vectors of an exported design and the C core run on them (docs/embedding.md#test-vectors).
//
// Input d_n (deterministic, t_n = n/f_s): offset 0.2 + tilt sin(Ω t_n) (first harmonic, amplitude 1) +
// Σ_{k=2..N} (0.5/k) sin(kΩ t_n + φ_k), φ_k = 2.399963·k (golden angle) — rounded to the precision (what the target
// stores). Expected m_n: the closed loop around a virtual static plant with one sample of delay,
//   m_n = d_n + u_{n−1}/K  (u_{−1} = 0),  u_n = filter(m_n),
// with the double afmkit::control::RealtimeFilter. The target runs the same loop with the core and checks
// |m_n − expected_n| ≤ tolerance (absolute, units of d).
#include <cstddef>
#include <vector>

#include "afmkit/embed/design.hpp"

namespace afmkit::embed {

struct TestVectors {
  std::vector<double> input;     // d_n, exactly representable in the precision
  std::vector<double> expected;  // m_n of the double reference loop
  double tolerance = 0.0;        // absolute, units of d
};

/// Tolerance of the precision for inputs of peak magnitude `peak`: float 2e-4·peak, double 1e-9·peak
/// (docs/embedding.md states what the tests measure).
double test_tolerance(Precision precision, double peak);

/// `samples` in [1, 10⁶] (a target holds 12 bytes per float sample); InvalidParameter("test_vectors") otherwise.
TestVectors make_test_vectors(const ExportedDesign& design, std::size_t samples);

/// Runs the host build of the C core (in the design's precision) on the loop above; returns max |m_n − expected_n|.
double run_core_closed_loop(const ExportedDesign& design, const TestVectors& vectors);

}  // namespace afmkit::embed
