// Periodic orbits of a multi-mode cantilever with commensurate drives, by shooting (modal_response.hpp).
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/modal_response.hpp"

namespace afmkit::tapping {

namespace {
int modal_orbit_dimension(const MultiModeModel& m) { return 2 * m.mode_count(); }

Eigen::VectorXd modal_orbit_pack(const TipState& s, int n) {
  Eigen::VectorXd z(n);
  z(0) = s.position;
  z(1) = s.velocity;
  for (int i = 2; i < n; ++i) z(i) = s.modal[i - 2];
  return z;
}

TipState modal_orbit_unpack(const Eigen::VectorXd& z, bool contact) {
  TipState s;
  s.position = z(0);
  s.velocity = z(1);
  s.contact = contact;
  for (int i = 2; i < z.size(); ++i) s.modal[i - 2] = z(i);
  return s;
}
}  // namespace

double common_period(const MultiModeModel& model, int max_multiple) {
  const double t1 = model.drives[0].period();
  if (model.drive_count() == 1) return t1;
  const double ratio = model.drives[1].frequency / model.drives[0].frequency;  // = n_2/n_1
  for (int n1 = 1; n1 <= max_multiple; ++n1) {
    const double n2 = std::round(ratio * n1);
    if (n2 >= 1 && n2 <= max_multiple && std::abs(ratio * n1 - n2) <= 1e-12 * n2) return n1 * t1;
  }
  throw InvalidParameter("drives", fmt::format("the drive frequencies {} and {} are not commensurate (ratio {:.15g} is "
                                               "no n2/n1 with n1, n2 <= {}): the motion has no period",
                                               model.drives[0].frequency, model.drives[1].frequency, ratio,
                                               max_multiple));
}

ModalOrbit modal_periodic_orbit(const MultiModeModel& model, double t0, TipState guess,
                                const ModalShootingOptions& options) {
  const double period = common_period(model, options.max_multiple);
  const int n = modal_orbit_dimension(model);
  const bool contact = guess.contact;
  auto map = [&](const Eigen::VectorXd& z) {
    const SimulationResult r = simulate(model, t0, modal_orbit_unpack(z, contact), t0 + period, options.simulation);
    return modal_orbit_pack(r.state, n);
  };
  ModalOrbit out;
  out.t0 = t0;
  out.period = period;
  Eigen::VectorXd z = modal_orbit_pack(guess, n);
  for (int it = 0; it <= options.max_iterations; ++it) {
    const Eigen::VectorXd f = map(z) - z;
    out.residual = f.norm();
    out.iterations = it;
    if (out.residual <= options.tolerance * std::max(1.0, z.norm())) {
      out.converged = true;
      break;
    }
    if (it == options.max_iterations) break;
    // Jacobian of Φ_T − I by central differences
    Eigen::MatrixXd j(n, n);
    for (int c = 0; c < n; ++c) {
      const double h = 1e-6 * std::max(1.0, std::abs(z(c)));
      Eigen::VectorXd zp = z, zm = z;
      zp(c) += h;
      zm(c) -= h;
      j.col(c) = (map(zp) - map(zm)) / (2.0 * h);
      j(c, c) -= 1.0;
    }
    const Eigen::VectorXd step = j.partialPivLu().solve(-f);
    if (!step.allFinite()) break;
    z += step;
  }
  out.state = modal_orbit_unpack(z, contact);
  return out;
}

}  // namespace afmkit::tapping
