"""Cheap, independent checks of the data behind the seed-003 and scan figures (python/afmkit/figures/seed003.py,
scan.py): afmkit's charts, margins and simulations against the crossing formulas of docs/theory-control.md (#stability-tau0, #delay-margin)
computed here in numpy, and the qualitative facts the figures show (decay inside, growth outside, the scan-area
gain). Units: rates in Ω (= 1), delays in T = 2π/Ω.
"""
import cmath
import math

import numpy as np
import pytest

import afmkit
from afmkit.figures import scan as scanfig
from afmkit.figures import seed003

GAMMA = 20.0
TWO_PI = 2.0 * math.pi


# ------------------------------------------------------------------------------------------------ numpy references
def tau_c_single(a, b, kappa=1.0):
    """Delay margin [T] of the one-oscillator loop (eq. 12) from seed-2 ext. E1 (Ω = 1)."""
    p = 2.0 + kappa**2 * a**2
    q = 1.0 - kappa**2 * b**2
    disc = p * p - 4 * q
    best = math.inf
    for nu2 in ((p + math.sqrt(disc)) / 2, (p - math.sqrt(disc)) / 2):
        if nu2 <= 0:
            continue
        nu = math.sqrt(nu2)
        rhs = (nu2 - 1.0) / (kappa * complex(-b, a * nu))
        theta = cmath.phase(rhs)  # e^{-i nu tau} = rhs  =>  tau = (-theta + 2 pi m)/nu
        tau = (-theta) % TWO_PI / nu
        best = min(best, tau)
    return best / TWO_PI


def tau_c_infinite(alpha, beta, rho=1.0, nu_max=12.0):
    """Delay margin [T] of the N = ∞ bank (seed-2 ext. E2 with F_∞ of eq. 29), Ω = 1, by bisection on a grid."""

    def parts(nu):
        s = 1j * nu
        coth = 1.0 / cmath.tanh(math.pi * s)
        F = 1.0 + math.pi * (alpha + beta / s) * coth - beta / s**2
        H1 = 2.0 * (alpha * s + beta) / (s * s + 1.0)
        return F - H1, H1

    def g(nu):
        D, H1 = parts(nu)
        return abs(D) - rho * abs(H1)

    grid = np.linspace(1e-3, nu_max, 200001)
    grid = grid[np.abs(grid - np.round(grid)) > 1e-4]  # keep away from the poles at integer ν
    vals = np.array([g(v) for v in grid])
    best = math.inf
    for i in np.nonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]:
        lo, hi = grid[i], grid[i + 1]
        if hi - lo > 1e-3:  # jumped over a pole
            continue
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if np.sign(g(mid)) == np.sign(g(lo)):
                lo = mid
            else:
                hi = mid
        nu = 0.5 * (lo + hi)
        D, H1 = parts(nu)
        if abs(g(nu)) > 1e-6 * max(1.0, abs(D)):
            continue  # a sign change through a pole, not a root
        theta = cmath.phase(-D / (rho * H1))
        best = min(best, (-theta) % TWO_PI / nu)
    return best / TWO_PI


def beta_critical(n):
    """β_c(N) of docs/theory-control.md#stability-tau0: Σ_{|k|≤N} 1/(ν − k) = 0 on (0, 1), β_c = [Σ_{0<|k|≤N} 1/(k(ν − k))]^{-1}."""
    ks = np.arange(-n, n + 1)
    lo, hi = 1e-12, 1 - 1e-12
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if np.sum(1.0 / (mid - ks)) > 0:
            lo = mid
        else:
            hi = mid
    nu = 0.5 * (lo + hi)
    k = ks[ks != 0]
    return 1.0 / np.sum(1.0 / (k * (nu - k)))


# ------------------------------------------------------------------------------------------------ the references work
def test_references_reproduce_math_md_values():
    # docs/theory-control.md #delay-margin / #stability-tau0 (hand-checked): the references above must be right before they judge afmkit
    assert tau_c_single(0.5, 0.0) == pytest.approx(0.195, abs=6e-4)
    assert tau_c_single(1.0, -1.0) == pytest.approx(0.096, abs=6e-4)
    assert beta_critical(1) == pytest.approx(-1.0 / 3.0, abs=1e-9)
    assert beta_critical(10) == pytest.approx(-0.25993, abs=1e-5)


# ------------------------------------------------------------------------------------------------ Fig. 2 data
def test_single_oscillator_chart_boundary_is_the_crossing_curve():
    """Every boundary point of the (a, b) chart at τ = 0.1T lies on the crossing curve of docs/theory-control.md#delay-margin (or on b = γΩ/K)."""
    tau = 0.1
    r = afmkit.control.chart(controller="single", gain=GAMMA, plant_rate=GAMMA, plant="static", delay=tau,
                             x_min=-0.5, x_max=2.0, y_min=-2.0, y_max=1.5, x_points=6, y_points=6,
                             boundaries_output="", progress=False)
    curves = seed003._boundaries(r)[tau]
    nu = np.concatenate([c[0] for c in curves])
    x = np.concatenate([c[1] for c in curves])
    y = np.concatenate([c[2] for c in curves])
    assert len(nu) > 20
    on_line = nu == 0
    assert np.allclose(y[on_line], 1.0, atol=1e-9)  # b = γΩ/K = 1 (root at s = 0)
    w, t = nu[~on_line], tau * TWO_PI
    a_ref = (w**2 - 1.0) * np.sin(w * t) / w
    b_ref = -(w**2 - 1.0) * np.cos(w * t)
    assert np.max(np.abs(x[~on_line] - a_ref)) < 1e-6
    assert np.max(np.abs(y[~on_line] - b_ref)) < 1e-6
    # the grid agrees with the region: (0.5, 0) stable (τ_c = 0.195 T > 0.1 T), (-0.3, 0) unstable (a < 0)
    xs, ys, Z = seed003._grid(r, "spectral_abscissa")
    assert np.all(np.isfinite(Z))


@pytest.mark.xfail(strict=True, reason="afmkit bug (reported by helper h2): `control chart` mislabels grid points at "
                   "tau = 0 on some grids: -inf abscissa on the row b = 0 (51 x 71), and a band just above b = 1 "
                   "for a < 0.3 marked stable although one root is real positive (50 x 70); 80 x 112 is clean. "
                   "Remove this marker once fixed.")
@pytest.mark.parametrize("nx,ny", [(51, 71), (50, 70)])
def test_single_oscillator_chart_at_tau0_matches_the_quadratic(nx, ny):
    """At τ = 0 eq. 12 is s² + (K/γ)(a s − bΩ) + Ω² = 0: its largest real part is exact at every grid point."""
    r = afmkit.control.chart(controller="single", gain=GAMMA, plant_rate=GAMMA, plant="static", delay=0.0,
                             x_min=-0.5, x_max=2.0, y_min=-2.0, y_max=1.5, x_points=nx, y_points=ny,
                             boundaries_output="", progress=False)
    exact = np.array([max(np.roots([1.0, a, 1.0 - b]).real) for a, b in zip(r["x"], r["y"])])
    assert np.max(np.abs(r["spectral_abscissa"] - exact)) < 1e-6


def test_single_oscillator_chart_at_tau0_on_the_figure_grid():
    """The grid of the Fig. 2 figure (seed003.NX2 × NY2) is clean at τ = 0 (see the xfail test above)."""
    r = afmkit.control.chart(controller="single", gain=GAMMA, plant_rate=GAMMA, plant="static", delay=0.0,
                             x_min=-0.5, x_max=2.0, y_min=-2.0, y_max=1.5, x_points=seed003.NX2,
                             y_points=seed003.NY2, boundaries_output="", progress=False)
    exact = np.array([max(np.roots([1.0, a, 1.0 - b]).real) for a, b in zip(r["x"], r["y"])])
    assert np.max(np.abs(r["spectral_abscissa"] - exact)) < 1e-6


@pytest.mark.parametrize("a,b", [(0.5, 0.0), (1.0, -1.0), (0.1, 0.5)])
def test_single_oscillator_margin_matches_E1(a, b):
    m = afmkit.control.margin(controller="single", a=a, b=b, gain=GAMMA, plant_rate=GAMMA, plant="static")
    assert m.results["critical_delay"] == pytest.approx(tau_c_single(a, b), rel=1e-5)


# ------------------------------------------------------------------------------------------------ Fig. 4 data
def test_infinite_bank_margin_matches_E2_at_universal_point():
    m = afmkit.control.margin(controller="infinite", alpha=0.1, beta=-0.1, gain=GAMMA, plant_rate=GAMMA,
                              plant="static")
    ref = tau_c_infinite(0.1, -0.1)
    assert ref == pytest.approx(0.294, abs=1e-3)
    assert m.results["critical_delay"] == pytest.approx(ref, rel=1e-5)


def test_beta_critical_N10_matches_B5():
    m = afmkit.control.margin(controller="bank", harmonics=10, alpha=0.1, beta=-0.1, gain=GAMMA, plant_rate=GAMMA,
                              plant="static")
    assert m.results["tau0"]["beta_critical"] == pytest.approx(beta_critical(10), rel=1e-6)


@pytest.mark.xfail(strict=True, reason="afmkit bug (reported by helper h2): on the 56 x 71 (alpha, beta) grid of the "
                   "N = inf chart the row beta = 0 gets abscissa 0 (roots: about -0.2), and at tau = 0.25 T the "
                   "points (0.12..0.2, -0.24) are labelled stable though `control roots` finds 2 unstable roots. "
                   "Remove this marker once fixed.")
@pytest.mark.parametrize("delay,alpha,beta", [(0.05, 0.18, 0.0), (0.25, 0.14, -0.24)])
def test_infinite_chart_point_agrees_with_roots(delay, alpha, beta):
    loop = dict(controller="infinite", gain=GAMMA, plant_rate=GAMMA, plant="static", delay=delay)
    r = afmkit.control.chart(x_min=-0.1, x_max=1.0, y_min=-0.4, y_max=1.0, x_points=56, y_points=71,
                             boundaries_output="", progress=False, **loop)
    k = int(np.argmin((r["x"] - alpha) ** 2 + (r["y"] - beta) ** 2))
    q = afmkit.control.roots(alpha=float(r["x"][k]), beta=float(r["y"][k]), **loop)
    assert r["spectral_abscissa"][k] == pytest.approx(q.results["spectral_abscissa"], abs=1e-6)


# ------------------------------------------------------------------------------------------------ Fig. 3 / spot checks
def test_simulation_decays_below_margin_and_grows_above():
    runs = {d: seed003._sim_single(d, 30) for d in (0.05, 0.2)}
    stable, unstable = runs[0.05].results, runs[0.2].results
    assert stable["growth_rate"] < -0.05
    assert stable["residual_first_harmonic"] < 1e-4
    assert unstable["growth_rate"] > 0
    env = unstable["envelope_first_harmonic"]
    assert env[-1] > env[len(env) // 2]
    # the growth rate in time is the rightmost root of the simulated loop (first-order plant, eq. 1):
    # (s + γ)(s² + Ω²) + K e^{-sτ}(a s − bΩ) = 0, solved here by Newton from afmkit's root
    one = dict(controller="single", a=0.5, b=0.0, gain=GAMMA, plant_rate=GAMMA, delay=0.2)
    q = afmkit.control.roots(plant="first_order", **one)
    root = q.results["spectral_abscissa"]
    s = complex(q["real"][0], abs(q["imag"][0]))
    tau = 0.2 * TWO_PI
    for _ in range(30):
        f = (s + GAMMA) * (s * s + 1) + GAMMA * cmath.exp(-s * tau) * 0.5 * s
        df = (s * s + 1) + 2 * s * (s + GAMMA) + GAMMA * cmath.exp(-s * tau) * 0.5 * (1 - tau * s)
        s -= f / df
    assert abs(f) < 1e-10 and s.real == pytest.approx(root, abs=1e-9)
    assert unstable["growth_rate"] == pytest.approx(root, abs=2e-3)
    # the +0.0102 Ω is the root of the static model (eq. 12)
    assert afmkit.control.roots(plant="static", **one).results["spectral_abscissa"] == pytest.approx(0.0102,
                                                                                                      abs=5e-5)


# ------------------------------------------------------------------------------------------------ Fig. 5 data
def test_bank_removes_first_harmonic_and_keeps_the_others():
    r = seed003._sim_bank("bank", 30, 600, 50)
    res = r.results
    assert res["residual_first_harmonic"] < 1e-5
    assert res["max_harmonic_error"] < 1e-4
    assert res["control_first_harmonic"]["abs"] == pytest.approx(GAMMA * 1.0, rel=1e-4)  # u_1 = γ F_1
    # the time series ends on its target
    tail = r["t"] >= 29
    assert np.max(np.abs(r["y"][tail] - r["target"][tail])) < 1e-4


# ------------------------------------------------------------------------------------------------ scan figure data
def test_scan_gsf_images_and_area_gain(tmp_path):
    p = dict(sample="grating", sample_resolution=256, tilt_angle=0.1, end_radius=2e-3, radial_speed=800e-6,
             image_resolution=48)
    off = afmkit.scan(control="off", image_output=str(tmp_path / "off"), **p)
    on = afmkit.scan(control="on", image_output=str(tmp_path / "on"), **p)
    d_off, hdr = scanfig.read_image(str(tmp_path / "off"), "deflection")
    d_on, _ = scanfig.read_image(str(tmp_path / "on"), "deflection")
    assert d_on.shape == (48, 48) and int(hdr["XRes"]) == 48
    assert float(hdr["XReal"]) == pytest.approx(2 * p["end_radius"], rel=0.05)
    # without control the tilt saturates the detector (±2 µm) part way out; with control it never does
    assert off.results["saturated_fraction"] > 0
    assert on.results["saturates_with_control"] is False
    assert on.results["scan_area_gain"] > 1.5
    assert np.isnan(d_off).sum() > np.isnan(d_on).sum()
    # the controlled deflection holds the grating (tens of nm), not the tilt (µm)
    assert np.nanmax(np.abs(d_on)) < 0.2 * np.nanmax(np.abs(d_off))
    # the GSF reader agrees with the per-turn table: the uncontrolled deflection reaches the detector range
    assert np.nanmax(np.abs(d_off)) == pytest.approx(2e-6, rel=0.2)
