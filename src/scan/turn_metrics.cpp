// Per-turn first harmonics of a spiral scan (turn_metrics.hpp).
#include "afmkit/scan/turn_metrics.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Dense>

namespace afmkit::scan {

void FirstHarmonicFit::add(double c, double s, double v) noexcept {
  ++n_;
  sc_ += c;
  ss_ += s;
  scc_ += c * c;
  scs_ += c * s;
  sss_ += s * s;
  sv_ += v;
  svc_ += v * c;
  svs_ += v * s;
}

void FirstHarmonicFit::add_pair(FirstHarmonicFit& first, FirstHarmonicFit& second, double c, double s, double v,
                                double w) noexcept {
  first.add(c, s, v);
  second.n_ = first.n_;
  second.sc_ = first.sc_;
  second.ss_ = first.ss_;
  second.scc_ = first.scc_;
  second.scs_ = first.scs_;
  second.sss_ = first.sss_;
  second.sv_ += w;
  second.svc_ += w * c;
  second.svs_ += w * s;
}

double FirstHarmonicFit::amplitude() const noexcept {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  if (n_ < 3) return nan;
  Eigen::Matrix3d normal;
  normal << static_cast<double>(n_), sc_, ss_, sc_, scc_, scs_, ss_, scs_, sss_;
  const Eigen::Vector3d rhs(sv_, svc_, svs_);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(normal);
  if (lu.rank() < 3) return nan;
  const Eigen::Vector3d x = lu.solve(rhs);
  return std::hypot(x[1], x[2]);
}

TurnMetrics::TurnMetrics(double tilt_slope, std::function<void(const TurnRecord&)> on_turn)
    : slope_(tilt_slope), on_turn_(std::move(on_turn)) {}

void TurnMetrics::close_turn() {
  TurnRecord r;
  r.turn = current_;
  r.samples = deflection_.count();
  r.radius = radius_sum_ / static_cast<double>(r.samples);
  r.deflection_first_harmonic = deflection_.amplitude();
  r.surface_first_harmonic = surface_.amplitude();
  r.tilt_first_harmonic = r.radius * slope_;
  r.saturated_samples = saturated_;
  ++turns_;
  if (on_turn_) on_turn_(r);
}

void TurnMetrics::angle_trig(double angle) noexcept {
  const double step = angle - last_angle_;
  const double change = step - step_;
  if (since_exact_ >= 0 && since_exact_ < 1024 && std::abs(change) <= 1e-6) {
    const double cd = 1.0 - 0.5 * change * change, sd = change;  // cos δ, sin δ to O(δ³)
    const double cs = cos_step_ * cd - sin_step_ * sd, ss = sin_step_ * cd + cos_step_ * sd;
    const double c = cos_ * cs - sin_ * ss;
    sin_ = sin_ * cs + cos_ * ss;
    cos_ = c;
    ++since_exact_;
  } else {
    cos_ = std::cos(angle);
    sin_ = std::sin(angle);
    if (since_exact_ >= 0 && std::abs(change) > 1e-6) {  // a new step: cache its rotation
      step_ = step;
      cos_step_ = std::cos(step);
      sin_step_ = std::sin(step);
    }
    since_exact_ = 0;
  }
  last_angle_ = angle;
}

bool TurnMetrics::sample(const ScanSample& s) {
  // the turn index floor(θ/2π), recomputed only when θ leaves the current turn's angles
  const bool same_turn = s.angle >= turn_begin_ && s.angle < turn_end_;
  const auto turn = same_turn ? current_ : static_cast<std::int64_t>(std::floor(s.angle / (2.0 * std::numbers::pi)));
  if (!same_turn) {
    turn_begin_ = 2.0 * std::numbers::pi * static_cast<double>(turn);
    turn_end_ = 2.0 * std::numbers::pi * static_cast<double>(turn + 1);
  }
  if (turn != current_) {
    if (current_ >= 0 && deflection_.count() > 0) close_turn();
    current_ = turn;
    deflection_.clear();
    surface_.clear();
    radius_sum_ = 0.0;
    saturated_ = 0;
  }
  angle_trig(s.angle);
  const double c = cos_, sn = sin_;
  FirstHarmonicFit::add_pair(deflection_, surface_, c, sn, s.deflection, s.surface);
  radius_sum_ += s.radius;
  saturated_ += s.saturated ? 1 : 0;
  return true;
}

}  // namespace afmkit::scan
