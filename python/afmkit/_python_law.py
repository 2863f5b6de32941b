"""Tabulation of a force law written in Python (afmkit.laws.Python; docs/force-laws.md#python).

The engine evaluates a law one gap at a time, in sequence: calling Python there would cost microseconds per call.
So each callable is evaluated here in a few vectorised batches, on an adaptive set of Chebyshev pieces (degree
``DEGREE``, Lobatto points) covering the law's domain: a piece is kept when its interpolant (from the even points of
a 2·DEGREE+1 point Lobatto set) matches the callable at the odd points (the midpoints) to ``RTOL`` times the largest
|value| met on its base interval, else it is halved. The base intervals end at the domain's ends, the switching gaps
and ±2^k nm (k = -3 … 30) and 0, so far gaps (where the van der Waals force is small) get pieces of their own scale.
On the base intervals next to a switching gap g the series are in u = √|d − g| (smooth for the δ^{1/2} and δ^{3/2}
of contact mechanics). A piece next to a switching gap narrower than ``MIN_WIDTH_NM`` that still misses the
tolerance (another endpoint singularity) is evaluated by the callable itself during runs; anywhere else the callable is not smooth
enough to tabulate, and the law is refused naming the place (a kink or jump must be a declared switching gap).
"""
from __future__ import annotations

import numpy as np
from numpy.polynomial import chebyshev

DEGREE = 16
RTOL = 1e-12
MIN_WIDTH_NM = 1e-6
_BASE_NM = np.concatenate([-(2.0 ** np.arange(30, -4, -1)), [0.0], 2.0 ** np.arange(-3, 31)])

_n = DEGREE
_LOBATTO = np.cos(np.pi * np.arange(2 * _n + 1) / (2 * _n))  # on [-1, 1], from +1 down to -1
_k = np.arange(_n + 1)
_FIT = (2.0 / _n) * np.cos(np.pi * np.outer(_k, _k) / _n)  # c_m = Σ'' f_k T_m(x_k) (halved ends), DCT-I
_FIT[:, [0, -1]] *= 0.5
_FIT[[0, -1], :] *= 0.5
_CHECK = np.cos(np.outer(np.pi * np.arange(1, 2 * _n, 2) / (2 * _n), _k))  # T_m at the odd (check) points


def values(f, label: str, x):
    """f(x) for SI distances `x` [m]: a float array of the shape of `x`, finite; ValueError naming the callable
    (`label`) when it raises, returns another shape or a value that is not finite."""
    try:
        y = f(x)
    except Exception as e:  # the user's callable: its error, reported as such
        raise ValueError(f"afmkit.laws.Python: {label} raised {type(e).__name__}: {e} (called with an array of "
                         f"{x.size} distances in m)") from e
    try:
        y = np.asarray(y, dtype=float)
    except (TypeError, ValueError) as e:
        raise TypeError(f"afmkit.laws.Python: {label} must return numbers (an array of floats), not "
                        f"{type(y).__name__}") from e
    if y.shape != x.shape:
        raise ValueError(f"afmkit.laws.Python: {label} returned an array of shape {y.shape} for distances of shape "
                         f"{x.shape}: it must return one value per distance (a vectorised NumPy function of the "
                         "distance array)")
    bad = np.flatnonzero(~np.isfinite(y))
    if bad.size:
        i = bad[0]
        raise ValueError(f"afmkit.laws.Python: {label} returned {y.flat[i]} at distance {x.flat[i]:.6g} m: a force "
                         "law must be finite on its whole domain (give domain= where it is)")
    return y


def tabulate(f, label: str, factor: float, domain_nm, switching_nm, non_negative=False) -> dict:
    """The branch `f` (SI callable) as Chebyshev pieces in nm and the law's units (value · `factor`), for
    python_law.cpp's PythonBranch.

    A piece is a series in a variable u: u = d on most pieces; on the base intervals next to a switching gap g,
    d = g ± u² (u = √|d − g|), so that the endpoint singularities of contact mechanics (δ^{1/2} of a Kelvin–Voigt
    damping, δ^{3/2} of Hertz) are smooth in u and need a few pieces, not dozens."""
    lo, hi = domain_nm
    switching = np.asarray([g for g in switching_nm if lo < g < hi], dtype=float)
    inner = _BASE_NM[(_BASE_NM > lo) & (_BASE_NM < hi)]
    edges = np.unique(np.concatenate([[lo, hi], inner, switching]))
    ea, eb = edges[:-1], edges[1:]
    left, right = np.isin(ea, switching), np.isin(eb, switching) & ~np.isin(ea, switching)
    sign = np.where(left, 1.0, np.where(right, -1.0, 0.0))     # d = anchor + sign·u² (sign 0: d = u)
    anchor = np.where(left, ea, np.where(right, eb, np.nan))
    width = np.sqrt(eb - ea)
    a = np.where(sign != 0, 0.0, ea)                             # u-interval of each piece
    b = np.where(sign != 0, width, eb)
    base = np.arange(a.size)              # the base interval of each piece
    scale = np.zeros(a.size)              # the largest |value| met on each base interval
    done = []

    def to_d(u, sg, an):
        return np.where(sg == 0, u, an + sg * u * u)

    while a.size:
        mid, half = 0.5 * (a + b), 0.5 * (b - a)
        sg, an = sign[base], anchor[base]
        u = mid[:, None] + half[:, None] * _LOBATTO[None, :]
        x = to_d(u, sg[:, None], an[:, None])  # nm
        # the ends of the base interval exactly (u² rounds)
        x = np.clip(x, ea[base][:, None], eb[base][:, None])
        y = values(f, label, x.ravel() * 1e-9).reshape(x.shape) * factor  # a 1-D array, as the callable expects
        if non_negative and np.any(y < 0):
            i = np.flatnonzero(y.ravel() < 0)[0]
            raise ValueError(f"afmkit.laws.Python: {label} returned {y.flat[i] / factor} at distance "
                             f"{x.flat[i] * 1e-9:.6g} m: a damping coefficient must be >= 0 (N s/m)")
        np.maximum.at(scale, base, np.abs(y).max(axis=1))
        c = y[:, ::2] @ _FIT.T
        err = np.abs(c @ _CHECK.T - y[:, 1::2]).max(axis=1)
        ok = err <= RTOL * scale[base]
        da, db = x.min(axis=1), x.max(axis=1)
        narrow = (db - da) < MIN_WIDTH_NM
        at_switch = np.zeros(a.size, bool)
        if switching.size:
            near = lambda e: np.any(np.abs(e[:, None] - switching[None, :]) <= 1e-12 * (1.0 + np.abs(switching)), 1)
            at_switch = near(da) | near(db)
        stuck = ~ok & narrow & ~at_switch
        if np.any(stuck):
            i = np.flatnonzero(stuck)[0]
            raise ValueError(f"afmkit.laws.Python: {label} is not smooth near distance "
                             f"{0.5 * (da[i] + db[i]) * 1e-9:.6g} m (a Chebyshev series misses it by "
                             f"{err[i] / factor:.3g} on an interval of {(db[i] - da[i]) * 1e-9:.3g} m): give the "
                             "distances where it has a kink or a jump as switching_gaps=[...] (m)")
        direct = ~ok & narrow  # next to a switching gap: evaluated by the callable during runs
        c[direct] = np.nan
        keep = ok | direct
        done.append((da[keep], a[keep], b[keep], sg[keep], an[keep], c[keep]))
        split = ~keep
        a, b, base = (np.concatenate([a[split], mid[split]]), np.concatenate([mid[split], b[split]]),
                      np.concatenate([base[split], base[split]]))
    pd, pa, pb, ps, pn, pc = (np.concatenate(parts) for parts in zip(*done))
    order = np.argsort(pd, kind="stable")
    pd, pa, pb, ps, pn, pc = pd[order], pa[order], pb[order], ps[order], pn[order], pc[order]
    slopes = chebyshev.chebder(pc, axis=1) * (2.0 / (pb - pa))[:, None]  # d/du
    return {"label": label, "callable": f, "factor": float(factor), "edges": np.append(pd, hi).tolist(),
            "coefficients": pc.ravel().tolist(), "slopes": slopes.ravel().tolist(), "degree": DEGREE,
            "u_low": pa.tolist(), "u_high": pb.tolist(), "signs": ps.tolist(),
            "anchors": np.nan_to_num(pn, nan=0.0).tolist(),
            "pieces": int(pd.size), "direct": int(np.isnan(pc[:, 0]).sum())}
