// The streamed curve (harmonic_balance_curve_chunks) gives the points of the curve held in memory
// (harmonic_balance_curve), bit for bit and in the same order, in chunks of at most the chunk size — for the closed
// form and for a general law, both spacings, with and without the "−" branch — and a failure of the sink stays the
// sink's.
#include <gtest/gtest.h>

#include <cstring>
#include <span>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::tapping {
namespace {

TappingModel chunks_closed_form_model() {
  return {Cantilever(1.0, 100.0), Drive(0.2, 0.995), impact::PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6),
          0.0};
}

TappingModel chunks_dmt_model() {  // k = 40 N/m, f0 = 300 kHz, Q = 400, A_free = 10 nm, R = 10 nm (as pyDAMPF's case)
  const PhysicalCantilever pc(40.0, 300.0, 400.0, 10.0, 1.0);
  return {pc.cantilever(), pc.drive(), pc.normalised_law(impact::DmtLaw(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165)),
          8.0};
}

bool chunks_same_point(const HbPoint& a, const HbPoint& b) {
  return std::memcmp(&a.q, &b.q, sizeof(double)) == 0 && std::memcmp(&a.separation, &b.separation, sizeof(double)) == 0 &&
         std::memcmp(&a.amplitude, &b.amplitude, sizeof(double)) == 0 &&
         std::memcmp(&a.offset, &b.offset, sizeof(double)) == 0 && std::memcmp(&a.phase, &b.phase, sizeof(double)) == 0 &&
         a.branch == b.branch;
}

void chunks_expect_same_curve(const TappingModel& model, const HbCurveOptions& o, const std::string& what,
                              const std::vector<std::size_t>& chunk_sizes) {
  const std::vector<HbPoint> held = harmonic_balance_curve(model, o);
  std::size_t minus = 0;
  for (const HbPoint& p : held) minus += p.branch == HbBranch::Minus ? 1 : 0;
  if (o.include_minus && o.q_min < 0.0) {
    EXPECT_GT(minus, 0u) << what << ": the case has a '-' block";
  }
  for (const std::size_t chunk : chunk_sizes) {
    std::vector<HbPoint> streamed;
    std::vector<std::size_t> sizes;
    const std::size_t count = harmonic_balance_curve_chunks(
        model, o,
        [&](std::span<const HbPoint> part) {
          sizes.push_back(part.size());
          streamed.insert(streamed.end(), part.begin(), part.end());
        },
        chunk);
    EXPECT_EQ(count, held.size()) << what << ", chunk " << chunk;
    ASSERT_EQ(streamed.size(), held.size()) << what << ", chunk " << chunk;
    for (std::size_t k = 0; k < held.size(); ++k)
      ASSERT_TRUE(chunks_same_point(streamed[k], held[k])) << what << ", chunk " << chunk << ", point " << k;
    for (std::size_t k = 0; k < sizes.size(); ++k) {  // full chunks, the last one possibly shorter
      EXPECT_LE(sizes[k], chunk);
      if (k + 1 < sizes.size()) {
        EXPECT_EQ(sizes[k], chunk) << what;
      }
    }
  }
}

TEST(CurveChunks, ClosedFormStreamsTheHeldCurve) {
  for (const HbCurveSpacing spacing : {HbCurveSpacing::Uniform, HbCurveSpacing::RefinedGrazing})
    for (const bool minus : {true, false}) {
      HbCurveOptions o;
      o.q_min = -2.0;
      o.q_max = 1.5;
      o.points = 3001;
      o.spacing = spacing;
      o.include_minus = minus;
      chunks_expect_same_curve(chunks_closed_form_model(), o,
                               std::string("closed form, ") + (minus ? "with" : "without") + " minus", {1, 7, 4096});
    }
}

TEST(CurveChunks, GeneralLawStreamsTheHeldCurve) {
  for (const HbCurveSpacing spacing : {HbCurveSpacing::RefinedGrazing})  // the merge of both sample kinds
    for (const bool minus : {true, false}) {
      HbCurveOptions o;
      o.q_min = -1.0;
      o.q_max = 1.5;
      o.points = 90;  // each sample of a general law evaluates describing functions: few of them
      o.spacing = spacing;
      o.include_minus = minus;
      chunks_expect_same_curve(chunks_dmt_model(), o, std::string("DMT, ") + (minus ? "with" : "without") + " minus",
                               {7, 4096});
    }
}

// A sink that fails (a full disk) ends the curve with its own error, not a numerical failure of the curve.
TEST(CurveChunks, TheSinksErrorPassesThrough) {
  HbCurveOptions o;
  o.points = 5000;
  std::size_t calls = 0;
  EXPECT_THROW(harmonic_balance_curve_chunks(
                   chunks_closed_form_model(), o,
                   [&](std::span<const HbPoint>) {
                     if (++calls == 2) throw InputError("error while writing output file 'x.csv': No space left");
                   },
                   100),
               InputError);
  EXPECT_EQ(calls, 2u);  // it stopped there
  HbCurveOptions bad = o;
  bad.points = 1;
  EXPECT_THROW(harmonic_balance_curve_chunks(chunks_closed_form_model(), bad, [](std::span<const HbPoint>) {}),
               InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
