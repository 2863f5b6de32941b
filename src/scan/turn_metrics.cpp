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

bool TurnMetrics::sample(const ScanSample& s) {
  const auto turn = static_cast<std::int64_t>(std::floor(s.angle / (2.0 * std::numbers::pi)));
  if (turn != current_) {
    if (current_ >= 0 && deflection_.count() > 0) close_turn();
    current_ = turn;
    deflection_.clear();
    surface_.clear();
    radius_sum_ = 0.0;
    saturated_ = 0;
  }
  const double c = std::cos(s.angle), sn = std::sin(s.angle);
  deflection_.add(c, sn, s.deflection);
  surface_.add(c, sn, s.surface);
  radius_sum_ += s.radius;
  saturated_ += s.saturated ? 1 : 0;
  return true;
}

}  // namespace afmkit::scan
