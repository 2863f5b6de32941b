// Argument principle, Newton refinement and subdivision search on Δ(s) (spectra_detail.hpp).
#include <algorithm>
#include <cmath>
#include <variant>

#include "afmkit/control/stability_tau0.hpp"
#include "spectra_detail.hpp"

namespace afmkit::control::spectra_detail {

LoopView view(const LoopSpec& loop) {
  LoopView v;
  v.omega = loop.rotation_frequency();
  const auto set_bank = [&v](const Bank& b) {
    if (const auto* o = std::get_if<OscillatorBank>(&b)) v.bank = o;
    else v.infinite = &std::get<InfiniteBank>(b);
  };
  if (const auto* sp = std::get_if<SmithPredictor>(&loop.controller)) {
    v.smith = sp;
    set_bank(sp->bank);
  } else if (const auto* o = std::get_if<OscillatorBank>(&loop.controller)) {
    v.bank = o;
  } else {
    v.infinite = &std::get<InfiniteBank>(loop.controller);
  }
  return v;
}

Winding winding(const Evaluator& f, const Box& box) { return winding(f, box, f.omega()); }

NewtonResult newton(const Evaluator& f, cplx guess, double tolerance, int max_iterations, int multiplicity) {
  const double omega = f.omega();
  NewtonResult r;
  cplx s = guess;
  double last = INFINITY;
  for (int it = 1; it <= max_iterations; ++it) {
    const Eval e = f(s);
    cplx step = static_cast<double>(multiplicity) * e.v / e.d;
    if (!(std::isfinite(step.real()) && std::isfinite(step.imag()))) break;
    const double limit = 0.5 * (omega + std::abs(s));
    if (std::abs(step) > limit) step *= limit / std::abs(step);
    s -= step;
    r.iterations = it;
    last = std::abs(step);
    if (last <= tolerance * std::max(omega, std::abs(s))) {
      r.converged = true;
      break;
    }
  }
  r.root = s;
  r.correction = last;
  // Rounding floor: accept a stagnating iteration whose corrections are already tiny.
  if (!r.converged && last <= 1e-9 * std::max(omega, std::abs(s))) r.converged = true;
  return r;
}

std::vector<cplx> delay_free_continuation(const Evaluator& f, double tolerance, std::size_t limit) {
  const double omega = f.omega();
  std::vector<cplx> poles = undelayed_poles(f.loop());
  std::erase_if(poles, [omega](cplx e) { return e.imag() < -1e-9 * omega; });
  if (poles.size() > limit) {
    std::partial_sort(poles.begin(), poles.begin() + static_cast<std::ptrdiff_t>(limit), poles.end(),
                      [](cplx a, cplx b) { return a.real() > b.real(); });
    poles.resize(limit);
  }
  std::vector<cplx> out;
  for (cplx e : poles) {
    const NewtonResult r = newton(f, e, tolerance, 60);
    if (!r.converged) continue;
    cplx s = r.root;
    if (std::abs(s.imag()) < 1e-10 * std::max(omega, std::abs(s))) s = s.real();
    if (s.imag() < 0) s = std::conj(s);
    out.push_back(s);
  }
  // distinct (sorted by imaginary part, neighbours compared: O(N log N))
  std::sort(out.begin(), out.end(), [](cplx a, cplx b) { return a.imag() < b.imag(); });
  std::vector<cplx> uniq;
  for (cplx s : out) {
    bool dup = false;
    for (std::size_t i = uniq.size(); i-- > 0;) {
      if (s.imag() - uniq[i].imag() > 1e-8 * std::max(omega, std::abs(s))) break;
      if (std::abs(uniq[i] - s) <= 1e-8 * std::max(omega, std::abs(s))) dup = true;
    }
    if (!dup) uniq.push_back(s);
  }
  return uniq;
}

bool add_unique(std::vector<cplx>& roots, cplx s, double radius) {
  for (const cplx& r : roots)
    if (std::abs(r - s) <= radius) return false;
  roots.push_back(s);
  return true;
}

bool robust_count(const Evaluator& f, Box& box, int& count) {
  const double omega = f.omega();
  for (int attempt = 0; attempt < 6; ++attempt) {
    const Winding w = winding(f, box);
    if (w.ok) {
      count = w.count;
      return true;
    }
    // nudge the edges outwards by small irrational fractions of Ω
    const double d = omega * 1e-4 * (1.0 + 0.618 * attempt) * std::pow(3.1, attempt);
    box.real_min -= d;
    box.real_max += 0.7 * d;
    box.imag_min -= 0.9 * d;
    box.imag_max += 0.8 * d;
  }
  return false;
}

namespace {
bool inside(const Box& b, cplx s, double slack) {
  return s.real() >= b.real_min - slack && s.real() <= b.real_max + slack && s.imag() >= b.imag_min - slack &&
         s.imag() <= b.imag_max + slack;
}

void search(const Evaluator& f, const Box& box, int count, double tolerance, int depth,
            std::vector<std::pair<cplx, int>>& out) {
  if (count <= 0) return;
  const double omega = f.omega();
  const double wr = box.real_max - box.real_min, wi = box.imag_max - box.imag_min;
  const cplx centre(0.5 * (box.real_min + box.real_max), 0.5 * (box.imag_min + box.imag_max));
  const double diameter = std::hypot(wr, wi);
  const bool tiny = diameter < 1e-7 * std::max(omega, std::abs(centre)) || depth > 60;
  if (count == 1 || tiny) {
    // simple root, or an unresolvable cluster treated as one root of multiplicity `count`
    const NewtonResult r = newton(f, centre, tolerance, 80, count);
    if (r.converged && inside(box, r.root, 1e-9 * std::max(omega, std::abs(r.root)))) {
      out.emplace_back(r.root, count);
      return;
    }
    if (tiny) {
      out.emplace_back(r.converged ? r.root : centre, count);
      return;
    }
  }
  // split the longer side near its middle (offset to avoid symmetric root positions)
  const double frac = 0.5 + 0.0173 * ((depth % 3) - 1);
  for (int attempt = 0; attempt < 5; ++attempt) {
    const double g = frac + 0.0311 * attempt * (attempt % 2 ? 1 : -1);
    Box b1 = box, b2 = box;
    if (wr >= wi) {
      const double x = box.real_min + g * wr;
      b1.real_max = x;
      b2.real_min = x;
    } else {
      const double y = box.imag_min + g * wi;
      b1.imag_max = y;
      b2.imag_min = y;
    }
    const Winding w1 = winding(f, b1);
    if (!w1.ok || w1.count < 0 || w1.count > count) continue;
    search(f, b1, w1.count, tolerance, depth + 1, out);
    search(f, b2, count - w1.count, tolerance, depth + 1, out);
    return;
  }
  // could not split cleanly: best effort from the centre
  const NewtonResult r = newton(f, centre, tolerance, 80, 1);
  if (r.converged) out.emplace_back(r.root, count);
}
}  // namespace

void subdivision_search(const Evaluator& f, const Box& box, int count, double tolerance,
                        std::vector<std::pair<cplx, int>>& out) {
  search(f, box, count, tolerance, 0, out);
}

}  // namespace afmkit::control::spectra_detail
