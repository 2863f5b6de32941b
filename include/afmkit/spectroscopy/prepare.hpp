#pragma once
// From a measured force curve to the force–distance table law (docs/spectroscopy.md): calibration, baseline,
// contact point, tip–sample distance, averaging of repeated curves, binning, snap-in and pull-off, and the table
// law file that `afmkit tapping orbit --law table --force-curve FILE` reads (table_law.hpp). SI units throughout;
// the table is written in nm and nN.
#include <cstddef>
#include <string>
#include <vector>

#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/io/curves/raw_curve.hpp"
#include "afmkit/spectroscopy/baseline.hpp"
#include "afmkit/spectroscopy/binning.hpp"
#include "afmkit/spectroscopy/calibration.hpp"
#include "afmkit/spectroscopy/contact_point.hpp"
#include "afmkit/spectroscopy/events.hpp"

namespace afmkit::spectroscopy {

struct PrepareOptions {
  Calibration calibration;               ///< overrides of the file's k and InvOLS
  double baseline_fraction = 0.3;        ///< farthest fraction of the approach's height range fitted (0, 1]
  std::size_t baseline_min_points = 10;  ///< fewer samples there: InvalidParameter "baseline_fraction"
  ContactPointOptions contact;           ///< method, noise multiple n, R and ν of the fit
  double bin_width = 0;                  ///< [m]; 0: automatic (the approach's distance span / 400, rounded down to 1, 2 or 5 × 10^k)
  /// Trim both branches beyond the interaction range: the largest distance where a branch's binned force leaves
  /// the band ±n·σ/√count, plus 2 bins (beyond it the table law is 0 anyway; noise there is no force).
  bool trim_baseline = true;
  // Whether trimmed or not, both branches then end in the same bin (the smaller of their last bins), at its centre.
};

/// What was found for one curve of the input.
struct CurvePreparation {
  std::string origin;
  double spring_constant = 0, invols = 0;  ///< used [N/m], [m/V] (NaN: not needed)
  std::string spring_constant_source, invols_source;
  BaselineFit baseline;
  ContactPoint contact;
  std::size_t approach_samples = 0, retract_samples = 0;
  std::vector<std::string> notes;  ///< the reader's and calibration's notes; a fit whose residual exceeds 10 σ
  /// The samples, for plots: height z [m], force before the baseline was subtracted [N], tip–sample distance [m],
  /// force after [N].
  ForceSegment approach, retract;
  std::vector<double> approach_raw_force, retract_raw_force, approach_distance, retract_distance;
};

struct PreparedCurve {
  std::vector<CurvePreparation> curves;
  double noise = 0;       ///< force noise σ of one sample [N] (RMS over the curves' baseline fits)
  double bin_width = 0;   ///< used [m]
  BinnedBranch approach, retract;  ///< averaged and binned (distances [m] from the contact point, forces [N])
  CurveEvent snap_in, pull_off;
  double trimmed_at = 0;  ///< largest distance kept [m] (the common end of the branches)
};

/// Prepares the curves (repeated measurements of the same spot): each is calibrated, levelled and given its own
/// contact point; their samples are pooled per branch and binned. Errors: those of calibrate, fit_baseline,
/// find_contact_point, bin_branch; InputError when `curves` is empty; InvalidParameter "bin_width" when a branch
/// keeps fewer than 4 bins (the table law needs 4 points).
PreparedCurve prepare(const std::vector<io::curves::RawCurve>& curves, const PrepareOptions& options = {});

/// The prepared branches as the table law's curve (gaps in nm, forces in nN).
impact::ForceCurve to_force_curve(const PreparedCurve& prepared, const std::string& origin);

/// The header of the table law file: approach distance (nm), approach force (nN), retract distance (nm), retract
/// force (nN) (the 4-column layout of table_law.hpp).
extern const char* const law_columns[4];

}  // namespace afmkit::spectroscopy
