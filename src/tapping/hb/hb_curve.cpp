// The parametric separation–amplitude curve (l(q), B(q), A(q), φ(q)) sampled over q (seed-1 eq. 19).
#include <algorithm>
#include <cmath>
#include <exception>

#include "afmkit/core/computed.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "general_harmonic_balance.hpp"

namespace afmkit::tapping {

namespace {

void validate_options(const HbCurveOptions& o) {
  validate::finite("q_min", o.q_min);
  validate::finite("q_max", o.q_max);
  validate::require(o.q_max > o.q_min, "q_max", o.q_max, "> q_min");
  validate::require(o.points >= 2, "points", static_cast<double>(o.points), ">= 2");
  validate::require(o.min_gap > 0.0 && o.min_gap < 1.0, "min_gap", o.min_gap, "in (0, 1)");
}

// Calls visit(q, gap) for every sample by increasing q (gap = 1 − q, exact for the log samples).
template <class Visit>
void for_each_sample(const HbCurveOptions& o, Visit visit) {
  const std::size_t n = o.points;
  // Log samples of the gap s = 1 − q on [max(min_gap, 1 − q_max), 1 − q_min], only where q < 1.
  const double gap_hi = 1.0 - o.q_min;
  const double gap_lo = std::max(o.min_gap, 1.0 - o.q_max);
  const bool refined = o.spacing == HbCurveSpacing::RefinedGrazing && o.q_min < 1.0 && gap_lo < gap_hi;
  const std::size_t n_log = refined && n >= 4 ? n / 2 : 0;  // both parts need ≥ 2 samples
  const std::size_t n_uniform = n - n_log;
  const double log_ratio = refined ? std::log(gap_lo / gap_hi) : 0.0;
  // The log samples exclude gap_hi (q_min is a uniform sample) and, when gap_lo = 1 − q_max, also gap_lo.
  const bool include_lo = o.min_gap > 1.0 - o.q_max;
  const double log_steps = static_cast<double>(include_lo ? n_log : n_log + 1);
  auto uniform_q = [&](std::size_t k) {
    if (k + 1 == n_uniform) return o.q_max;
    return o.q_min + (o.q_max - o.q_min) * static_cast<double>(k) / static_cast<double>(n_uniform - 1);
  };
  auto log_gap = [&](std::size_t k) {
    if (include_lo && k + 1 == n_log) return gap_lo;
    return gap_hi * std::exp(log_ratio * static_cast<double>(k + 1) / log_steps);
  };
  // Merge both sequences by increasing q (uniform: increasing q; log: decreasing gap).
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < n_uniform || j < n_log) {
    if (j >= n_log || (i < n_uniform && uniform_q(i) <= 1.0 - log_gap(j))) {
      const double q = uniform_q(i++);
      visit(q, 1.0 - q);
    } else {
      const double gap = log_gap(j++);
      visit(1.0 - gap, gap);
    }
  }
}

HbPoint curve_point(const HbBranchEvaluation& e, HbBranch branch) {
  return {e.q, e.separation, e.amplitude, e.offset, e.phase, branch};
}

// Any other law: every point at each sample from the traced curve (general_harmonic_balance.hpp).
void general_curve(const TappingModel& model, const HbCurveOptions& options, std::vector<HbPoint>& out) {
  std::vector<double> qs;
  qs.reserve(options.points);
  for_each_sample(options, [&](double q, double) { qs.push_back(q); });
  const detail::GeneralHarmonicBalance hb(model, options.cancellation);
  std::vector<HbPoint> lower;
  out.clear();
  hb.sample(qs, options.include_minus, out, lower, options.cancellation);
  out.insert(out.end(), lower.begin(), lower.end());
}

void curve_of_checked(const TappingModel& model, const HbCurveOptions& options, std::vector<HbPoint>& out) {
  if (model.law.piecewise_linear() == nullptr) {
    general_curve(model, options, out);
    return;
  }
  const HbCoefficients c(model);
  const std::size_t n = options.points;
  // One pass: Plus/Free points fill out[0, …), Minus points out[n, …); then the Minus block is moved down.
  // No allocation when out.capacity() ≥ 2n.
  out.resize(2 * n);
  std::size_t n_plus = 0;
  std::size_t n_minus = 0;
  const double b_free = c.free_amplitude();
  const double phase_free = c.free_phase();
  std::size_t visited = 0;
  for_each_sample(options, [&](double q, double gap) {
    if ((++visited & 4095) == 0) options.cancellation.check();
    if (gap <= 0.0) {
      out[n_plus++] = {q, q * b_free, b_free, 0.0, phase_free, HbBranch::Free};
      return;
    }
    const HbRoots roots = evaluate_branches_at_gap(c, gap, false);
    if (roots.plus.exists) out[n_plus++] = curve_point(roots.plus, HbBranch::Plus);
    if (options.include_minus && roots.minus.exists) out[n + n_minus++] = curve_point(roots.minus, HbBranch::Minus);
  });
  std::copy(out.begin() + static_cast<std::ptrdiff_t>(n), out.begin() + static_cast<std::ptrdiff_t>(n + n_minus),
            out.begin() + static_cast<std::ptrdiff_t>(n_plus));
  out.resize(n_plus + n_minus);
}

// Thrown through computed() when the sink failed (its own exception is kept: a write error stays the sink's,
// never a numerical failure of the curve).
struct SinkStopped {};

// Points handed to a sink in chunks of at most `size`.
class ChunkSink {
 public:
  ChunkSink(const std::function<void(std::span<const HbPoint>)>& sink, std::size_t size) : sink_(sink), size_(size) {
    buffer_.reserve(size_);
  }
  void push(const HbPoint& p) {
    buffer_.push_back(p);
    if (buffer_.size() == size_) flush();
  }
  void flush() {
    if (buffer_.empty()) return;
    count_ += buffer_.size();
    try {
      sink_(std::span<const HbPoint>(buffer_));
    } catch (...) {
      error_ = std::current_exception();
      throw SinkStopped{};
    }
    buffer_.clear();
  }
  std::size_t count() const { return count_; }
  std::exception_ptr error() const { return error_; }

 private:
  const std::function<void(std::span<const HbPoint>)>& sink_;
  std::size_t size_;
  std::vector<HbPoint> buffer_;
  std::size_t count_ = 0;
  std::exception_ptr error_;
};

// Any other law, streamed: the q samples in chunks of `size`, each sampled on the traced curve (the points of a
// sample depend on its q only: the same as one call over every sample); the Minus points of the chunks that have
// some in a second pass.
std::size_t general_curve_chunks(const TappingModel& model, const HbCurveOptions& options, ChunkSink& sink,
                                 std::size_t size) {
  const detail::GeneralHarmonicBalance hb(model, options.cancellation);
  std::vector<double> qs;
  qs.reserve(size);
  std::vector<HbPoint> upper, lower;
  std::vector<bool> has_minus;  // per chunk of samples: one bit each
  auto run_chunks = [&](bool minus_pass) {
    std::size_t index = 0;
    auto sample_chunk = [&] {
      if (qs.empty()) return;
      if (!minus_pass || has_minus[index]) {
        upper.clear();
        lower.clear();
        hb.sample(qs, options.include_minus, upper, lower, options.cancellation);
        if (!minus_pass) has_minus.push_back(!lower.empty());
        for (const HbPoint& p : minus_pass ? lower : upper) sink.push(p);
      }
      ++index;
      qs.clear();
    };
    for_each_sample(options, [&](double q, double) {
      qs.push_back(q);
      if (qs.size() == size) sample_chunk();
    });
    sample_chunk();
  };
  run_chunks(false);
  if (std::find(has_minus.begin(), has_minus.end(), true) != has_minus.end()) run_chunks(true);
  sink.flush();
  return sink.count();
}

// Piecewise-linear laws, streamed: the Plus/Free points in one pass, the Minus points in a second one where the
// first found some (evaluate_branches_at_gap gives both roots of a sample: the same points as curve_of_checked).
std::size_t closed_form_curve_chunks(const TappingModel& model, const HbCurveOptions& options, ChunkSink& sink) {
  const HbCoefficients c(model);
  const double b_free = c.free_amplitude();
  const double phase_free = c.free_phase();
  std::size_t n_minus = 0;
  std::size_t visited = 0;
  for_each_sample(options, [&](double q, double gap) {
    if ((++visited & 4095) == 0) options.cancellation.check();
    if (gap <= 0.0) {
      sink.push({q, q * b_free, b_free, 0.0, phase_free, HbBranch::Free});
      return;
    }
    const HbRoots roots = evaluate_branches_at_gap(c, gap, false);
    if (roots.plus.exists) sink.push(curve_point(roots.plus, HbBranch::Plus));
    if (options.include_minus && roots.minus.exists) ++n_minus;
  });
  if (n_minus > 0) {
    for_each_sample(options, [&](double, double gap) {
      if ((++visited & 4095) == 0) options.cancellation.check();
      if (gap <= 0.0) return;
      const HbRoots roots = evaluate_branches_at_gap(c, gap, false);
      if (roots.minus.exists) sink.push(curve_point(roots.minus, HbBranch::Minus));
    });
  }
  sink.flush();
  return sink.count();
}

}  // namespace

std::size_t harmonic_balance_curve_chunks(const TappingModel& model, const HbCurveOptions& options,
                                          const std::function<void(std::span<const HbPoint>)>& sink,
                                          std::size_t chunk) {
  validate_options(options);
  validate::require(chunk >= 1, "chunk", static_cast<double>(chunk), ">= 1");
  // the options are checked: what is refused from here on was computed (core/computed.hpp)
  ChunkSink out(sink, chunk);
  try {
    return computed("harmonic-balance curve", [&] {
      return model.law.piecewise_linear() == nullptr ? general_curve_chunks(model, options, out, chunk)
                                                     : closed_form_curve_chunks(model, options, out);
    });
  } catch (const SinkStopped&) {
    std::rethrow_exception(out.error());
  }
}

void harmonic_balance_curve(const TappingModel& model, const HbCurveOptions& options, std::vector<HbPoint>& out) {
  validate_options(options);
  // the options are checked: what is refused from here on was computed (core/computed.hpp)
  computed("harmonic-balance curve", [&] { curve_of_checked(model, options, out); });
}

std::vector<HbPoint> harmonic_balance_curve(const TappingModel& model, const HbCurveOptions& options) {
  std::vector<HbPoint> out;
  out.reserve(2 * options.points);
  harmonic_balance_curve(model, options, out);
  return out;
}

}  // namespace afmkit::tapping
