// closed_loop_dde(): the closed loop as a linear delay-differential system (finite banks).
#include <Eigen/LU>

#include "afmkit/control/loop.hpp"
#include "afmkit/core/error.hpp"

namespace afmkit::control {

Eigen::MatrixXd DelayDifferentialSystem::undelayed_matrix() const {
  Eigen::MatrixXd m = a0;
  for (const auto& [tau, a] : delayed) m += a;
  return m;
}

std::complex<double> DelayDifferentialSystem::determinant(std::complex<double> s) const {
  const auto n = a0.rows();
  Eigen::MatrixXcd m = s * Eigen::MatrixXcd::Identity(n, n) - a0.cast<std::complex<double>>();
  for (const auto& [tau, a] : delayed) m -= std::exp(-s * tau) * a.cast<std::complex<double>>();
  return Eigen::PartialPivLU<Eigen::MatrixXcd>(m).determinant();
}

namespace {
const OscillatorBank& finite_bank(const Bank& bank) {
  const auto* b = std::get_if<OscillatorBank>(&bank);
  if (!b)
    throw InvalidParameter("controller", "controller: the N = infinity bank has no finite delay-differential "
                                         "form here; use a finite OscillatorBank");
  return *b;
}
}  // namespace

DelayDifferentialSystem closed_loop_dde(const LoopSpec& loop) {
  const SmithPredictor* sp = std::get_if<SmithPredictor>(&loop.controller);
  const Bank bank_variant = sp ? sp->bank
                               : std::visit(
                                     [](const auto& c) -> Bank {
                                       if constexpr (std::is_same_v<std::decay_t<decltype(c)>, SmithPredictor>)
                                         return c.bank;
                                       else
                                         return c;
                                     },
                                     loop.controller);
  const OscillatorBank& bank = finite_bank(bank_variant);
  // Bank realisation z' = A z + b m̂, w = c_out z (u = −w); without x0 when a0 = 0 (disconnected integrator).
  const int off = bank.a0() == 0.0 ? 1 : 0;
  const int nz = bank.state_size() - off;
  const Eigen::MatrixXd a_bank = bank.state_matrix().bottomRightCorner(nz, nz);
  const Eigen::VectorXd b_bank = bank.input_vector().tail(nz);
  const Eigen::RowVectorXd c_out = bank.output_vector().tail(nz);

  const bool plant_state = loop.plant_kind == PlantKind::FirstOrder;
  const bool model_state = sp && sp->model_kind == PlantKind::FirstOrder;
  const int iy = nz, iyh = nz + (plant_state ? 1 : 0);
  const int n = nz + (plant_state ? 1 : 0) + (model_state ? 1 : 0);

  Eigen::MatrixXd a0 = Eigen::MatrixXd::Zero(n, n);
  a0.topLeftCorner(nz, nz) = a_bank;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  b.head(nz) = b_bank;
  // y as a row over the state: static y = u/γ = −c_out z/γ; first order: state y' = −γ y − c_out z.
  Eigen::RowVectorXd y_row = Eigen::RowVectorXd::Zero(n);
  if (plant_state) {
    y_row(iy) = 1.0;
    a0(iy, iy) = -loop.plant_rate;
    a0.row(iy).head(nz) = -c_out;
  } else {
    y_row.head(nz) = -c_out / loop.plant_rate;
  }
  DelayDifferentialSystem sys;
  if (!sp) {
    sys.a0 = a0;
    sys.delayed.emplace_back(loop.delay, b * y_row);
    return sys;
  }
  // Smith: m̂ = y(t − τ − τ_m) + ŷ(t) − ŷ(t − τ_c)
  Eigen::RowVectorXd yh_row = Eigen::RowVectorXd::Zero(n);
  if (model_state) {
    yh_row(iyh) = 1.0;
    a0(iyh, iyh) = -sp->model_rate;
    a0.row(iyh).head(nz) = -c_out;
  } else {
    yh_row.head(nz) = -c_out / sp->model_rate;
  }
  sys.a0 = a0 + b * yh_row;
  sys.delayed.emplace_back(loop.delay + sp->measurement_delay(), b * y_row);
  sys.delayed.emplace_back(sp->correction_delay(), -(b * yh_row));
  return sys;
}

}  // namespace afmkit::control
