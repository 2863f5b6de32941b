#pragma once
// A force law from a measured force curve: an approach and a retract force–distance table, as exported by AFM
// software, each branch interpolated by PCHIP (shape-preserving piecewise cubic Hermite, Fritsch–Carlson).
//
// File format (read_force_curve / parse_force_curve)
//   * UTF-8 text (an initial byte-order mark and CR-LF line ends are accepted). Lines whose first non-blank
//     character is '#' are comments; blank lines are ignored.
//   * The first other line is the header. The separator is taken from it: ';' if it contains one, else ',',
//     else a tab, else runs of blanks (spaces/tabs). Every data line uses the same separator. Cells are trimmed
//     and may be enclosed in double quotes. Numbers use a decimal point ("1.5", "-2e-3"); nan/inf are rejected.
//   * Header columns name a role and a unit. The unit is written "(nm)", "[nm]" or as a "_nm" suffix
//     ("distance_nm"). Length units: nm, A, Å, angstrom, um, µm, m (converted to nm); force units: nN, pN, uN,
//     µN, N (converted to nN). The unit decides whether a column is a distance or a force. The branch is
//     recognised by a word of the column name starting with approach/extend/trace (approach branch) or
//     retract/retrace/withdraw (retract branch), case-insensitive; "distance", "separation", "gap", "z" and
//     "force" are descriptive only (a force unit on a column called distance/separation/gap/z, or a length unit
//     on a column called force, is an error). In a blank-separated header a column is the words up to and
//     including its unit, e.g. `approach distance (A)  approach force (pN)  …`.
//   * Two layouts, columns in any order:
//       3 columns: a shared distance (no branch word), an approach force, a retract force, e.g.
//                  `distance (nm), approach (nN), retract (nN)`;
//       4 columns: approach distance, approach force, retract distance, retract force, e.g.
//                  `approach distance (nm), approach force (nN), retract distance (nm), retract force (nN)`.
//     A branch may start later or end earlier than the other: its cells are empty in those rows (with blank
//     separators trailing cells may simply be left out). A branch's rows must be contiguous; in the 4-column
//     layout a branch's distance and force are both given or both empty.
//   * Rows may be in either distance order (AFM exports list the approach with decreasing distance), but each
//     branch must be strictly monotone in distance; it is sorted ascending. Each branch needs ≥ 4 points.
//   * Errors (InputError, message "<origin>:<line>: …"): no header, a column without a unit or with an unknown
//     unit, an unrecognised set of columns (a missing branch), a non-number / nan / inf cell, too many cells,
//     a half-empty 4-column branch, a duplicate or non-monotone distance, a branch with fewer than 4 points
//     (reported at the header line).
//
// The law (TableLaw), gap d in nm (d < 0 penetration), force H in nN (H > 0 repulsive):
//   * inside a branch's table: its PCHIP interpolant (C¹; monotone between consecutive knots, so it never
//     overshoots the data; slopes at the knots by the Fritsch–Butland weighted harmonic mean, at the two ends by
//     the shape-preserving three-point formula);
//   * below the smallest distance (deeper indentation than measured): the straight line continuing the
//     interpolant's end value and slope (C¹) — except the retract branch when it is stiffer at its deepest point
//     than the approach (cells and polymers unload stiffer than they load): then it continues with the approach's
//     end slope (C⁰, a kink at its smallest distance, which becomes a switching gap). How a contact unloads from a
//     depth never measured is unknown; this rule keeps the law from creating energy there;
//   * above the largest distance: 0 — the table must reach out to where the interaction is negligible; the
//     force jumps to 0 there, and that distance is a switching gap of the law.
//   * branch selection: contact-aware by default (docs/force-laws.md#hysteresis) — the retract branch only after
//     the tip reached the contact gap, until it rises above the release gap (where the branches become equal,
//     to the release tolerance); Hysteresis::velocity gives the seed's rule (by the sign of the gap rate).
// Evaluation allocates nothing: the interval is found in O(1) on an evenly spaced table (as AFM exports are), by
// binary search otherwise (measured ≈ 16 ns / 38 ns latency per call for 200 knots, about that of the DMT law).
// A noisy baseline makes the retract force exceed the approach force somewhere, which require_dissipative()
// rejects unless allow_energy_gain is set (smooth or trim the baseline, or opt in); so do a retract table that
// ends before an attractive approach (0 above an attraction), an approach table that ends before a repulsive
// retract, and a retract above the approach at the deepest measured point.
#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "afmkit/impact/force_law.hpp"

namespace afmkit::impact {

/// A measured force curve: each branch sorted by ascending gap [nm], forces in nN (H > 0 repulsive).
struct ForceCurve {
  std::vector<double> approach_gap, approach_force;
  std::vector<double> retract_gap, retract_force;
  std::string origin;  ///< where it came from (file name), used in messages
};

/// Parses a force-curve table (format above); `origin` names it in messages ("<origin>:<line>: …").
/// Throws InputError on malformed input.
ForceCurve parse_force_curve(std::string_view text, const std::string& origin);
/// Reads and parses the file `path` (InputError "cannot open file '<path>'" if it cannot be read).
ForceCurve read_force_curve(const std::string& path);

/// The force law of a measured force curve (rules above). Name "table".
class TableLaw final : public ForceLawModel {
 public:
  /// Validates (InvalidParameter "force_curve"): each branch ≥ 4 points, equal lengths, finite values, strictly
  /// ascending gaps, and an interpolant that stays finite (distances not absurdly close for the forces).
  /// `hysteresis`: contact (the default: the retract branch applies only after the tip reached the contact gap,
  /// until it rises above the release gap; docs/force-laws.md#hysteresis) or velocity (seed-1 eq. 4: the branch
  /// by the sign of the gap rate alone, so any branch difference at positive gap dissipates at every turn).
  /// `release_tolerance` [nN] (contact-aware only; finite, ≥ 0): a branch difference up to it counts as none when
  /// placing the release gap (a measured curve's drag, baseline offset or noise above the pull-off); 0: 1e-9 of the
  /// largest tabulated force. Above the release gap the law is H_a on both branches' behalf.
  explicit TableLaw(ForceCurve curve, bool allow_energy_gain = false, Hysteresis hysteresis = Hysteresis::contact,
                    double release_tolerance = 0.0);

  std::string name() const override { return "table"; }
  double approach(double gap) const override { return approach_.eval(gap); }
  double departure(double gap) const override { return retract_.eval(gap); }
  bool smooth() const override { return false; }  // PCHIP: C¹ at the knots
  /// The largest distance of each branch (where the force jumps to 0); one value if both branches end together.
  /// Contact-aware: also the contact gap and the release gap (the mode switches; the interpolant is C¹ there).
  std::vector<double> switching_gaps() const override { return switching_; }
  Hysteresis hysteresis() const override { return hysteresis_; }
  /// Contact-aware: the release gap d_r = max(contact gap, the largest distance below which the branches differ
  /// by more than the release tolerance somewhere) — exact for the interpolant (the extrema of the cubic difference
  /// between consecutive knots of the union). Above it H_a = H_b to that tolerance (a measured curve whose
  /// branches differ by noise up to the end of the table has d_r = the end of the shorter table's branch
  /// difference, usually the table's end). NaN for velocity-sign switching.
  double release_gap() const override { return hysteresis_ == Hysteresis::contact ? release_ : std::numeric_limits<double>::quiet_NaN(); }
  /// The largest distance at which the interpolated branches differ (by more than the release tolerance); −inf if
  /// never.
  double branch_difference_end() const { return difference_end_; }
  /// Contact: below the bottom of the approach curve's adhesion well (the tabulated distance of its most negative
  /// force); a curve without attraction: below the largest distance where its force is positive.
  double contact_gap() const override;
  /// Below the highest switching gap the branches may differ; above it both are 0 (contact-aware: above the
  /// release gap they are equal).
  bool branch_dependent(int region) const override { return region < dependent_regions_; }
  /// Unless allow_energy_gain: H_a(d) ≥ H_b(d) − 1e-9·max|F| for every distance d, as the law is evaluated —
  /// the cubics between the knots of either branch, the straight lines below the tables (where the difference is
  /// linear: the retract line may not be steeper than the approach line, slopes within 1e-9 counting as equal)
  /// and 0 beyond each table's end; exact (the minimum of the cubic difference between consecutive knots of the
  /// union, no sampling). Else InvalidParameter("force_curve", …) naming the smallest such region, the distance
  /// of the largest excess in it, both forces and which rule of the law applies there.
  void require_dissipative() const override;
  /// ∫_lo^hi (H_a − H_b) dd, exact for the interpolant and the rules beyond the table (each cubic piece and the
  /// linear continuation integrated in closed form) [nN·nm]. The generic adaptive quadrature of
  /// hysteresis_energy_loss does not reach its 1e-9 tolerance on a realistic table (the integrand is only C¹ at
  /// every knot), so the law supplies the integral itself.
  double hysteresis_area(double lo, double hi) const override;

  const ForceCurve& curve() const& { return curve_; }
  bool allow_energy_gain() const { return allow_gain_; }

 private:
  /// One PCHIP branch: knots x (strictly ascending) and per knot i the cubic on [x_i, x_{i+1}] in Horner form,
  /// with t = d − x_i: y + t (c1 + t (c2 + t c3)) (c1 = slope at x_i; the last piece holds the end value and slope).
  struct Piece {
    double y, c1, c2, c3;
  };
  struct Branch {
    std::vector<double> x;
    std::vector<Piece> piece;
    std::vector<double> cumulative;  // ∫_{x_0}^{x_i} of the interpolant
    double inverse_mean_step = 0.0;   // (n − 1)/(x_{n−1} − x_0): the interval of an evenly spaced table in O(1)
    double below_slope = 0.0;         // slope of the straight line below x_0 (the end slope, or see above)
    double eval(double d) const;
    std::size_t locate(double d) const;  // i with x_i ≤ d < x_{i+1} (binary search), for x_0 ≤ d < x_{n−1}
    /// The branch on an open interval (a, b) holding no knot, as a cubic in t = d − a: the piece's cubic shifted
    /// to a, the straight line below the table, or 0 beyond it.
    Piece local(double a, double b) const;
    double integral(double d) const;  // ∫_{x_0}^{d} of the branch (negative below x_0, constant above x_{n−1})
  };
  static Branch build(const std::vector<double>& x, const std::vector<double>& y, const std::string& what,
                      const std::string& origin);

  ForceCurve curve_;
  bool allow_gain_;
  Branch approach_, retract_;
  std::vector<double> switching_;
  Hysteresis hysteresis_ = Hysteresis::contact;
  double difference_end_ = 0.0;  // largest distance where the branches differ (−inf: nowhere)
  double release_ = 0.0;         // max(contact gap, difference_end_)
  int dependent_regions_ = 0;    // regions below this index may have H_a ≠ H_b
  double compute_difference_end(double tolerance) const;
};

}  // namespace afmkit::impact
