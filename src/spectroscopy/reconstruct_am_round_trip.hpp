#pragma once
// The AM round trip (private to src/spectroscopy): the reconstructed law through afmkit's exact orbits.
#include "afmkit/spectroscopy/reconstruct_am.hpp"

namespace afmkit::spectroscopy {
/// Fills the round-trip fields of r: an instrument sweep (approach) of the table law r.law at every measured
/// separation, with the cantilever and drive of `s`. `dissipative`: the law passes require_dissipative.
void am_round_trip(AmReconstruction& r, const AmSettings& s, bool dissipative, int points);
}  // namespace afmkit::spectroscopy
