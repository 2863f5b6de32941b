// Robust tuning by coarse grid + Nelder–Mead on the worst-case decay rate (tuning.hpp).
#include "afmkit/control/tuning.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <numbers>

#include <omp.h>

#include "afmkit/control/delay_margin.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/core/parallel.hpp"
#include "afmkit/core/computed.hpp"
#include "afmkit/core/validate.hpp"
#include "spectra_detail.hpp"
#include "tracking.hpp"

namespace afmkit::control {

using spectra_detail::RootTracker;
using spectra_detail::TrackedSpectrum;

namespace {
void check(const RobustTuningSpec& s) {
  validate::non_negative("delay_max", s.delay_max);
  validate::in_range("delay_points", static_cast<long>(s.delay_points), 1L, 10000L);
  validate::positive("gain_ratio_min", s.gain_ratio_min);
  validate::positive("gain_ratio_max", s.gain_ratio_max);
  validate::require(s.gain_ratio_max >= s.gain_ratio_min, "gain_ratio_max", s.gain_ratio_max, ">= gain_ratio_min");
  validate::in_range("gain_points", static_cast<long>(s.gain_points), 1L, 10000L);
  spectra_detail::validate_window(s.x_min, s.x_max, s.y_min, s.y_max);
  validate::in_range("coarse_points", static_cast<long>(s.coarse_points), 2L, 10000L);
  validate::in_range("max_evaluations", static_cast<long>(s.max_evaluations), 0L, 1000000L);
  validate::in_range("tolerance", s.tolerance, 1e-12, 1.0);
  validate::in_range("threads", static_cast<long>(s.threads), 0L, 1024L);
}

std::vector<double> gain_grid(const RobustTuningSpec& s) {
  std::vector<double> r(s.gain_points);
  for (int j = 0; j < s.gain_points; ++j)
    r[j] = s.gain_points == 1 ? s.gain_ratio_min
                              : s.gain_ratio_min * std::pow(s.gain_ratio_max / s.gain_ratio_min,
                                                            static_cast<double>(j) / (s.gain_points - 1));
  return r;
}

// The τ = 0 spectra of the last evaluated point (one per ρ) and where it was.
struct WarmStart {
  std::vector<TrackedSpectrum> spectra;
  double x = 0.0, y = 0.0;
};

// J(x, y) with warm starts at τ = 0 from the previous point when it is near (within a tenth of the window; always
// for N = ∞, whose τ = 0 spectrum has no finite list to start from), else a fresh tracked spectrum.
class Objective {
 public:
  explicit Objective(const RobustTuningSpec& spec) : spec_(spec), rhos_(gain_grid(spec)) {
    const int n = spec.delay_points;
    for (int i = 0; i < n; ++i) taus_.push_back(n == 1 ? spec.delay_max : spec.delay_max * i / (n - 1));
    // τ continuation sub-steps of at most T/50
    const double period = 2.0 * std::numbers::pi / spec.family.rotation_frequency;
    substeps_ = std::max(1, static_cast<int>(std::ceil(spec.delay_max / std::max(1, n - 1) / (period / 50.0))));
    small_bank_ = spec.family.harmonics <= spectra_detail::kCollocationMaxHarmonics;
  }
  double operator()(double x, double y, WarmStart& warm, double* wd, double* wr) const {
    if (warm.spectra.size() != rhos_.size()) warm.spectra.assign(rhos_.size(), TrackedSpectrum{});
    const bool near = spec_.family.neutral() || std::hypot((x - warm.x) / (spec_.x_max - spec_.x_min),
                                                           (y - warm.y) / (spec_.y_max - spec_.y_min)) <= 0.1;
    warm.x = x;
    warm.y = y;
    double worst = INFINITY;
    for (std::size_t j = 0; j < rhos_.size(); ++j) {
      const LoopSpec l0 = spec_.family.at(x, y, 0.0, rhos_[j]);
      TrackedSpectrum s = (warm.spectra[j].roots.empty() || !near) ? tracker_.initial(l0)
                                                                   : tracker_.update(l0, warm.spectra[j], true);
      warm.spectra[j] = s;
      double prev = 0.0;
      for (double tau : taus_) {
        if (tau > 0.0) {
          s = advance(x, y, rhos_[j], s, prev, tau);
          // finite banks: merge a fresh collocation spectrum at the largest delay (chain roots from −∞)
          // (large banks start from the delay-free poles, which hold no chain roots: nothing to merge)
          if (!spec_.family.neutral() && tau == taus_.back() && small_bank_)
            s = tracker_.merge(s, tracker_.initial(spec_.family.at(x, y, tau, rhos_[j])));
        }
        prev = tau;
        const double decay = -s.abscissa();
        if (decay < worst) {
          worst = decay;
          if (wd) *wd = tau;
          if (wr) *wr = rhos_[j];
        }
      }
    }
    return worst;
  }
  const std::vector<double>& taus() const { return taus_; }

  // number of roots of `a` within 0.5 Ω of the abscissa of `ref` (the ones that matter for J)
  static std::size_t relevant(const TrackedSpectrum& a, const TrackedSpectrum& ref) {
    const double cut = ref.abscissa() - 0.5 * ref.omega;
    return static_cast<std::size_t>(std::count_if(a.roots.begin(), a.roots.end(), [cut](auto r) { return r.real() >= cut; }));
  }

  // τ continuation from t0 to t1 in sub-steps; a step that loses tracked roots (two Newton runs converging to the
  // same root) is halved, down to T/2000.
  TrackedSpectrum advance(double x, double y, double rho, TrackedSpectrum s, double t0, double t1) const {
    const double period = 2.0 * std::numbers::pi / spec_.family.rotation_frequency;
    double t = t0, h = (t1 - t0) / substeps_;
    while (t < t1) {
      const double tn = std::min(t1, t + h);
      TrackedSpectrum next = tracker_.update(spec_.family.at(x, y, tn, rho), s, tn == t1);
      if (relevant(next, s) < relevant(s, s) && h > period / 2000.0) {
        h *= 0.5;
        continue;
      }
      s = std::move(next);
      t = tn;
    }
    return s;
  }
  const std::vector<double>& rhos() const { return rhos_; }

 private:
  const RobustTuningSpec& spec_;
  std::vector<double> rhos_, taus_;
  int substeps_ = 1;
  bool small_bank_ = true;
  RootTracker tracker_{24};
};
}  // namespace

double worst_case_decay(const RobustTuningSpec& spec, double x, double y, double* worst_delay,
                        double* worst_gain_ratio) {
  check(spec);
  WarmStart warm;
  return Objective(spec)(x, y, warm, worst_delay, worst_gain_ratio);
}

namespace {
// robust_tuning on checked arguments (the public function checks them first)
RobustTuning robust_tuning_checked(const RobustTuningSpec& spec, const std::function<void(long, long)>& progress) {
  const Objective objective(spec);
  RobustTuning out;
  const int n = spec.coarse_points;
  const long total = static_cast<long>(n) * n + spec.max_evaluations;
  for (int i = 0; i < n; ++i) {
    out.coarse_x.push_back(spec.x_min + (spec.x_max - spec.x_min) * i / (n - 1));
    out.coarse_y.push_back(spec.y_min + (spec.y_max - spec.y_min) * i / (n - 1));
  }
  out.coarse_worst_decay.assign(static_cast<std::size_t>(n) * n, 0.0);
  ExceptionCollector errors;
  const int nt = spec.threads > 0 ? spec.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
  for (int j = 0; j < n; ++j) {
    errors.run([&] {
      WarmStart warm;
      for (int i = 0; i < n; ++i) {
        spec.cancellation.check();
        out.coarse_worst_decay[static_cast<std::size_t>(j) * n + i] =
            objective(out.coarse_x[i], out.coarse_y[j], warm, nullptr, nullptr);
      }
      if (progress) progress(n, total);
    });
  }
  errors.rethrow();
  out.evaluations = n * n;
  const auto best = std::max_element(out.coarse_worst_decay.begin(), out.coarse_worst_decay.end()) -
                    out.coarse_worst_decay.begin();
  double bx = out.coarse_x[best % n], by = out.coarse_y[best / n];

  // Nelder–Mead on −J, clamped to the window
  WarmStart warm;
  const auto clamp = [&](std::array<double, 2> p) {
    p[0] = std::clamp(p[0], spec.x_min, spec.x_max);
    p[1] = std::clamp(p[1], spec.y_min, spec.y_max);
    return p;
  };
  int used = 0;
  const auto f = [&](const std::array<double, 2>& p) {
    spec.cancellation.check();
    ++used;
    if (progress) progress(1, total);
    return -objective(p[0], p[1], warm, nullptr, nullptr);
  };
  const double hx = 0.5 * (spec.x_max - spec.x_min) / (n - 1), hy = 0.5 * (spec.y_max - spec.y_min) / (n - 1);
  std::array<std::array<double, 2>, 3> v{clamp({bx, by}), clamp({bx + hx, by}), clamp({bx, by + hy})};
  if (v[1] == v[0]) v[1] = clamp({bx - hx, by});
  if (v[2] == v[0]) v[2] = clamp({bx, by - hy});
  std::array<double, 3> fv{};
  const double tol = spec.tolerance * spec.family.rotation_frequency;
  if (spec.max_evaluations >= 3) {
    for (int k = 0; k < 3; ++k) fv[k] = f(v[k]);
    while (used < spec.max_evaluations) {
      std::array<int, 3> idx{0, 1, 2};
      std::sort(idx.begin(), idx.end(), [&](int a, int b) { return fv[a] < fv[b]; });
      const auto b0 = v[idx[0]], b1 = v[idx[1]], w = v[idx[2]];
      const double size = std::max(std::hypot(b1[0] - b0[0], b1[1] - b0[1]), std::hypot(w[0] - b0[0], w[1] - b0[1]));
      if (size < tol) {
        out.converged = true;
        break;
      }
      const std::array<double, 2> c{0.5 * (b0[0] + b1[0]), 0.5 * (b0[1] + b1[1])};
      const auto along = [&](double t) { return clamp({c[0] + t * (w[0] - c[0]), c[1] + t * (w[1] - c[1])}); };
      const auto r = along(-1.0);
      const double fr = f(r);
      if (fr < fv[idx[0]]) {
        const auto e = along(-2.0);
        const double fe = f(e);
        if (fe < fr) v[idx[2]] = e, fv[idx[2]] = fe;
        else v[idx[2]] = r, fv[idx[2]] = fr;
      } else if (fr < fv[idx[1]]) {
        v[idx[2]] = r, fv[idx[2]] = fr;
      } else {
        const auto k = fr < fv[idx[2]] ? along(-0.5) : along(0.5);
        const double fk = f(k);
        if (fk < std::min(fr, fv[idx[2]])) {
          v[idx[2]] = k, fv[idx[2]] = fk;
        } else {  // shrink towards the best vertex
          for (int q : {idx[1], idx[2]}) {
            v[q] = clamp({0.5 * (v[q][0] + b0[0]), 0.5 * (v[q][1] + b0[1])});
            fv[q] = f(v[q]);
          }
        }
      }
    }
    const int ib = static_cast<int>(std::min_element(fv.begin(), fv.end()) - fv.begin());
    if (-fv[ib] >= out.coarse_worst_decay[best]) {
      bx = v[ib][0];
      by = v[ib][1];
    }
  }
  out.evaluations += used;
  out.x = bx;
  out.y = by;
  warm = WarmStart{};
  out.worst_decay = objective(bx, by, warm, &out.worst_delay, &out.worst_gain_ratio);

  // certified re-evaluation and margins at the optimum
  const std::size_t nt_tau = objective.taus().size(), n_cert = objective.rhos().size() * nt_tau;
  std::vector<double> cert(n_cert);
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
  for (std::size_t i = 0; i < n_cert; ++i) {
    errors.run([&] {
      spec.cancellation.check();
      const LoopSpec loop = spec.family.at(bx, by, objective.taus()[i % nt_tau], objective.rhos()[i / nt_tau]);
      cert[i] = -rightmost_roots(loop).spectral_abscissa;
    });
  }
  errors.rethrow();
  out.certified_worst_decay = *std::min_element(cert.begin(), cert.end());
  std::vector<double> rs{spec.gain_ratio_min};
  if (spec.gain_ratio_min < 1.0 && spec.gain_ratio_max > 1.0) rs.push_back(1.0);
  if (spec.gain_ratio_max != spec.gain_ratio_min) rs.push_back(spec.gain_ratio_max);
  for (double rho : rs) {
    const DelayMargin dm = delay_margin(spec.family.at(bx, by, 0.0, rho));
    out.margins.push_back({rho, dm.stable_at_reference ? dm.upper : std::numeric_limits<double>::quiet_NaN(),
                           dm.upper_frequency});
  }
  return out;
}
}  // namespace

RobustTuning robust_tuning(const RobustTuningSpec& spec, const std::function<void(long, long)>& progress) {
  check(spec);
  // the arguments are checked: what is refused from here on was computed (core/computed.hpp)
  return computed("robust tuning", [&] { return robust_tuning_checked(spec, progress); });
}

}  // namespace afmkit::control
