"""Cheap, independent checks of the data behind the seed-1 figures (python/afmkit/figures/seed000.py): the
properties the figures show, computed afresh with afmkit — not a regeneration of the figures."""
import math

import numpy as np
import pytest

import afmkit
from afmkit.figures import ReportEntry, seed000


def _hb_physical(ka, **kw):
    return afmkit.tapping.hb(**seed000._physical_case(ka), **kw)


def test_free_branch_amplitude_is_the_free_amplitude():
    r = _hb_physical(10.0, q_min=0.2, q_max=1.5, points=400)
    free = r["q"] > 1.0
    assert free.sum() > 10
    target = seed000.PHYSICAL["free_amplitude"]  # input: the free amplitude the physical run is scaled to
    assert r.results["free_amplitude"] == pytest.approx(target, rel=1e-6)
    np.testing.assert_allclose(r["amplitude"][free], target, rtol=1e-6)
    np.testing.assert_allclose(r["separation"][free], r["q"][free] * target, rtol=1e-6)  # l = q A_free, no contact
    assert np.all(r["offset"][free] == 0.0)


@pytest.mark.parametrize("ka", seed000.STIFFNESS_RATIOS)
def test_fig3_l_of_q_increasing_at_resonance(ka):
    q, l, _ = seed000._contact_curve(_hb_physical(ka, q_min=-1.0, q_max=1.1, points=1500))
    assert np.all(np.diff(q) > 0)
    assert np.all(np.diff(l) > 0), "l(q) must be increasing for omega = omega_n (seed-1, after eq. 19)"


def test_fig3_contact_curve_collapses_onto_q_equal_1():
    qs = [_hb_physical(ka, separation=10.0, points=200).results["solutions_at_separation"][0]["q"]
          for ka in seed000.STIFFNESS_RATIOS]
    assert all(q < 1.0 for q in qs)
    assert np.all(np.diff(qs) > 0), qs
    assert 1.0 - qs[-1] < 0.02 * (1.0 - qs[0])  # 1000x stiffer: ~90x closer to grazing


def test_fig4_stiff_sample_amplitude_follows_separation():
    s = _hb_physical(1000.0, separation=10.0, points=200).results["solutions_at_separation"]
    assert len(s) == 1
    # eq. 20: l ~ B - A for large K_a (the offset A is small but not negligible)
    assert s[0]["amplitude"] - s[0]["offset"] == pytest.approx(10.0, rel=2e-3)


def test_minimum_separation_limit_matches_ext_e8():
    ka, kb, gamma = 10.0, 8.0, 0.2  # normalised, omega = omega_n = 1
    r = afmkit.tapping.hb(approach_stiffness=ka, departure_stiffness=kb, drive_amplitude=gamma, points=50)
    expected = -(1.0 + (ka + kb) / 2.0) * math.pi * gamma / (2.0 * (ka - kb))
    assert r.results["minimum_separation_limit"] == pytest.approx(expected, rel=1e-9)


def _attractive_hb(ratio, points=3000):
    return afmkit.tapping.hb(**seed000.ATTRACTIVE, frequency_ratio=ratio, q_min=-1.0, q_max=2.5, points=points)


@pytest.mark.parametrize("ratio", seed000.FREQUENCY_RATIOS)
def test_folds_are_where_dl_dq_changes_sign(ratio):
    r = _attractive_hb(ratio)
    folds = r.results["folds"]
    assert folds, "the repulsive-attractive curves of the figure all fold"
    for f in folds:
        seg = [s for s in seed000._branch_lines(r, f["branch"]) if s[0][0] < f["q"] < s[0][-1]]
        assert len(seg) == 1
        q, l, _ = seg[0]
        i = np.searchsorted(q, f["q"])
        lo, hi = max(i - 3, 0), min(i + 3, len(q) - 1)
        before, after = l[lo + 1] - l[lo], l[hi] - l[hi - 1]
        assert before * after < 0, (f, before, after)
        # the fold is the extreme of l on its neighbourhood
        near = l[lo:hi + 1]
        if f["kind"] == "maximum":
            assert f["separation"] >= near.max() - 1e-9 * abs(f["separation"])
        else:
            assert f["separation"] <= near.min() + 1e-9 * abs(f["separation"])


def test_instrument_sweep_jumps_bracket_the_hb_prediction():
    h = _attractive_hb(seed000.SWEEP_RATIO, points=2000).results
    fold = max(f["separation"] for f in h["folds"])
    seps = list(np.linspace(8.5, 10.5, 81))
    s = afmkit.tapping.sweep(**seed000.ATTRACTIVE, frequency_ratio=seed000.SWEEP_RATIO, separations=seps)
    tol = s.results["jump_tolerance"]  # jumps are located (docs/theory-tapping.md#located-jumps), not grid points
    (up,), (down,) = s.results["retract_jumps"], s.results["approach_jumps"]
    assert abs(down - h["free_amplitude"]) <= tol  # jump into contact at grazing (ext. E7)
    assert fold <= up <= fold + 0.02 * fold  # jump off contact just past the HB fold (HB ~1 % accurate)
    assert down < up  # hysteresis


def test_orbits_agree_with_hb_in_the_bistable_window():
    o = afmkit.tapping.orbit(**seed000.ATTRACTIVE, frequency_ratio=seed000.SWEEP_RATIO, separation=9.6)
    hb = sorted(h["amplitude"] for h in o.results["harmonic_balance"])
    b = np.sort(o["amplitude"])
    assert len(b) == len(hb) == 3
    np.testing.assert_allclose(b, hb, rtol=0.01)
    stable = o["stable"][np.argsort(o["amplitude"])]
    assert list(stable) == [1, 0, 1]  # free and large contact orbit stable, the middle one a saddle


def test_hb_vs_exact_difference_is_small_on_the_branch():
    case = seed000.ORBIT_CASES[0]
    cont = afmkit.tapping.sweep(**case["model"], mode="continuation", separation_min=case["window"][0],
                                separation_max=case["window"][1])
    assert len(cont.results["folds"]) >= 1
    d = seed000._hb_vs_exact(cont, 10.1)
    assert set(d) == {"stable", "unstable"}
    assert all(v[0] < 0.02 for v in d.values()), d
    assert np.any(cont["stable"] == 0) and np.any(cont["stable"] == 1)


def test_impact_restitution_is_sqrt_of_stiffness_ratio():
    for ratio in (0.1, 0.64):
        r = afmkit.impact(law="hysteresis", approach_stiffness=10.0, departure_stiffness=10.0 * ratio,
                          method="integrator", mass1=3.0, mass2=0.5, velocity=2.0)
        assert r.results["restitution"] == pytest.approx(math.sqrt(ratio), abs=1e-8)
        assert r.results["kinetic_energy_loss"] == pytest.approx(r.results["energy_loss_area"], rel=1e-8)


def test_helpers():
    assert seed000._runs(np.array([1, 1, 0, 0, 1])) == [(0, 3, 1), (2, 5, 0), (4, 5, 1)]
    assert seed000._runs(np.array([0])) == [(0, 1, 0)]


def test_fig3_draws(tmp_path):
    f = seed000.fig3(tmp_path).report
    assert isinstance(f, ReportEntry) and f.id == "seed000-fig3"
    png = tmp_path / f.filename
    assert png.exists() and png.stat().st_size > 10000
    import matplotlib.image as mpimg
    assert mpimg.imread(png).shape[1] <= 1400
    qs = [float(v) for _, v, _ in f.numbers]
    assert len(qs) == len(seed000.STIFFNESS_RATIOS) and np.all(np.diff(qs) > 0)


def test_figure_list():
    assert seed000.FIGURES[:3] == [seed000.fig3, seed000.fig4, seed000.fig_attractive]
    assert len(set(seed000.FIGURES)) == len(seed000.FIGURES)
