#pragma once
// The C header `afmkit control export --format c-header` writes (docs/embedding.md): tuning comment (units, afmkit
// version), #include "afmkit/embed/afmkit_embed.h", a precision guard, AFMKIT_EXPORT_STATE_SIZE, AFMKIT_EXPORT_GAIN,
// the static const coefficient arrays and `afmkit_export_coefficients`; with test vectors AFMKIT_EXPORT_TEST_SAMPLES,
// afmkit_export_test_input / _expected and AFMKIT_EXPORT_TEST_TOLERANCE. Numbers are printed to round-trip exactly
// (%.9g with f suffix for float, %.17g for double).
#include <cstddef>
#include <string>

#include "afmkit/embed/design.hpp"
#include "afmkit/embed/test_vectors.hpp"

namespace afmkit::embed {

/// The header text; `vectors` may be null (no test vectors).
std::string render_c_header(const ExportedDesign& design, const TestVectors* vectors);

/// Design, verification and text in one: builds the design (checks (a)–(d)), makes test vectors (test_samples > 0)
/// or a verification run of max(4 turns, 4096) samples (capped at 10⁶), runs the host build of the core on them and
/// throws NumericalFailure if it misses the tolerance; returns the header text.
std::string export_c_header(const ExportSpec& spec, std::size_t test_samples);

}  // namespace afmkit::embed
