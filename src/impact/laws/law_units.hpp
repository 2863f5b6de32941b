#pragma once
// The unit conversions the built-in laws share (their parameters in SI or nm units, forces in nN: docs/force-laws.md).
namespace afmkit::impact {

inline constexpr double joule_per_nm_in_nN = 1e18;  // 1 J / 1 nm = 1e9 N = 1e18 nN

}  // namespace afmkit::impact
