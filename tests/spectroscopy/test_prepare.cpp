// Preparation of measured force curves (spectroscopy/prepare.hpp) on synthetic raw curves made from known models:
// the baseline, noise, contact point, modulus, snap-in and pull-off are recovered within bounds derived from the
// noise, and the prepared table read back by the table law equals the binned curve.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numeric>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/io/curves/read_curves.hpp"
#include "afmkit/spectroscopy/prepare.hpp"
#include "synthetic_curve.hpp"

namespace sp = afmkit::spectroscopy;
using afmkit_test::SyntheticModel;

namespace {

constexpr double kE = 100e3, kNu = 0.5, kR = 2e-6;
const double kC = 4.0 / 3.0 * kE / (1 - kNu * kNu) * std::sqrt(kR);  // Hertz coefficient [N/m^1.5]

/// Hertz contact (retract 20 % lower: a viscoelastic loss), no attraction.
SyntheticModel hertz_model() {
  SyntheticModel m;
  m.force = [](double s, int branch) { return s < 0 ? (branch == 0 ? 1.0 : 0.8) * kC * std::pow(-s, 1.5) : 0.0; };
  m.window_below = -60e-9;
  m.window_above = 1.2e-6;
  m.step = 2e-9;
  return m;
}

// DMT + van der Waals (sphere–plane, Hamaker H): snap-in on the approach, pull-off at the contact on the retract
constexpr double kH = 2e-20, kRd = 20e-9, kA0 = 0.3e-9, kEstar = 0.1e9;
const double kCd = 4.0 / 3.0 * kEstar * std::sqrt(kRd);
const double kAdhesion = kH * kRd / (6 * kA0 * kA0);  // DMT adhesion force [N]

SyntheticModel dmt_model() {
  SyntheticModel m;
  m.k = 0.5;
  m.invols = 20e-9;
  m.contact = 100e-9;
  m.z_top = 160e-9;
  m.z_bottom = 86e-9;
  m.samples = 2000;
  m.offset = 5e-9;
  m.tilt = -2e-3;
  m.noise_volts = 1e-3;  // σ_d = 0.02 nm, σ_F = 10 pN
  m.force = [](double s, int) {
    const double gap = s + kA0;
    return gap >= kA0 ? -kH * kRd / (6 * gap * gap) : -kAdhesion + kCd * std::pow(kA0 - gap, 1.5);
  };
  m.window_below = -3e-9;
  m.window_above = 15e-9;
  m.step = 0.005e-9;
  return m;
}

/// Independent least-squares slope standard error of the baseline range: σ / √Σ(z − z̄)².
double slope_error(const SyntheticModel& m, double sigma, double from) {
  std::vector<double> z;
  for (std::size_t i = 0; i < m.samples; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(m.samples - 1);
    const double zi = m.z_top + t * (m.z_bottom - m.z_top);
    if (zi >= from) z.push_back(zi);
  }
  const double mean = std::accumulate(z.begin(), z.end(), 0.0) / static_cast<double>(z.size());
  double s = 0;
  for (double v : z) s += (v - mean) * (v - mean);
  return sigma / std::sqrt(s);
}

std::string law_text(const sp::PreparedCurve& p) {
  std::string t = fmt::format("{},{},{},{}\n", sp::law_columns[0], sp::law_columns[1], sp::law_columns[2],
                              sp::law_columns[3]);
  const auto c = sp::to_force_curve(p, "t");
  for (std::size_t i = 0; i < std::max(c.approach_gap.size(), c.retract_gap.size()); ++i) {
    if (i < c.approach_gap.size()) t += fmt::format("{},{},", c.approach_gap[i], c.approach_force[i]);
    else t += ",,";
    if (i < c.retract_gap.size()) t += fmt::format("{},{}\n", c.retract_gap[i], c.retract_force[i]);
    else t += ",\n";
  }
  return t;
}

}  // namespace

TEST(Prepare, HertzCurveRecoversBaselineNoiseContactPointAndModulus) {
  const SyntheticModel m = hertz_model();
  sp::PrepareOptions o;
  o.contact.fit.tip_radius = kR;
  o.contact.fit.poisson_ratio = kNu;
  const sp::PreparedCurve p = sp::prepare({afmkit_test::synthetic_curve(m)}, o);
  ASSERT_EQ(p.curves.size(), 1u);
  const sp::CurvePreparation& c = p.curves[0];
  const double sigma = m.k * m.invols * m.noise_volts;  // force noise of one sample [N]
  EXPECT_EQ(c.spring_constant_source, "file");
  EXPECT_DOUBLE_EQ(c.invols, m.invols);
  // noise: the RMS of ~450 residuals is within 10 % of σ (its relative standard error is 1/√(2n) ≈ 3.3 %)
  EXPECT_NEAR(c.baseline.residual_rms, sigma, 0.1 * sigma);
  // tilt: k·b1 within 5 standard errors of the least-squares slope
  EXPECT_NEAR(c.baseline.slope, m.k * m.tilt, 5 * slope_error(m, sigma, c.baseline.height_from));
  // offset: the line at the middle of the fit range within 5 σ/√n of k·(b0 + b1 z)
  const double zmid = 0.5 * (c.baseline.height_from + c.baseline.height_to);
  EXPECT_NEAR(c.baseline.at(zmid), m.k * (m.offset + m.tilt * zmid),
              5 * sigma / std::sqrt(static_cast<double>(c.baseline.points)));
  // contact point: the Hertz fit's, within 5 of its standard errors; the error itself is sub-nm at this noise
  ASSERT_TRUE(c.contact.fit.has_value());
  EXPECT_GT(c.contact.error, 0.0);
  EXPECT_LT(c.contact.error, 1e-9);
  EXPECT_NEAR(c.contact.position, m.contact, 5 * c.contact.error);
  // the threshold estimate lies inside the sample by about the indentation at which F = 3σ: (3σ/C)^{2/3}
  const double inside = std::pow(3 * sigma / kC, 2.0 / 3.0);
  EXPECT_LT(c.contact.threshold_position, m.contact + 5 * sigma / m.k);
  EXPECT_GT(c.contact.threshold_position, m.contact - 3 * inside);
  // E from the Hertz fit within 5 standard errors of the truth, and the error small (< 1 %)
  const sp::HertzFit& fit = *c.contact.fit;
  EXPECT_NEAR(fit.youngs_modulus, kE, 5 * fit.youngs_modulus_error);
  EXPECT_LT(fit.youngs_modulus_error, 0.01 * kE);
  // no attraction: no snap-in, no pull-off
  EXPECT_FALSE(p.snap_in.detected);
  EXPECT_FALSE(p.pull_off.detected);
  // binned approach against the model: Hertz force at the bin's mean indentation within 5 standard errors (+ the
  // curvature of δ^{3/2} over a bin and the contact point's uncertainty)
  for (std::size_t i = 0; i < p.approach.size(); ++i) {
    const double d = p.approach.distance[i];
    if (d > -20e-9) continue;
    const double model = kC * std::pow(-d, 1.5), slope = 1.5 * kC * std::sqrt(-d);
    const double tol = 5 * p.approach.force_error[i] + slope * (p.bin_width / 2 + 5 * c.contact.error) + 6 * sigma;
    EXPECT_NEAR(p.approach.force[i], model, tol) << "approach bin at " << d * 1e9 << " nm";
  }
}

TEST(Prepare, PreparedTableReadBackByTheTableLawEqualsTheBinnedCurve) {
  const sp::PreparedCurve p = sp::prepare({afmkit_test::synthetic_curve(hertz_model())});
  const afmkit::impact::ForceCurve curve = afmkit::impact::parse_force_curve(law_text(p), "prepared");
  ASSERT_EQ(curve.approach_gap.size(), p.approach.size());
  ASSERT_EQ(curve.retract_gap.size(), p.retract.size());
  // (near the contact the 20 % loss is below the noise of a bin: whether the law creates energy there is the
  // command's check, reported as a status; here the read-back)
  const afmkit::impact::TableLaw law(curve, true);
  for (std::size_t i = 0; i < p.approach.size(); ++i) {
    EXPECT_DOUBLE_EQ(curve.approach_gap[i], p.approach.distance[i] * 1e9);
    EXPECT_NEAR(law.approach(p.approach.distance[i] * 1e9), p.approach.force[i] * 1e9,
                1e-12 * (1 + std::abs(p.approach.force[i] * 1e9)));
  }
  for (std::size_t i = 0; i < p.retract.size(); ++i)
    EXPECT_NEAR(law.departure(p.retract.distance[i] * 1e9), p.retract.force[i] * 1e9,
                1e-12 * (1 + std::abs(p.retract.force[i] * 1e9)));
  // trimmed to the interaction range: the table ends within a few bins of the contact point (+ noise excursions)
  EXPECT_LT(p.approach.distance.back(), 0.2e-6);
  // bins: a monotone grid of multiples of the width
  for (std::size_t i = 1; i < p.approach.size(); ++i) EXPECT_GT(p.approach.distance[i], p.approach.distance[i - 1]);
}

TEST(Prepare, DmtCurveRecoversContactPointSnapInAndPullOff) {
  const SyntheticModel m = dmt_model();
  sp::PrepareOptions o;
  o.contact.method = sp::ContactMethod::dmt;
  o.bin_width = 0.1e-9;
  const sp::PreparedCurve p = sp::prepare({afmkit_test::synthetic_curve(m)}, o);
  const sp::CurvePreparation& c = p.curves[0];
  const double sigma = m.k * m.invols * m.noise_volts;
  ASSERT_TRUE(c.contact.fit.has_value());
  EXPECT_NEAR(c.contact.position, m.contact, 5 * c.contact.error + 0.05e-9);
  EXPECT_NEAR(c.contact.fit->offset, -kAdhesion, 5 * c.contact.fit->offset_error + 3 * sigma);
  // pull-off: at the contact point (DMT breaks there), force −F_ad within the bin's curvature and the noise
  ASSERT_TRUE(p.pull_off.detected);
  EXPECT_NEAR(p.pull_off.distance, 0.0, p.bin_width + 5 * c.contact.error);
  EXPECT_GT(p.pull_off.force, -kAdhesion - 5 * sigma);
  EXPECT_LT(p.pull_off.force, -kAdhesion + kCd * std::pow(p.bin_width, 1.5) + 5 * sigma);
  // snap-in: the approach's adhesion minimum, attractive, above −F_ad, near the contact
  ASSERT_TRUE(p.snap_in.detected);
  EXPECT_LT(p.snap_in.force, -3 * sigma);
  EXPECT_GT(p.snap_in.force, -kAdhesion - 5 * sigma);
  EXPECT_LT(std::abs(p.snap_in.distance), 3e-9);
}

TEST(Prepare, RepeatedCurvesAreAveraged) {
  SyntheticModel a = hertz_model(), b = hertz_model();
  b.seed = 777;
  b.contact = 2.05e-6;  // the second curve's contact 50 nm further: each curve gets its own contact point
  const sp::PreparedCurve one = sp::prepare({afmkit_test::synthetic_curve(a)});
  const sp::PreparedCurve two = sp::prepare({afmkit_test::synthetic_curve(a), afmkit_test::synthetic_curve(b)});
  ASSERT_EQ(two.curves.size(), 2u);
  EXPECT_NEAR(two.curves[1].contact.position - two.curves[0].contact.position, 50e-9,
              5 * std::hypot(two.curves[0].contact.error, two.curves[1].contact.error));
  std::size_t one_count = 0, two_count = 0;
  for (auto n : one.approach.count) one_count += n;
  for (auto n : two.approach.count) two_count += n;
  EXPECT_GT(two_count, one_count);  // the pooled bins hold the samples of both curves
}

TEST(PrepareBadInput, NamesTheParameterOrTheCurve) {
  const auto good = afmkit_test::synthetic_curve(hertz_model());
  {  // k <= 0
    sp::PrepareOptions o;
    o.calibration.spring_constant = -1;
    try { sp::prepare({good}, o); FAIL(); } catch (const afmkit::InvalidParameter& e) { EXPECT_EQ(e.parameter(), "spring_constant"); }
  }
  {  // no k anywhere
    auto raw = good;
    raw.metadata.spring_constant = std::nan("");
    try { sp::prepare({raw}); FAIL(); } catch (const afmkit::InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), "spring_constant");
      EXPECT_NE(std::string(e.what()).find("--spring-constant"), std::string::npos);
    }
  }
  {  // no InvOLS for a signal in volts
    auto raw = good;
    raw.metadata.invols = std::nan("");
    try { sp::prepare({raw}); FAIL(); } catch (const afmkit::InvalidParameter& e) { EXPECT_EQ(e.parameter(), "invols"); }
  }
  {  // no retract
    auto raw = good;
    raw.segments.pop_back();
    try { sp::prepare({raw}); FAIL(); } catch (const afmkit::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("no retract"), std::string::npos) << e.what();
    }
  }
  {  // non-monotone piezo height: the approach goes back up halfway
    auto raw = good;
    auto& z = raw.segments[0].height;
    for (std::size_t i = z.size() / 2; i < z.size(); ++i) z[i] = z[z.size() / 2] + (z[z.size() / 2] - z[i]) * 0.5;
    try { sp::prepare({raw}); FAIL(); } catch (const afmkit::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("not monotone"), std::string::npos) << e.what();
    }
  }
  {  // too few samples in the baseline range
    sp::PrepareOptions o;
    o.baseline_fraction = 0.001;
    try { sp::prepare({good}, o); FAIL(); } catch (const afmkit::InvalidParameter& e) { EXPECT_EQ(e.parameter(), "baseline_fraction"); }
  }
  {  // no contact: the approach stays in the noise band
    SyntheticModel m = hertz_model();
    m.z_bottom = 3e-6;
    try { sp::prepare({afmkit_test::synthetic_curve(m)}); FAIL(); } catch (const afmkit::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("never rises above the noise band"), std::string::npos) << e.what();
    }
  }
}

// The real JPK file (shared/data/force-curves, beside the clone): the vendor's paraboloid Hertz fit (R = 40 nm,
// ν = 0.5) gives E = 233.1 kPa and the contact point 18.03 µm (tip position). Its value is given to 10 nm (±5 nm)
// and its fit range and baseline are not in the file; ours, for baseline fractions 0.1–0.7 and the Hertz or DMT
// model, lie within 18.0393–18.0403 µm (standard error 1.0 nm), 9–10 nm above: tolerance 15 nm. E: ours
// 233.3 ± 3.1 kPa (233.2–234.6 kPa over the same choices): tolerance 2 %.
TEST(PrepareRealFile, JpkVendorHertzFit) {
  const std::string path = std::string(AFMKIT_SOURCE_DIR) + "/../shared/data/force-curves/jpk_spot3-0192.jpk-force";
  if (!std::ifstream(path)) GTEST_SKIP() << "the measured force curves are not beside the clone: " << path;
  std::vector<afmkit::io::curves::RawCurve> curves;
  try {
    curves = afmkit::io::curves::read_curves(path);
  } catch (const afmkit::InputError& e) {
    if (std::string(e.what()).find("not in this build") != std::string::npos) GTEST_SKIP() << e.what();
    throw;
  }
  sp::PrepareOptions o;
  o.contact.fit.tip_radius = 40e-9;
  o.contact.fit.poisson_ratio = 0.5;
  const sp::PreparedCurve p = sp::prepare(curves, o);
  ASSERT_EQ(p.curves.size(), 1u);
  const sp::CurvePreparation& c = p.curves[0];
  EXPECT_NEAR(c.spring_constant, 0.04349, 0.00001);  // the file's (README)
  EXPECT_EQ(c.spring_constant_source, "file");
  ASSERT_TRUE(c.contact.fit.has_value());
  EXPECT_NEAR(c.contact.position, 18.03e-6, 15e-9);
  EXPECT_NEAR(c.contact.fit->youngs_modulus, 233.1e3, 0.02 * 233.1e3);
  // the prepared table is a table law; the cell unloads stiffer than it loads (retract end slope steeper than the
  // approach's at the deepest point): the law continues the retract below the table with the approach's slope
  // (table_law.hpp), so it accepts the curve as it is, and the difference below the table stays that at the
  // deepest point
  const afmkit::impact::TableLaw law(afmkit::impact::parse_force_curve(law_text(p), "jpk"));
  const auto& a = p.approach;
  const auto& r = p.retract;
  const double approach_slope = (a.force[1] - a.force[0]) / (a.distance[1] - a.distance[0]);
  const double retract_slope = (r.force[1] - r.force[0]) / (r.distance[1] - r.distance[0]);
  EXPECT_LT(retract_slope, approach_slope);  // both negative: the retract steeper
  EXPECT_NO_THROW(law.require_dissipative());
  const double deepest = std::min(a.distance.front(), r.distance.front()) * 1e9;  // nm
  EXPECT_NEAR(law.approach(deepest - 50.0) - law.departure(deepest - 50.0),
              law.approach(deepest) - law.departure(deepest), 1e-9);
  EXPECT_EQ(a.distance.back(), r.distance.back());  // both branches end together
  // a pull-off (adhesion) shows on the retract, near the contact
  EXPECT_TRUE(p.pull_off.detected);
  EXPECT_LT(p.pull_off.force, -0.2e-9);
}

TEST(Prepare, AFitTheModelDoesNotDescribeIsNoted) {
  // the Hertz model (no adhesion offset) on the DMT + vdW curve: residuals far above the noise, said in a note
  sp::PrepareOptions o;
  o.bin_width = 0.1e-9;
  const sp::PreparedCurve p = sp::prepare({afmkit_test::synthetic_curve(dmt_model())}, o);
  ASSERT_EQ(p.curves[0].notes.size(), 1u);
  EXPECT_NE(p.curves[0].notes[0].find("the model does not describe this contact"), std::string::npos);
  // the Hertz curve fitted by Hertz: no note
  EXPECT_TRUE(sp::prepare({afmkit_test::synthetic_curve(hertz_model())}).curves[0].notes.empty());
}

TEST(Prepare, PausesAndUnlabelledSegmentsAreTakenByTheirDirection) {
  const auto labelled = afmkit_test::synthetic_curve(hertz_model());
  auto raw = labelled;
  // a dwell at the turning point between the two, and the labels dropped: kinds from the height's direction
  afmkit::io::curves::Segment pause;
  pause.kind = afmkit::io::curves::SegmentKind::pause;
  pause.height.assign(50, raw.segments[0].height.back());
  pause.deflection_volts.assign(50, raw.segments[0].deflection_volts.back());
  raw.segments.insert(raw.segments.begin() + 1, pause);
  raw.segments[0].kind = raw.segments[2].kind = afmkit::io::curves::SegmentKind::unknown;
  const sp::PreparedCurve a = sp::prepare({labelled}), b = sp::prepare({raw});
  EXPECT_EQ(a.curves[0].contact.position, b.curves[0].contact.position);
  EXPECT_EQ(a.approach.force, b.approach.force);
  EXPECT_EQ(a.retract.force, b.retract.force);
}
