"""Force laws as objects one composes and hands to the commands (docs/python.md#force-laws, docs/force-laws.md).

One class per built-in law, made from the law registry the commands use (``afmkit._afmkit.laws()``): ``Linear``,
``Hysteresis``, ``Attractive``, ``Hertz``, ``DMT``, ``JKR``, ``LennardJones``, ``KelvinVoigt``, and ``Table`` (a
measured or reconstructed force curve, from arrays)::

    import afmkit
    law = afmkit.laws.DMT(hamaker=1e-19, effective_modulus=1.0, tip_radius=10.0)
    r = afmkit.tapping.sweep(law=law, spring_constant=40.0, resonance_frequency=300.0, quality_factor=400.0,
                             free_amplitude=10.0, separation_min=0.0, separation_max=12.0, points=25)

A law object holds the values given (keys and units of docs/force-laws.md: GPa, nm, J, ...; the keys not given take
the command's defaults, recorded in ``r.params`` as used). Given as ``law=`` to a command, it stands for
``law="<name>"`` and its keys; a key given both in the law and as a keyword is refused (ValueError), as is a law
key the command does not know. A law with physical parameters sets ``units="physical"`` on the tapping commands
unless ``units`` is given.

``Table(distance, approach, retract)`` takes SI arrays (m, N; force positive repulsive) and stands for
``law="table", force_curve=<file>``: the arrays are written once to a file named by their content (SHA-256) in
``$AFMKIT_LAW_CACHE`` (default ``~/.cache/afmkit/laws``), so the record ``r.params`` names a file that holds exactly
these values and replays.

``Python(approach=f, departure=g, damping=c)`` is a law written in Python: vectorised NumPy callables of the
tip–sample distance [m] giving the force [N] (positive repulsive) on approach and departure, and the Kelvin–Voigt
coefficient [N s/m] (docs/force-laws.md#python). It stands for ``law="python"`` with the law itself handed to the
run (not through a file), so it works with every command that simulates a given law: ``tapping orbit``, ``hb``,
``sweep``, ``fm``, ``impact``, ``demo``.

Every law evaluates as the commands use it: ``law.force(distance)`` gives the approach and departure branches (and
the damping) in SI units, ``law.force(distance, velocity)`` the force H(d, ḋ) with the branch the velocity selects
(seed-1 eq. 4, the Kelvin–Voigt term included); ``law(distance, velocity)`` is the same; ``law.plot(ax=...)``
draws the branches.
"""
from __future__ import annotations

import hashlib
import math
import os
from collections import namedtuple

import numpy as np

from . import _afmkit

_SPECS = {spec["name"]: spec for spec in _afmkit.laws()}
_CLASS_NAMES = {"linear": "Linear", "hysteresis": "Hysteresis", "attractive": "Attractive", "hertz": "Hertz",
                "dmt": "DMT", "jkr": "JKR", "lennard_jones": "LennardJones", "kelvin_voigt": "KelvinVoigt",
                "table": "Table", "python": "Python"}


class Law:
    """A force law of the registry with the values given (see the module's help)."""

    name = ""  # the registry's name: --law NAME

    def __init__(self, **values):
        spec = _SPECS[self.name]
        known = {k["key"]: k for k in spec["keys"]}
        for key, value in values.items():
            if key not in known:
                raise ValueError(f"afmkit.laws.{type(self).__name__}: {key} is not a key of law {self.name} "
                                 f"(its keys: {', '.join(known) or 'none'})")
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
                raise ValueError(f"afmkit.laws.{type(self).__name__}: {key} must be a number "
                                 f"({_unit(known[key])}), not {type(value).__name__}")
            k = known[key]
            v = float(value)
            low_ok = v > k["lower"] if k["lower_open"] else v >= k["lower"]
            if not (math.isfinite(v) and low_ok and v <= k["upper"]):
                raise ValueError(f"afmkit.laws.{type(self).__name__}: {key} = {v:g} is out of range: must be "
                                 f"{'>' if k['lower_open'] else '>='} {k['lower']:g}"
                                 + (f" and <= {k['upper']:g}" if math.isfinite(k["upper"]) else "")
                                 + f" ({_unit(k)})")
        self.values = {k: float(v) for k, v in values.items()}

    @property
    def physical(self) -> bool:
        """Whether the law's parameters are physical (GPa, nm, J): the tapping commands then run in physical units."""
        return not _SPECS[self.name]["piecewise_linear"]

    def kwargs(self) -> dict:
        """The command keywords this law stands for: ``law`` and the values given."""
        return {"law": self.name, **self.values}

    def si_values(self) -> dict:
        """The values given, in SI units (m, N, Pa, J, ...: the units of the spectroscopy fit and its results)."""
        factor = {k["key"]: k["si_factor"] for k in _SPECS[self.name]["keys"]}
        return {key: float(value) * factor[key] for key, value in self.values.items()}

    def __eq__(self, other):
        return type(self) is type(other) and self.kwargs() == other.kwargs()

    def __repr__(self):
        body = ", ".join(f"{k}={v!r}" for k, v in self.values.items())
        return f"afmkit.laws.{type(self).__name__}({body})"

    # ---- the law as the commands use it
    def _evaluate(self, distance, velocity, in_contact):
        """law_values of the compiled module: this law built as the commands build it, at SI distances."""
        d = np.asarray(distance, dtype=float)
        v = None if velocity is None else np.broadcast_to(np.asarray(velocity, dtype=float), d.shape)
        out = _afmkit.law_values(self._object(), self.name, self.values, self._force_curve(), "", True,
                                 np.ravel(d), None if v is None else np.ravel(v), bool(in_contact))
        return d.shape, out

    def _object(self):
        return None  # the law object handed to the run (law = python)

    def _force_curve(self) -> str:
        return ""

    def force(self, distance, velocity=None, *, in_contact=True):
        """The force as the commands use it, in SI units (parameters not given: the commands' defaults).

        ``distance`` [m]: the tip–sample gap (any shape). Without ``velocity``: the branches, a named tuple
        ``(approach [N], departure [N], damping [N s/m])`` of arrays of the shape of ``distance``. With ``velocity``
        [m/s] (the gap rate ḋ, broadcast to ``distance``): the force H(d, ḋ) [N] = the approach branch while
        approaching (ḋ < 0), the departure branch while departing (ḋ > 0), their mean at ḋ = 0, minus c(d)·ḋ (seed-1
        eq. 4 with the Kelvin–Voigt term). ``in_contact`` (table laws with hysteresis = contact only): whether the
        tip has touched (False: the approach branch whatever the velocity, as before the first contact).
        Forces are positive when repulsive. A piecewise-linear law (Linear, Hysteresis, Attractive) reads its
        stiffnesses in N/m and adhesions in nN (docs/force-laws.md)."""
        shape, out = self._evaluate(distance, velocity, in_contact)
        if velocity is not None:
            return out["force"].reshape(shape)
        return Branches(out["approach"].reshape(shape), out["departure"].reshape(shape),
                        out["damping"].reshape(shape))

    __call__ = force

    def switching_gaps(self) -> np.ndarray:
        """The distances [m] where a branch is not smooth (events of the integrators), sorted."""
        return self._evaluate([0.0], None, True)[1]["switching_gaps"]

    def contact_gap(self) -> float:
        """The distance [m] below which tip and sample count as in contact (NaN: the law has none)."""
        return float(self._evaluate([0.0], None, True)[1]["contact_gap"])

    def _plot_range(self):
        c = self.contact_gap()
        c = 0.0 if not math.isfinite(c) else c
        return np.linspace(c - 2e-9, c + 8e-9, 801)

    def plot(self, ax=None, distance=None, *, damping=False):
        """Draws the approach and departure branches (nN against nm; the departure dashed where it differs, the
        switching gaps dotted) on ``ax`` (None: a new figure) and returns the Axes. ``distance`` [m]: where
        (default: 2 nm below to 8 nm above the contact gap; a table: its distances). ``damping``: the
        Kelvin–Voigt coefficient too, on a second axis."""
        from . import _plots
        d = self._plot_range() if distance is None else np.asarray(distance, dtype=float)
        b = self.force(d)
        if ax is None:
            fig, ax = _plots._plt().subplots(constrained_layout=True)
        ax.plot(d * 1e9, b.approach * 1e9, label="approach")
        if not np.array_equal(b.approach, b.departure):
            ax.plot(d * 1e9, b.departure * 1e9, "--", label="departure")
        for g in self.switching_gaps():
            if d.min() <= g <= d.max():
                ax.axvline(g * 1e9, color="0.6", lw=0.8, ls=":")
        if damping and np.any(b.damping != 0):
            twin = ax.twinx()
            twin.plot(d * 1e9, b.damping, color="C2", lw=1.0, label="damping")
            twin.set_ylabel("damping c (N s/m)")
        ax.axhline(0.0, color="0.8", lw=0.6)
        ax.set_xlabel("distance (nm)")
        ax.set_ylabel("force (nN)")
        ax.set_title(repr(self), fontsize="small")
        ax.legend()
        return ax


Branches = namedtuple("Branches", ["approach", "departure", "damping"])
Branches.__doc__ = "A law's branches at given distances: approach and departure forces [N], damping [N s/m]."


def _unit(key: dict) -> str:
    return f"unit {key['unit']}" if key["unit"] else "dimensionless"


def _law_class(spec: dict):
    keys = spec["keys"]
    lines = [f"{spec['summary']} (law = {spec['name']}, docs/force-laws.md).", "",
             "Keyword arguments (not given: the command's default, recorded as used):", ""]
    for k in keys:
        follows = f"; default: the value of {k['follows']}" if k["follows"] else f"; default {k['default']:g}"
        lines.append(f"  {k['key']} ({_unit(k)}{follows}): {k['help']}")
    cls = type(_CLASS_NAMES.get(spec["name"], spec["name"]), (Law,),
               {"name": spec["name"], "__doc__": "\n".join(lines), "__module__": __name__})
    return cls


def _cache_folder() -> str:
    return os.environ.get("AFMKIT_LAW_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "afmkit", "laws")


class Table(Law):
    """A measured or reconstructed force curve as a table law (law = table; docs/force-laws.md#table).

    ``distance`` [m] (tip–sample distance, increasing or decreasing, distinct), ``approach`` [N] and ``retract`` [N]
    (force positive repulsive; ``retract`` omitted: the same as ``approach``, a conservative law). The commands read
    it through a file written once per content (see the module's help); ``hysteresis``, ``allow_energy_gain`` and
    ``release_tolerance`` stay keywords of the command.
    """

    name = "table"

    def __init__(self, distance, approach, retract=None):
        super().__init__()
        arrays = {}
        for label, value in (("distance", distance), ("approach", approach),
                             ("retract", approach if retract is None else retract)):
            a = np.asarray(value, dtype=float)
            if a.ndim != 1:
                raise ValueError(f"afmkit.laws.Table: {label} must be a 1-D array, not of shape {a.shape}")
            bad = np.flatnonzero(~np.isfinite(a))
            if bad.size:
                raise ValueError(f"afmkit.laws.Table: {label}[{bad[0]}] = {a[bad[0]]} is not finite")
            arrays[label] = a
        n = arrays["distance"].size
        for label in ("approach", "retract"):
            if arrays[label].size != n:
                raise ValueError(f"afmkit.laws.Table: {label} has {arrays[label].size} values and distance {n}: "
                                 "one force per distance")
        if n < 2:
            raise ValueError(f"afmkit.laws.Table: distance has {n} value(s): a table needs at least 2 distances")
        self.distance, self.approach, self.retract = arrays["distance"], arrays["approach"], arrays["retract"]
        self._path = None

    @property
    def physical(self) -> bool:
        return True

    def text(self) -> str:
        """The table as the force-curve file the commands read (nm and nN, 17 significant digits)."""
        rows = "".join(f"{d * 1e9:.17g}, {a * 1e9:.17g}, {r * 1e9:.17g}\n"
                       for d, a, r in zip(self.distance, self.approach, self.retract))
        return "distance (nm), approach force (nN), retract force (nN)\n" + rows

    def path(self) -> str:
        """The file that holds this table (written on first use; named by its content)."""
        if self._path is None:
            text = self.text()
            folder = _cache_folder()
            os.makedirs(folder, exist_ok=True)
            path = os.path.join(folder, f"table-{hashlib.sha256(text.encode()).hexdigest()[:24]}.csv")
            if not os.path.exists(path):
                tmp = f"{path}.tmp.{os.getpid()}"
                with open(tmp, "w") as f:
                    f.write(text)
                os.replace(tmp, path)  # whole or not at all
            self._path = path
        return self._path

    def kwargs(self) -> dict:
        return {"law": "table", "force_curve": self.path()}

    def _force_curve(self) -> str:
        return self.path()

    def _plot_range(self):
        return np.linspace(self.distance.min(), self.distance.max(), 801)

    def __eq__(self, other):
        return type(self) is type(other) and self.text() == other.text()

    def __repr__(self):
        return (f"afmkit.laws.Table({self.distance.size} distances from {self.distance.min() * 1e9:.4g} to "
                f"{self.distance.max() * 1e9:.4g} nm)")


class Python(Law):
    """A force law written in Python (law = python; docs/force-laws.md#python).

    ``approach``, ``departure``: vectorised callables of the tip–sample distance [m] (a NumPy array) returning
    the force [N] at each distance, positive repulsive: H_a while the gap closes, H_b while it opens (seed-1
    eq. 4); ``departure`` omitted: the same as ``approach`` (a conservative law). ``damping``: the Kelvin–Voigt
    coefficient c(d) >= 0 [N s/m] (a callable of the distance or a number; the force gains −c(d)·ḋ);
    omitted: none. ``switching_gaps`` [m]: the distances where a branch or the damping has a kink or a jump (the
    contact edge), located as events by the integrators; ``contact_gap`` [m]: the gap below which tip and sample
    count as in contact (default: the lowest switching gap). ``domain`` = (lowest, highest) distance [m] over
    which the callables are tabulated (they must be finite there); beyond it they are called point by point
    (correct, slower). ``name``: how records and messages name the law. ``tabulation``: per branch, the number
    of pieces and of those evaluated by the callable. A departure branch above the approach branch somewhere
    creates energy: the commands refuse the law then unless ``allow_energy_gain=True`` (``energy_gain``: where).

    The callables are evaluated once, here, in a few vectorised batches: the law is tabulated as Chebyshev pieces
    to 1e-12 of the largest force on each interval (see docs/force-laws.md#python for the check and the cost), so
    a run calls no Python inside the domain. A callable that raises, returns another shape or a value that is not
    finite is refused here (ValueError/TypeError naming it), or, beyond the domain during a run, with
    afmkit.InvalidParameter naming it.
    """

    name = "python"

    def __init__(self, approach, departure=None, damping=None, *, switching_gaps=(), contact_gap=None,
                 domain=(-1e-3, 1.0), name=None):
        super().__init__()
        from . import _python_law
        for label, f in (("approach", approach), ("departure", departure)):
            if f is not None and not callable(f):
                raise TypeError(f"afmkit.laws.Python: {label} must be a callable of the distance [m] (a vectorised "
                                f"NumPy function), not {type(f).__name__}")
        if approach is None:
            raise TypeError("afmkit.laws.Python: approach is required (a callable of the distance [m])")
        if damping is not None and not callable(damping):
            if isinstance(damping, bool) or not isinstance(damping, (int, float, np.integer, np.floating)):
                raise TypeError(f"afmkit.laws.Python: damping must be a callable of the distance [m] or a number "
                                f"(N s/m), not {type(damping).__name__}")
            if not (math.isfinite(damping) and damping >= 0):
                raise ValueError(f"afmkit.laws.Python: damping = {damping} must be a finite number >= 0 (N s/m)")
            constant = float(damping)
            damping_f = _Constant(constant)
            damping_label = f"damping={constant!r}"
        else:
            damping_f = damping
            damping_label = f"damping={_callable_name(damping)}" if damping is not None else ""
        lo, hi = (float(x) for x in domain)
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ValueError(f"afmkit.laws.Python: domain = {tuple(domain)} must be (lowest, highest) finite "
                             "distances in m, lowest < highest")
        gaps = np.asarray(switching_gaps, dtype=float).ravel()
        if not np.all(np.isfinite(gaps)):
            raise ValueError("afmkit.laws.Python: switching_gaps must be finite distances in m")
        if contact_gap is not None and not math.isfinite(float(contact_gap)):
            raise ValueError("afmkit.laws.Python: contact_gap must be a finite distance in m")
        self.approach, self.departure, self.damping = approach, departure, damping
        self.switching, self.domain = np.unique(gaps), (lo, hi)
        self.label = name or _callable_name(approach)
        dom_nm, gaps_nm = (lo * 1e9, hi * 1e9), (self.switching * 1e9).tolist()
        branch = lambda f, label, factor, **kw: _python_law.tabulate(f, label, factor, dom_nm, gaps_nm, **kw)
        tables = {"approach": branch(approach, f"approach={_callable_name(approach)}", 1e9)}
        tables["departure"] = (branch(departure, f"departure={_callable_name(departure)}", 1e9)
                               if departure is not None else None)
        tables["damping"] = (branch(damping_f, damping_label, 1.0, non_negative=True)
                             if damping_f is not None else None)
        self.tabulation = {k: {"pieces": v["pieces"], "direct": v["direct"]} for k, v in tables.items() if v}
        self._tables, self._gaps_nm = tables, gaps_nm
        self._contact_nm = math.nan if contact_gap is None else float(contact_gap) * 1e9
        self._model = self._build()
        self.energy_gain = None if departure is None else self._energy_gain(tables)

    def _build(self):
        t = self._tables
        return _afmkit.PythonLaw(self.label, t["approach"], t["departure"], t["damping"], self._gaps_nm,
                                 self._contact_nm)

    # pickling (multiprocessing, Dask, the study runner's workers): the tabulation and the callables travel, the
    # compiled law is rebuilt from the tabulation without calling them again; a callable pickle cannot carry (a
    # lambda, a local function) makes pickle raise as for any object holding one
    def __getstate__(self):
        state = self.__dict__.copy()
        del state["_model"]
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._model = self._build()

    def _energy_gain(self, tables):
        """(distance [m], H_a [N], H_b [N]) where the departure branch lies above the approach branch (the law
        creates energy there: docs/force-laws.md#convention), else None. Checked at the edges and midpoints of
        every tabulated piece of both branches, to 1e-9 of the larger force."""
        edges = np.unique(np.concatenate([tables["approach"]["edges"], tables["departure"]["edges"]]))
        d = np.sort(np.concatenate([edges, 0.5 * (edges[1:] + edges[:-1])])) * 1e-9
        b = self.force(d)
        bad = np.flatnonzero(b.departure - b.approach > 1e-9 * np.maximum(np.abs(b.approach), np.abs(b.departure)))
        return None if bad.size == 0 else (float(d[bad[0]]), float(b.approach[bad[0]]), float(b.departure[bad[0]]))

    @property
    def physical(self) -> bool:
        return True

    def _object(self):
        return self._model

    def kwargs(self) -> dict:
        return {"law": self._model}

    def __eq__(self, other):
        return self is other

    __hash__ = object.__hash__

    def __repr__(self):
        parts = [f"approach={_callable_name(self.approach)}"]
        if self.departure is not None:
            parts.append(f"departure={_callable_name(self.departure)}")
        if self.damping is not None:
            parts.append(f"damping={self.damping!r}" if not callable(self.damping)
                         else f"damping={_callable_name(self.damping)}")
        if self.switching.size:
            parts.append(f"switching_gaps={self.switching.tolist()}")
        return f"afmkit.laws.Python({', '.join(parts)})"


class _Constant:
    """A constant damping coefficient as a vectorised callable of the distance (picklable, unlike a lambda)."""

    def __init__(self, value: float):
        self.value = value

    def __call__(self, d):
        return np.full(np.shape(d), self.value)


def _callable_name(f) -> str:
    return getattr(f, "__qualname__", None) or getattr(f, "__name__", None) or repr(f)


_classes = {}
for _spec in _SPECS.values():
    if _spec["name"] not in ("table", "python"):
        _classes[_CLASS_NAMES.get(_spec["name"], _spec["name"])] = _law_class(_spec)
globals().update(_classes)
__all__ = ["Law", "Table", "Python", *_classes]


def expand(path: str, kwargs: dict, keys) -> dict:
    """The keywords of command `path` with a Law object given as ``law=`` replaced by what it stands for (see the
    module's help); `keys`: the command's keys."""
    law = kwargs.get("law")
    if not isinstance(law, Law):
        return kwargs
    out = {k: v for k, v in kwargs.items() if k != "law"}
    for key, value in law.kwargs().items():
        if key not in keys:
            raise ValueError(f"{path}: law {law!r} has {key}, which this command does not take")
        if out.get(key) is not None:
            raise ValueError(f"{path}: {key} is given both in law={law!r} and as a keyword: give it once")
        out[key] = value
    if "units" in keys and law.physical and out.get("units") is None:
        out["units"] = "physical"
    gain = getattr(law, "energy_gain", None)
    if gain is not None and not out.get("allow_energy_gain"):  # as every command refuses a built-in law's gain
        err = _afmkit.InvalidParameter(
            f"{path}: the departure branch of {law!r} lies above its approach branch at distance {gain[0]:.6g} m "
            f"(H_b = {gain[2]:.6g} N > H_a = {gain[1]:.6g} N): the law creates energy; give allow_energy_gain=True to "
            "run it anyway (docs/force-laws.md#convention)")
        err.parameter = "law"
        raise err
    return out
