"""Figures of seed 1 (Materassi, Basso, Genesio, IEEE CDC 2003: impact dynamics and tapping-mode AFM) and the
tapping / impact figures beyond the paper, every number computed by afmkit.

Parameter values of Figs. 3-4 (the paper gives none): docs/theory-tapping.md#large-stiffness
(the values of seed-1 Figs. 3-4) -- f0 = 300 kHz, Q = 100, k = 40 N/m, omega = omega_n, free amplitude 20 nm,
K_a/omega_n^2 in {1, 10, 100, 1000}, K_b = 0.64 K_a. The repulsive-attractive figures use the case of `afmkit demo`
(normalised units: omega_n = 1, Q = 100, Gamma = 0.2, K_a = 10, K_b = 8, F_a = 0.5, F_b = 1).
"""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import afmkit  # noqa: E402
from afmkit.figures import figure, finish, integer, interval, number, number_list  # noqa: E402

COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"]

# ---------------------------------------------------------------------------------------------------------------
# Parameters (inputs only; every plotted or reported number is computed by afmkit from them)

#: Figs. 3-4 in physical units (docs/theory-tapping.md#large-stiffness).
PHYSICAL = dict(units="physical", spring_constant=40.0, resonance_frequency=300.0, quality_factor=100.0,
                free_amplitude=20.0, frequency_ratio=1.0, law="hysteresis")
#: K_a / omega_n^2 of Figs. 3-4 (the sample stiffness in units of the cantilever's k); K_b = RATIO_B * K_a.
STIFFNESS_RATIOS = [1.0, 10.0, 100.0, 1000.0]
RATIO_B = 0.64
#: separation (nm) at which Figs. 3-4 report q and B for every K_a
PROBE_SEPARATION = 10.0

#: Repulsive-attractive hysteresis (seed-1 eq. 26), normalised units: the `afmkit demo` case.
ATTRACTIVE = dict(law="attractive", quality_factor=100.0, drive_amplitude=0.2, approach_stiffness=10.0,
                  departure_stiffness=8.0, approach_adhesion=0.5, departure_adhesion=1.0)
FREQUENCY_RATIOS = [0.99, 0.995, 1.0, 1.005]
#: the instrument sweep overlaid on the omega = 0.99 omega_n curve (the `afmkit demo` range)
SWEEP_RATIO, SWEEP_RANGE, SWEEP_POINTS, SWEEP_FINE = 0.99, (7.0, 12.0), 101, 0.002

#: HB against exact orbits: the attractive case below resonance and the purely repulsive one above it.
ORBIT_CASES = [
    dict(title="(a) attraction, ω = 0.99 ω_n (K_a = 10, K_b = 8, F_a = 0.5, F_b = 1)",
         model=dict(ATTRACTIVE, frequency_ratio=0.99), window=(7.0, 12.0), probes=[8.5, 9.3, 9.8, 10.05]),
    dict(title="(b) no attraction, ω = 1.005 ω_n (K_a = 10, K_b = 8)",
         model=dict(law="hysteresis", quality_factor=100.0, drive_amplitude=0.2, approach_stiffness=10.0,
                    departure_stiffness=8.0, frequency_ratio=1.005), window=(8.0, 22.0), probes=[11.0, 16.0, 19.0]),
]

#: impacts: approach stiffness (N/m), departure/approach ratios, mass pairs (kg) and approach speeds (nm/s)
IMPACT_KA = 10.0
IMPACT_RATIOS = [0.04, 0.1, 0.2, 0.3, 0.4, 0.5, 0.64, 0.75, 0.85, 0.95, 1.0]
IMPACT_BODIES = [dict(mass1=1.0, mass2=1.0, velocity=1.0), dict(mass1=3.0, mass2=0.5, velocity=2.0)]
IMPACT_LOOP_RATIO = 0.64


# ---------------------------------------------------------------------------------------------------------------
# helpers

def _physical_case(ka_ratio: float, model: dict = PHYSICAL, departure_ratio: float = RATIO_B) -> dict:
    k = model["spring_constant"]
    return dict(model, sample_stiffness_approach=ka_ratio * k,
                sample_stiffness_departure=departure_ratio * ka_ratio * k)


def _color(i: int) -> str:
    return COLORS[i % len(COLORS)]


def _fmt(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def _branch_lines(r, branch: str):
    """Segments (q, l, B) of one branch of a `tapping hb` result, ordered in q and broken where the branch has no
    root at a q sample of the curve (the '-' root exists only on parts of the q range)."""
    q_all = np.unique(r["q"])
    m = r["branch"] == branch
    q, l, b = r["q"][m], r["separation"][m], r["amplitude"][m]
    o = np.argsort(q)
    q, l, b = q[o], l[o], b[o]
    if len(q) == 0:
        return []
    pos = np.searchsorted(q_all, q)
    breaks = np.where(np.diff(pos) > 1)[0] + 1
    return [(qq, ll, bb) for qq, ll, bb in zip(np.split(q, breaks), np.split(l, breaks), np.split(b, breaks))]


def _contact_curve(r):
    """The '+' branch and the free oscillation joined in q order (one curve l(q), B(q))."""
    m = (r["branch"] == "plus") | (r["branch"] == "free")
    o = np.argsort(r["q"][m])
    return r["q"][m][o], r["separation"][m][o], r["amplitude"][m][o]


def _runs(flag):
    """Index ranges [i, j) of constant `flag`, each extended by one point so consecutive runs join."""
    out, i = [], 0
    for j in range(1, len(flag) + 1):
        if j == len(flag) or flag[j] != flag[i]:
            out.append((i, min(j + 1, len(flag)), flag[i]))
            i = j
    return out


def _hb_vs_exact(cont, hb_fold_max):
    """Largest relative difference |B_orbit - B_HB| / B_HB over the continuation points with l at or below the
    largest HB fold (beyond it HB has no contact solution to compare with); B_HB = nearest HB amplitude at l."""
    l, b, bh, st = cont["separation"], cont["amplitude"], cont["hb_amplitude"], cont["stable"]
    ok = np.isfinite(bh) & (l <= hb_fold_max)
    rel = np.abs(b - bh) / bh
    res = {}
    for name, sel in (("stable", ok & (st == 1)), ("unstable", ok & (st == 0))):
        if sel.any():
            k = np.flatnonzero(sel)[np.argmax(rel[sel])]
            res[name] = (rel[k], l[k], int(sel.sum()))
    return res


# ---------------------------------------------------------------------------------------------------------------
# Figures 3 and 4 of the paper

def _fig34_setup(spring_constant, resonance_frequency, quality_factor, free_amplitude, stiffness_ratios,
                 departure_ratio, probe_separation, q_range, points):
    """The checked parameters of Figs. 3-4: (model, stiffness ratios, departure ratio, probe separation, q range)."""
    model = dict(PHYSICAL, spring_constant=number("spring_constant", spring_constant, positive=True),
                 resonance_frequency=number("resonance_frequency", resonance_frequency, positive=True),
                 quality_factor=number("quality_factor", quality_factor, positive=True),
                 free_amplitude=number("free_amplitude", free_amplitude, positive=True))
    ratios = number_list("stiffness_ratios", stiffness_ratios, positive=True, longest=12)
    kb = number("departure_ratio", departure_ratio, positive=True, high=1.0)
    probe = number("probe_separation", probe_separation)
    q = interval("q_range", q_range)
    integer("points", points, low=10, high=100000)
    return model, ratios, kb, probe, q


def _fig34_runs(model, ratios, departure_ratio, probe, q_range, points):
    return [(ka, afmkit.tapping.hb(**_physical_case(ka, model, departure_ratio), q_min=q_range[0], q_max=q_range[1],
                                   points=points, separation=probe)) for ka in ratios]


def _fig34_caption_params(r, p, ratios, departure_ratio) -> str:
    return (f"f0 = {_fmt(p['resonance_frequency'])} kHz, Q = {_fmt(p['quality_factor'])}, k = "
            f"{_fmt(p['spring_constant'])} N/m, ω = ω_n, free amplitude {_fmt(r.results['free_amplitude'])} "
            f"{r.units['separation']}, linear hysteresis law (seed-1 eq. 11) with K_a/ω_n² = "
            f"{', '.join(_fmt(k) for k in ratios)} (sample stiffness "
            f"{', '.join(_fmt(k * p['spring_constant']) for k in ratios)} N/m) and K_b = "
            f"{_fmt(departure_ratio)} K_a (restitution e = √(K_b/K_a) = {_fmt(np.sqrt(departure_ratio))})")


@figure("seed000-fig3")
def fig3(out=None, *, spring_constant: float = PHYSICAL["spring_constant"],
         resonance_frequency: float = PHYSICAL["resonance_frequency"],
         quality_factor: float = PHYSICAL["quality_factor"], free_amplitude: float = PHYSICAL["free_amplitude"],
         stiffness_ratios=tuple(STIFFNESS_RATIOS), departure_ratio: float = RATIO_B,
         probe_separation: float = PROBE_SEPARATION, q_range=(0.2, 1.1), points: int = 2000):
    """Seed 1, Fig. 3: harmonic-balance separation l(q) for several sample stiffnesses (physical units).

    spring_constant (N/m), resonance_frequency (kHz), quality_factor, free_amplitude (nm): the cantilever;
    stiffness_ratios: K_a/ω_n² (sample stiffness in units of k), one curve each; departure_ratio: K_b/K_a;
    probe_separation (nm): where the solutions are marked; q_range, points: the q samples of `tapping hb` (also the
    x range). Returns the Matplotlib Figure (``fig.report``: caption, key numbers); writes the PNG if ``out``."""
    p, ratios, kb, probe, q_range = _fig34_setup(spring_constant, resonance_frequency, quality_factor,
                                                 free_amplitude, stiffness_ratios, departure_ratio,
                                                 probe_separation, q_range, points)
    runs = _fig34_runs(p, ratios, kb, probe, q_range, points)
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    numbers = []
    for i, (ka, r) in enumerate(runs):
        c = _color(i)
        q, l, _ = _contact_curve(r)
        ax.plot(q, l, color=c, lw=1.6, label=f"K_a/ω_n² = {_fmt(ka)}")
        sol = [s for s in r.results["solutions_at_separation"] if s["branch"] != "free"]
        for s in sol:
            ax.plot(s["q"], s["separation"], "o", color=c, ms=4)
            numbers.append((f"q at l = {_fmt(probe)} {r.units['separation']}, K_a/ω_n² = {_fmt(ka)}",
                            f"{s['q']:.6f}", f"tapping hb solutions_at_separation ({s['branch']} branch)"))
    unit = runs[0][1].units["separation"]
    free = runs[0][1].results["free_amplitude"]
    ax.axhline(probe, color="0.6", lw=0.7, ls=":")
    ax.axvline(1.0, color="0.6", lw=0.7, ls="--")
    ax.set_xlim(*q_range)
    ax.set_ylim(-0.25 * free, 1.5 * free)
    ax.set_xlabel("penetration parameter q = (A + l)/B (dimensionless)")
    ax.set_ylabel(f"separation l ({unit})")
    ax.set_title("Separation l versus q for increasing sample stiffness")
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    q_stiff = numbers[-1][1] if numbers else "n/a"
    caption = (f"Harmonic-balance separation l(q) (seed-1 eq. 18, `tapping hb`) for "
               f"{_fig34_caption_params(runs[0][1], p, ratios, kb)}. "
               f"As K_a grows the contact part (q < 1) collapses onto the vertical line q = 1, as in the paper: the "
               f"dots mark the solution at l = {_fmt(probe)} {unit}, at q = {q_stiff} for the stiffest "
               f"sample. For q > 1 (no contact) l = q·A_free. l(q) is increasing (ω = ω_n), so every separation has "
               f"one solution.")
    return finish(fig, out, "seed000-fig3",
                  title="Seed 1, Fig. 3: separation l versus q for increasing sample stiffness",
                  caption=caption, numbers=numbers)


@figure("seed000-fig4")
def fig4(out=None, *, spring_constant: float = PHYSICAL["spring_constant"],
         resonance_frequency: float = PHYSICAL["resonance_frequency"],
         quality_factor: float = PHYSICAL["quality_factor"], free_amplitude: float = PHYSICAL["free_amplitude"],
         stiffness_ratios=tuple(STIFFNESS_RATIOS), departure_ratio: float = RATIO_B,
         probe_separation: float = PROBE_SEPARATION, q_range=(-20.0, 1.5), points: int = 3000):
    """Seed 1, Fig. 4: harmonic-balance amplitude B against separation l for several sample stiffnesses.

    The keywords are those of :func:`fig3` (q_range here reaches into permanent contact, q < −1, drawn dotted).
    Returns the Matplotlib Figure (``fig.report``: caption, key numbers); writes the PNG if ``out``."""
    p, ratios, kb, probe, q_range = _fig34_setup(spring_constant, resonance_frequency, quality_factor,
                                                 free_amplitude, stiffness_ratios, departure_ratio,
                                                 probe_separation, q_range, points)
    runs = _fig34_runs(p, ratios, kb, probe, q_range, points)
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    numbers = []
    for i, (ka, r) in enumerate(runs):
        c = _color(i)
        q, l, b = _contact_curve(r)
        phys = q >= -1.0
        ax.plot(l[phys], b[phys], color=c, lw=1.6, label=f"K_a/ω_n² = {_fmt(ka)}")
        ax.plot(l[q <= -1.0], b[q <= -1.0], color=c, lw=1.0, ls=":")
        for s in r.results["solutions_at_separation"]:
            numbers.append((f"B at l = {_fmt(probe)} {r.units['amplitude']}, K_a/ω_n² = {_fmt(ka)}",
                            f"{s['amplitude']:.4f} {r.units['amplitude']}",
                            f"tapping hb solutions_at_separation ({s['branch']} branch, q = {s['q']:.5f})"))
        lim = r.results.get("minimum_separation_limit")
        if lim is not None:
            numbers.append((f"smallest separation with an oscillation (ext. E8), K_a/ω_n² = {_fmt(ka)}",
                            f"{lim:.4f} {r.units['separation']}", "tapping hb minimum_separation_limit"))
    r0 = runs[0][1]
    unit = r0.units["separation"]
    free = r0.results["free_amplitude"]
    ax.plot([0, free], [0, free], color="0.5", lw=0.8, ls="--", label="B = l (stiff limit, eq. 22)")
    ax.set_xlim(-0.25 * free, 1.5 * free)
    ax.set_ylim(0, 1.5 * free)
    ax.set_xlabel(f"separation l ({unit})")
    ax.set_ylabel(f"amplitude B ({r0.units['amplitude']})")
    ax.set_title("Separation–amplitude curves with increasing force slope")
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    caption = (f"Harmonic-balance amplitude B versus separation l (seed-1 eq. 19, `tapping hb`) for "
               f"{_fig34_caption_params(r0, p, ratios, kb)}. Solid: |q| ≤ 1 and free oscillation; dotted: the "
               f"permanent-contact range q < −1 (physically meaningless, down to q = {_fmt(q_range[0]).replace('-', '−')}). For "
               f"l ≥ {_fmt(free)} {unit} the tip does not "
               f"touch and B = A_free; below, the amplitude follows the separation more and more closely as the "
               f"sample stiffens (B ≈ l, eq. 22, dashed) — the amplitude-modulation imaging principle.")
    return finish(fig, out, "seed000-fig4",
                  title="Seed 1, Fig. 4: separation–amplitude curves for increasing force slope",
                  caption=caption, numbers=numbers)


# ---------------------------------------------------------------------------------------------------------------
# repulsive-attractive hysteresis (after the extraction of the paper)

def _attractive_case_text(a: dict = ATTRACTIVE) -> str:
    return (f"Q = {_fmt(a['quality_factor'])}, Γ = {_fmt(a['drive_amplitude'])} L·ω_n², K_a = "
            f"{_fmt(a['approach_stiffness'])} ω_n², K_b = {_fmt(a['departure_stiffness'])} ω_n², F_a = "
            f"{_fmt(a['approach_adhesion'])} L·ω_n², F_b = {_fmt(a['departure_adhesion'])} L·ω_n²")


def _attractive_model(quality_factor, drive_amplitude, approach_stiffness, departure_stiffness, approach_adhesion,
                      departure_adhesion) -> dict:
    return dict(law="attractive", quality_factor=number("quality_factor", quality_factor, positive=True),
                drive_amplitude=number("drive_amplitude", drive_amplitude, positive=True),
                approach_stiffness=number("approach_stiffness", approach_stiffness, positive=True),
                departure_stiffness=number("departure_stiffness", departure_stiffness, positive=True),
                approach_adhesion=number("approach_adhesion", approach_adhesion, low=0.0),
                departure_adhesion=number("departure_adhesion", departure_adhesion, low=0.0))


@figure("seed000-attractive")
def fig_attractive(out=None, *, quality_factor: float = ATTRACTIVE["quality_factor"],
                   drive_amplitude: float = ATTRACTIVE["drive_amplitude"],
                   approach_stiffness: float = ATTRACTIVE["approach_stiffness"],
                   departure_stiffness: float = ATTRACTIVE["departure_stiffness"],
                   approach_adhesion: float = ATTRACTIVE["approach_adhesion"],
                   departure_adhesion: float = ATTRACTIVE["departure_adhesion"],
                   frequency_ratios=tuple(FREQUENCY_RATIOS), q_range=(-1.0, 2.5), points: int = 4000,
                   sweep_ratio: float = SWEEP_RATIO, sweep_range=SWEEP_RANGE, sweep_points: int = SWEEP_POINTS,
                   sweep_step: float = SWEEP_FINE, axis_limit: float = 22.0):
    """Seed 1, after eq. 33: HB curves with attraction (eq. 26, normalised units), folds, and an approach/retract
    sweep of exact orbits with its jumps.

    quality_factor, drive_amplitude (Γ), approach_stiffness/departure_stiffness (K_a, K_b),
    approach_adhesion/departure_adhesion (F_a, F_b): the model; frequency_ratios: ω/ω_n, one HB curve each;
    q_range, points: the q samples of `tapping hb`; sweep_ratio (one of frequency_ratios), sweep_range,
    sweep_points: the instrument sweep of panel (b), refined with step sweep_step around the HB grazing and fold;
    axis_limit: the separation and amplitude extent of panel (a). Returns the Matplotlib Figure (``fig.report``:
    caption, key numbers); writes the PNG if ``out``."""
    model = _attractive_model(quality_factor, drive_amplitude, approach_stiffness, departure_stiffness,
                              approach_adhesion, departure_adhesion)
    ratios = number_list("frequency_ratios", frequency_ratios, positive=True, longest=12)
    q_min, q_max = interval("q_range", q_range)
    integer("points", points, low=10, high=100000)
    if number("sweep_ratio", sweep_ratio, positive=True) not in ratios:
        raise ValueError(f"sweep_ratio = {sweep_ratio!r} is not allowed: must be one of frequency_ratios "
                         f"({', '.join(_fmt(w) for w in ratios)})")
    lo, hi = interval("sweep_range", sweep_range)
    integer("sweep_points", sweep_points, low=2, high=10000)
    number("sweep_step", sweep_step, positive=True)
    number("axis_limit", axis_limit, positive=True)
    curves = [(w, afmkit.tapping.hb(**model, frequency_ratio=w, q_min=q_min, q_max=q_max, points=points))
              for w in ratios]
    # instrument sweep: a uniform grid, refined (step SWEEP_FINE) around the HB grazing and the HB fold where the
    # jumps are expected, so the jump separations are resolved to SWEEP_FINE
    h99 = dict(curves)[sweep_ratio].results
    seps = list(np.linspace(lo, hi, sweep_points))
    for centre in [h99["free_amplitude"]] + [f["separation"] for f in h99["folds"] if lo < f["separation"] < hi]:
        seps += list(centre + sweep_step * np.arange(-25, 26))
    seps = sorted({round(float(x), 6) for x in seps if lo <= x <= hi})
    sweep = afmkit.tapping.sweep(**model, frequency_ratio=sweep_ratio, mode="instrument", separations=seps)
    unit = curves[0][1].units["separation"]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12.4, 4.8))
    ins = ax.inset_axes([0.62, 0.08, 0.35, 0.35])
    numbers = []
    for i, (w, r) in enumerate(curves):
        c = _color(i)
        first = True
        for branch, ls in (("plus", "-"), ("free", "-"), ("minus", ":")):
            for _, l, b in _branch_lines(r, branch):
                for a in (ax, ins):
                    a.plot(l, b, color=c, lw=1.3, ls=ls, label=f"ω/ω_n = {_fmt(w)}" if (first and a is ax) else None)
                first = False
        for f in r.results["folds"]:
            for a in (ax, ins):
                a.plot(f["separation"], f["amplitude"], "D", mfc="none", mec=c, ms=6)
            numbers.append((f"fold ({f['kind']} of l), ω/ω_n = {_fmt(w)}",
                            f"l = {f['separation']:.4f} {unit}, B = {f['amplitude']:.4f} {unit}",
                            f"tapping hb folds ({f['branch']} branch, q = {f['q']:.6f})"))
        numbers.append((f"free amplitude, ω/ω_n = {_fmt(w)}", f"{r.results['free_amplitude']:.4f} {unit}",
                        "tapping hb free_amplitude"))
    ax.plot([], [], "D", mfc="none", mec="k", label="fold (dl/dq = 0)")
    ax.plot([], [], "k:", label="'−' root of ext. E1")
    ax.set_xlim(0, axis_limit)
    ax.set_ylim(0, axis_limit)
    ax.set_xlabel(f"separation l ({unit})")
    ax.set_ylabel(f"amplitude B ({unit})")
    ax.set_title("(a) harmonic balance, all branches")
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    ins.set_xlim(0, 0.3)
    ins.set_ylim(0, 0.45)
    ins.set_title("tip trapped at the surface", fontsize=7)
    ins.tick_params(labelsize=6)

    # (b) the omega = 0.99 omega_n curve and the instrument sweep
    r99 = dict(curves)[sweep_ratio]
    c99 = _color(ratios.index(sweep_ratio))
    for branch in ("plus", "free"):
        for _, l, b in _branch_lines(r99, branch):
            bx.plot(l, b, color=c99, lw=1.2, alpha=0.7, label="harmonic balance" if branch == "plus" else None)
    for f in r99.results["folds"]:
        if lo <= f["separation"] <= hi:
            bx.plot(f["separation"], f["amplitude"], "D", mfc="none", mec="k", ms=7, label="HB fold")
    marker = {"approach": ("v", "#1f77b4"), "retract": ("^", "#d62728")}
    for d in ("approach", "retract"):
        m = sweep["direction"] == d
        mk, col = marker[d]
        bx.plot(sweep["separation"][m], sweep["amplitude"][m], mk, color=col, ms=3.5, mfc="none",
                label=f"sweep: {d} (exact orbits)")
        idx = np.flatnonzero(m)
        for k in idx[1:]:
            if sweep["jumped"][k] == 1:
                xy = (sweep["separation"][k], sweep["amplitude"][k])
                bx.annotate("", xy=xy, xytext=(sweep["separation"][k - 1], sweep["amplitude"][k - 1]),
                            arrowprops=dict(arrowstyle="->", color=col, lw=1.5))
                bx.annotate(f"{d} jump\nl = {xy[0]:.4f} {unit}", xy=xy, xytext=(12, -28 if d == "approach" else 8),
                            textcoords="offset points", fontsize=8, color=col)
    for d in ("approach", "retract"):
        for lj in sweep.results[f"{d}_jumps"]:
            numbers.append((f"sweep jump on {d}, ω/ω_n = {_fmt(sweep_ratio)}", f"l = {lj:.4f} {unit}",
                            f"tapping sweep {d}_jumps (grid step {sweep_step:g} {unit} near the jump)"))
    bx.set_xlim(lo, hi)
    free99 = r99.results["free_amplitude"]
    amp = sweep["amplitude"]
    bx.set_ylim(np.nanmin(amp) - 0.3, np.nanmax(amp) + 0.4)
    bx.set_xlabel(f"separation l ({unit})")
    bx.set_ylabel(f"amplitude B ({unit})")
    bx.set_title(f"(b) ω = {_fmt(sweep_ratio)} ω_n: approach/retract sweep, jumps and hysteresis")
    bx.legend(loc="lower right", fontsize=8)
    bx.grid(alpha=0.3)
    fig.tight_layout()
    big = [f for f in r99.results["folds"] if f["kind"] == "maximum" and f["separation"] > lo]
    fold_txt = f"{big[0]['separation']:.4f} {unit}" if big else "none"
    caption = (f"Repulsive–attractive hysteresis (seed-1 eq. 26) in normalised units (ω_n = 1, L = length unit): "
               f"{_attractive_case_text(model)}, ω/ω_n = {', '.join(_fmt(w) for w in ratios)}. "
               f"(a) Harmonic balance with both roots of ext. E1 (`tapping hb`): the contact branch bends above the "
               f"free amplitude and folds back (diamonds: dl/dq = 0), so several amplitudes coexist at one "
               f"separation; the inset shows the small-amplitude solutions of a tip trapped at the surface. "
               f"(b) An approach/retract sweep of exact periodic orbits ({len(seps)} separations per direction, "
               f"step {sweep_step:g} {unit} near the HB grazing and fold, `tapping sweep`) jumps into contact on approach at l = "
               f"{', '.join(f'{x:.4f}' for x in sweep.results['approach_jumps'])} {unit} (HB grazing "
               f"{free99:.4f}) and off contact on retract at l = "
               f"{', '.join(f'{x:.4f}' for x in sweep.results['retract_jumps'])} {unit} (HB fold {fold_txt}): "
               f"hysteresis.")
    return finish(fig, out, "seed000-attractive",
                  title="Seed 1, after eq. 33: separation–amplitude curves with attraction — folds, jumps, hysteresis",
                  caption=caption, numbers=numbers)


# ---------------------------------------------------------------------------------------------------------------
# beyond the paper: harmonic balance against exact periodic orbits

def _orbit_cases(cases) -> list:
    """The checked cases of :func:`fig_hb_vs_orbits`."""
    try:
        items = list(cases)
    except TypeError:
        items = []
    if not 1 <= len(items) <= 4:
        raise ValueError(f"cases = {cases!r} is not allowed: must be a list of 1 to 4 dicts with keys model (dict of "
                         f"afmkit.tapping keywords), window (separation range) and probes (separations)")
    out = []
    for i, case in enumerate(items):
        if not isinstance(case, dict) or not isinstance(case.get("model"), dict):
            raise ValueError(f"cases[{i}] = {case!r} is not allowed: must be a dict with a dict 'model' of "
                             f"afmkit.tapping keywords, a 'window' (low, high) and a list 'probes'")
        unknown = set(case) - {"model", "window", "probes", "title"}
        if unknown:
            raise ValueError(f"cases[{i}] has unknown keys {sorted(unknown)}: allowed are model, window, probes, "
                             f"title")
        window = interval(f"cases[{i}].window", case.get("window"))
        probes = number_list(f"cases[{i}].probes", case.get("probes", ()), longest=12) if case.get("probes") else []
        title = case.get("title") or f"({'abcd'[i]}) " + ", ".join(f"{k} = {v}" for k, v in case["model"].items())
        out.append(dict(model=case["model"], window=window, probes=probes, title=str(title)))
    return out


def _shared_model_text(cases) -> str:
    """ "Normalised units, Q = …, Γ = … L·ω_n². " when every case has the same Q and Γ (the caption's common part)."""
    q = {c["model"].get("quality_factor", 100.0) for c in cases}
    g = {c["model"].get("drive_amplitude") for c in cases}
    if len(q) == 1 and len(g) == 1 and None not in g and all(c["model"].get("units", "normalized") != "physical"
                                                            for c in cases):
        return f"Normalised units, Q = {_fmt(q.pop())}, Γ = {_fmt(g.pop())} L·ω_n². "
    return ""


@figure("beyond-hb-vs-orbits")
def fig_hb_vs_orbits(out=None, *, cases=tuple(ORBIT_CASES), points: int = 3000):
    """Beyond the papers: harmonic balance against the exact periodic orbits (stable and unstable branches, folds).

    cases: one panel each, a dict with ``model`` (keywords of afmkit.tapping.hb/sweep/orbit), ``window`` (the
    separation range of the continuation and of the panel), ``probes`` (separations where `tapping orbit` finds
    every orbit) and ``title`` (its first four characters, "(a) ", are dropped in the caption); points: q samples
    of `tapping hb`. Returns the Matplotlib Figure (``fig.report``: caption, key numbers); writes the PNG if
    ``out``."""
    cases = _orbit_cases(cases)
    integer("points", points, low=10, high=100000)
    fig, axes = plt.subplots(1, len(cases), figsize=(6.2 * len(cases), 4.8), squeeze=False)
    numbers_, cap_parts = [], []
    for ax, case, tag in zip(axes[0], cases, "abcd"):
        lo, hi = case["window"]
        model = case["model"]
        hb = afmkit.tapping.hb(**model, q_min=-1.0, q_max=2.5, points=points)
        cont = afmkit.tapping.sweep(**model, mode="continuation", separation_min=lo, separation_max=hi)
        unit = hb.units["separation"]
        for branch in ("plus", "free", "minus"):
            for i, (_, l, b) in enumerate(_branch_lines(hb, branch)):
                ax.plot(l, b, color="0.55", lw=3.0, alpha=0.45,
                        label="harmonic balance" if (branch == "plus" and i == 0) else None)
        l, b, st = cont["separation"], cont["amplitude"], cont["stable"]
        shown = set()
        for i, j, s in _runs(st):
            lab = "exact orbit, stable" if s == 1 else "exact orbit, unstable"
            ax.plot(l[i:j], b[i:j], color="#1f77b4" if s == 1 else "#d62728", lw=1.4, ls="-" if s == 1 else "--",
                    label=lab if lab not in shown else None)
            shown.add(lab)
        hb_folds = [f for f in hb.results["folds"] if lo <= f["separation"] <= hi]
        for f in hb_folds:
            ax.plot(f["separation"], f["amplitude"], "D", mfc="none", mec="k", ms=7,
                    label="HB fold" if f is hb_folds[0] else None)
        for k, lf in enumerate(f["separation"] for f in cont.results["folds"]):
            ax.axvline(lf, color="#d62728", lw=0.8, ls=":", label="exact fold (continuation)" if k == 0 else None)
        for lg in cont.results["grazing"]:
            numbers_.append((f"({tag}) grazing of the free oscillation (exact)", f"l = {lg:.5f} {unit}",
                            "tapping sweep continuation grazing"))
        # tapping orbit: every periodic orbit at a few separations
        n_orbits, multi = 0, []
        for k, lp in enumerate(case["probes"]):
            o = afmkit.tapping.orbit(**model, separation=lp)
            if len(o["amplitude"]) > 1:
                multi.append(f"{len(o['amplitude'])} orbits ({int(np.sum(o['stable'] == 1))} stable) at l = {_fmt(lp)}")
            for a, s, pm in zip(o["amplitude"], o["stable"], o["period_multiple"]):
                ax.plot(lp, a, "o", ms=6, color="k", mfc="k" if s == 1 else "w", zorder=5,
                        label=("`tapping orbit` (filled: stable)" if n_orbits == 0 else None))
                n_orbits += 1
        # HB vs exact
        hb_max = max((f["separation"] for f in hb.results["folds"] if f["kind"] == "maximum"), default=np.inf)
        diff = _hb_vs_exact(cont, hb_max)
        big_exact = max((f["separation"] for f in cont.results["folds"]), default=None)
        big_hb = max((f for f in hb_folds if f["kind"] == "maximum"), key=lambda f: f["separation"], default=None)
        if big_exact is not None and big_hb is not None:
            numbers_.append((f"({tag}) fold (largest l): exact orbit vs HB",
                            f"{big_exact:.4f} vs {big_hb['separation']:.4f} {unit} "
                            f"({100 * (big_exact - big_hb['separation']) / big_hb['separation']:+.2f} %)",
                            "tapping sweep continuation folds; tapping hb folds"))
        for name, (rel, at, n) in diff.items():
            numbers_.append((f"({tag}) max |B_orbit − B_HB|/B_HB, {name} branch",
                            f"{100 * rel:.2f} % (at l = {at:.3f} {unit})",
                            f"tapping sweep continuation, {n} points with l ≤ largest HB fold"))
        cap_parts.append(
            f"({tag}) {case['title'][4:]}: exact fold at l = {big_exact:.4f} {unit} against HB "
            f"{big_hb['separation']:.4f} {unit}; B differs from HB by at most "
            + " and ".join(f"{100 * v[0]:.2f} % ({k})" for k, v in diff.items())
            + (f"; `tapping orbit` finds {', '.join(multi)} {unit}" if multi else "")
            if big_exact is not None and big_hb is not None else f"({tag}) {case['title'][4:]}")
        ax.set_xlim(lo, hi)
        bmax = np.nanmax(b[(l >= lo) & (l <= hi)])
        bmin = np.nanmin(b[(l >= lo) & (l <= hi)])
        ax.set_ylim(bmin - 0.05 * (bmax - bmin) - 0.2, bmax + 0.12 * (bmax - bmin) + 0.2)
        ax.set_xlabel(f"separation l ({unit})")
        ax.set_ylabel(f"amplitude B ({hb.units['amplitude']})")
        ax.set_title(case["title"], fontsize=9.5)
        ax.legend(loc="lower right", fontsize=7.5)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    caption = ("Harmonic balance (grey, `tapping hb`) against the exact periodic orbits of eq. 8 (shooting with "
               "Floquet multipliers: `tapping sweep` in continuation mode through the folds, blue stable / red dashed "
               "unstable; circles: every orbit `tapping orbit` finds at a few separations, filled = stable). "
               + _shared_model_text(cases) + "The unstable middle branch joins the fold to the grazing "
               "of the free oscillation, so between them several orbits coexist. " + "; ".join(cap_parts)
               + " (difference measured at the nearest HB amplitude, over the points with l below the largest HB "
               "fold).")
    return finish(fig, out, "beyond-hb-vs-orbits",
                  title="Beyond the papers: harmonic balance against exact periodic orbits (stability, folds)",
                  caption=caption, numbers=numbers_)


# ---------------------------------------------------------------------------------------------------------------
# beyond the paper: impacts and restitution (seed-1 eqs. 1-6, ext. E0)

def _masses(body: dict) -> str:
    m1, m2 = _fmt(body["mass1"]), _fmt(body["mass2"])
    return f"m1 = m2 = {m1} kg" if m1 == m2 else f"m1 = {m1} kg, m2 = {m2} kg"


@figure("beyond-impact")
def fig_impact(out=None, *, approach_stiffness: float = IMPACT_KA, departure_ratios=tuple(IMPACT_RATIOS),
               bodies=tuple(IMPACT_BODIES), loop_ratio: float = IMPACT_LOOP_RATIO, loop_points: int = 400):
    """Beyond the papers: two-body impacts with the hysteresis law (seed-1 eqs. 1-6): one force-gap loop and the
    coefficient of restitution against √(K_b/K_a).

    approach_stiffness (K_a, N/m); departure_ratios: the K_b/K_a of panel (b); bodies: dicts of mass1, mass2 (kg)
    and velocity (approach speed), one marker series each, the first also drawn in panel (a); loop_ratio: K_b/K_a
    of panel (a); loop_points: samples of its loop. Returns the Matplotlib Figure (``fig.report``: caption, key
    numbers); writes the PNG if ``out``."""
    ka = number("approach_stiffness", approach_stiffness, positive=True)
    ratios = number_list("departure_ratios", departure_ratios, positive=True, high=1.0)
    loop_r = number("loop_ratio", loop_ratio, positive=True, high=1.0)
    integer("loop_points", loop_points, low=2, high=100000)
    try:
        body_list = [dict(b) for b in bodies]
    except (TypeError, ValueError):
        body_list = []
    if not 1 <= len(body_list) <= 4 or any(set(b) != {"mass1", "mass2", "velocity"} for b in body_list):
        raise ValueError(f"bodies = {bodies!r} is not allowed: must be a list of 1 to 4 dicts with keys mass1, "
                         f"mass2 (kg) and velocity")
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11.0, 4.4))
    loop = afmkit.impact(law="hysteresis", approach_stiffness=ka,
                         departure_stiffness=loop_r * ka, method="integrator", points=loop_points,
                         **body_list[0])
    gap, force, rate = loop["gap"], loop["force"], loop["gap_rate"]
    inside = gap <= loop.results["contact_gap"]
    for sel, col, lab in ((inside & (rate < 0), "#1f77b4", "approach (K_a)"),
                          (inside & (rate > 0), "#d62728", "departure (K_b)")):
        o = np.argsort(gap[sel])
        ax.plot(gap[sel][o], force[sel][o], ".-", color=col, ms=3, lw=1.2, label=lab)
    # the area between the branches, both as simulated (departure branch interpolated onto the approach gaps)
    ga, fa = gap[inside & (rate < 0)], force[inside & (rate < 0)]
    gb, fb = gap[inside & (rate > 0)], force[inside & (rate > 0)]
    oa, ob = np.argsort(ga), np.argsort(gb)
    ax.fill_between(ga[oa], np.interp(ga[oa], gb[ob], fb[ob]), fa[oa], color="0.8",
                    label=f"lost energy (eq. 6) = {loop.results['energy_loss_area']:.4g} {loop.results['units']['energy_loss_area']}")
    ax.set_xlabel(f"gap d ({loop.units['gap']})")
    ax.set_ylabel(f"contact force H ({loop.units['force']})")
    ax.set_title(f"(a) one impact, K_a = {_fmt(ka)} N/m, K_b = {_fmt(loop_r * ka)} N/m",
                 fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)

    worst_e, worst_de, worst_res = 0.0, 0.0, 0.0
    for k, bodies in enumerate(body_list):
        mk, col = "ox+^"[k], COLORS[k]
        e_sim, e_formula = [], []
        for ratio in ratios:
            r = afmkit.impact(law="hysteresis", approach_stiffness=ka, departure_stiffness=ratio * ka,
                              method="integrator", points=2, **bodies)
            res = r.results
            e_sim.append(res["restitution"])
            e_formula.append(np.sqrt(ratio))
            mu = res["reduced_mass"]
            de_eq3 = (1 - res["restitution"] ** 2) * mu / 2 * res["approach_gap_rate"] ** 2
            worst_de = max(worst_de, abs(res["kinetic_energy_loss"] - de_eq3) / max(res["kinetic_energy_before"], 1e-300))
            worst_res = max(worst_res, abs(res["energy_balance_residual"]) / res["kinetic_energy_before"])
        e_sim, e_formula = np.array(e_sim), np.array(e_formula)
        worst_e = max(worst_e, float(np.max(np.abs(e_sim - e_formula))))
        bx.plot(ratios, e_sim, mk, color=col, ms=7, mfc="none",
                label=f"simulated, m1 = {_fmt(bodies['mass1'])} kg, m2 = {_fmt(bodies['mass2'])} kg, "
                      f"v = {_fmt(bodies['velocity'])} nm/s")
    kk = np.linspace(0, 1, 200)
    bx.plot(kk, np.sqrt(kk), "k-", lw=1, label="e = √(K_b/K_a) (ext. E0)")
    bx.set_xlabel("K_b / K_a (dimensionless)")
    bx.set_ylabel("coefficient of restitution e (dimensionless)")
    bx.set_title("(b) restitution: simulation against the formula", fontsize=10)
    bx.legend(fontsize=7.5, loc="lower right")
    bx.grid(alpha=0.3)
    fig.tight_layout()
    u = loop.results["units"]
    numbers = [
        (f"restitution, K_b/K_a = {_fmt(loop_r)}: formula vs simulation",
         f"{loop.results['restitution_impulsive_limit']:.6f} vs {loop.results['restitution']:.10f}",
         "impact restitution_impulsive_limit, restitution (integrator)"),
        ("max |e_sim − √(K_b/K_a)| over all runs", f"{worst_e:.2e}",
         f"impact, {len(ratios) * len(body_list)} runs (integrator)"),
        (f"energy loss, K_b/K_a = {_fmt(loop_r)}: kinetic (eq. 3) vs area (eq. 6)",
         f"{loop.results['kinetic_energy_loss']:.6g} vs {loop.results['energy_loss_area']:.6g} {u['energy_loss_area']}",
         "impact kinetic_energy_loss, energy_loss_area"),
        ("max relative |ΔE_kin − (1 − e²)μḋ²/2| (eq. 3)", f"{worst_de:.2e}", "impact, all runs"),
        ("max relative energy-balance residual of the integrator", f"{worst_res:.2e}",
         "impact energy_balance_residual / kinetic_energy_before"),
    ]
    caption = (f"Two-body impact with the linear hysteresis law (seed-1 eqs. 1–6, `afmkit impact`, adaptive "
               f"integrator), K_a = {_fmt(ka)} N/m. (a) Force–gap loop of one impact ("
               f"{_masses(body_list[0])}, approach speed "
               f"{_fmt(body_list[0]['velocity'])} nm/s, K_b = {_fmt(loop_r)} K_a): the bodies approach on the K_a branch "
               f"and leave on the K_b branch; the area between them is the energy lost, "
               f"{loop.results['energy_loss_area']:.4g} {u['energy_loss_area']} against the kinetic-energy loss "
               f"{loop.results['kinetic_energy_loss']:.4g} {u['kinetic_energy_loss']}. (b) The simulated coefficient of restitution "
               f"for K_b/K_a from {_fmt(min(ratios))} to {_fmt(max(ratios))} and "
               f"{['one', 'two', 'three', 'four'][len(body_list) - 1]} mass/speed pair{'s' if len(body_list) > 1 else ''} "
               f"agrees with e = √(K_b/K_a) to {worst_e:.1e}, independent of masses and speed.")
    return finish(fig, out, "beyond-impact",
                  title="Beyond the papers: impact restitution and energy loss (seed-1 eqs. 1–6)",
                  caption=caption, numbers=numbers)


FIGURES = [fig3, fig4, fig_attractive, fig_hb_vs_orbits, fig_impact]
