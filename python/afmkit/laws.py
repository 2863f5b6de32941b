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
"""
from __future__ import annotations

import hashlib
import math
import os

import numpy as np

from . import _afmkit

_SPECS = {spec["name"]: spec for spec in _afmkit.laws()}
_CLASS_NAMES = {"linear": "Linear", "hysteresis": "Hysteresis", "attractive": "Attractive", "hertz": "Hertz",
                "dmt": "DMT", "jkr": "JKR", "lennard_jones": "LennardJones", "kelvin_voigt": "KelvinVoigt",
                "table": "Table"}


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

    def __eq__(self, other):
        return type(self) is type(other) and self.kwargs() == other.kwargs()

    def __repr__(self):
        body = ", ".join(f"{k}={v!r}" for k, v in self.values.items())
        return f"afmkit.laws.{type(self).__name__}({body})"


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

    def __eq__(self, other):
        return type(self) is type(other) and self.text() == other.text()

    def __repr__(self):
        return (f"afmkit.laws.Table({self.distance.size} distances from {self.distance.min() * 1e9:.4g} to "
                f"{self.distance.max() * 1e9:.4g} nm)")


_classes = {}
for _spec in _SPECS.values():
    if _spec["name"] != "table":
        _classes[_CLASS_NAMES.get(_spec["name"], _spec["name"])] = _law_class(_spec)
globals().update(_classes)
__all__ = ["Law", "Table", *_classes]


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
    return out
