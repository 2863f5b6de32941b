#pragma once
// Test-only reference: classical fixed-step RK4 on the relative coordinate, μ d̈ = H(d) + μ g, with the
// branch chosen by phase and each event (turning point, contact edge, return to d0) located by bisection
// on the length of the last RK4 step. Independent of the library's closed form and of Boost.Odeint.
// The branches take (d, inside): `inside` is the side of the contact edge at the start of the step, so a
// step never mixes the two smooth pieces of a law (each piece is evaluated as its smooth extension).
#include <cmath>
#include <functional>

namespace afmkit_test {

struct ReferenceImpact {
  bool separated = false;
  double minimum_gap = 0, minimum_time = 0, end_time = 0, exit_rate = 0;
};

using Branch = std::function<double(double gap, bool inside)>;

inline ReferenceImpact reference_impact(const Branch& approach, const Branch& departure, double mu, double g,
                                        double d0, double v0, double edge, double h, double t_max = 1e4) {
  struct S {
    double d, v;
  };
  bool dep = false, inside = d0 < edge || (d0 == edge && v0 < 0);
  auto acc = [&](double d) { return (dep ? departure(d, inside) : approach(d, inside)) / mu + g; };
  auto rk4 = [&](S s, double k) {
    const double k1d = s.v, k1v = acc(s.d);
    const double k2d = s.v + 0.5 * k * k1v, k2v = acc(s.d + 0.5 * k * k1d);
    const double k3d = s.v + 0.5 * k * k2v, k3v = acc(s.d + 0.5 * k * k2d);
    const double k4d = s.v + k * k3v, k4v = acc(s.d + k * k3d);
    return S{s.d + k / 6 * (k1d + 2 * k2d + 2 * k3d + k4d), s.v + k / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)};
  };
  ReferenceImpact out;
  S s{d0, v0};
  double t = 0;
  while (t < t_max) {
    // guards: >= 0 means fired; kind 0 turning, 1 contact edge, 2 end
    auto guard = [&](const S& z, int kind) {
      if (kind == 0) return dep ? -z.v : z.v;
      if (kind == 1) return dep ? z.d - edge : edge - z.d;
      return z.d - d0;
    };
    const S trial = rk4(s, h);
    double best = h;
    int best_kind = -1;
    auto check = [&](int kind) {
      if (guard(trial, kind) < 0) return;
      double lo = 0, hi = h;
      for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        (guard(rk4(s, mid), kind) >= 0 ? hi : lo) = mid;
      }
      if (best_kind < 0 || hi < best) {
        best = hi;
        best_kind = kind;
      }
    };
    check(0);
    if ((!dep && !inside) || (dep && inside && edge < d0)) check(1);
    if (dep) check(2);
    s = rk4(s, best);
    t += best;
    if (best_kind == 0) {
      if (dep) return out;  // turned back: captured
      out.minimum_gap = s.d;
      out.minimum_time = t;
      s.v = 0;
      dep = true;
      if (acc(s.d) <= 0) return out;  // stuck
    } else if (best_kind == 1) {
      inside = !inside;
    } else if (best_kind == 2) {
      out.separated = true;
      out.end_time = t;
      out.exit_rate = s.v;
      return out;
    }
  }
  return out;
}

}  // namespace afmkit_test
