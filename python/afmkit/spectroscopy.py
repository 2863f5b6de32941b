"""Measured force curves (docs/spectroscopy.md): from an instrument's raw curve to the table law of ``--law table``.

``prepare(height, deflection, spring_constant=...)`` takes one curve (or a list of repeated curves) as NumPy arrays
in SI units; ``prepare_file(path, ...)`` reads an instrument file (docs/curve-files.md). Both run the code of
``afmkit spectroscopy prepare`` with its parameters and messages, and return a :class:`PreparedCurve`: the law as
arrays in SI units (``r.law["approach_distance"]`` [m], ``r.law["approach_force"]`` [N], …), the contact point,
Young's modulus, noise, snap-in and pull-off, and the command's summary document ``r.results`` (its units in
``r.results["units"]``: nm, nN, Pa).

Keyword options are the command's keys (``afmkit spectroscopy prepare --help``), with lengths in SI units here:
``invols`` [m/V], ``tip_radius`` [m], ``bin_width`` [m]; e.g. ``contact_method="dmt"``, ``baseline_fraction=0.3``,
``noise_multiple=3``, ``poisson_ratio=0.5``, ``keep_baseline=True``, ``allow_energy_gain=True``, ``output="law.csv"``
(writes the law file and its sidecar), ``plot="curve.png"`` (raw vs prepared curves, Matplotlib).

Also here: ``reconstruct_fm(distance, frequency_shift, ...)`` and ``reconstruct_am(distance, amplitude, phase, ...)``
(the force from FM-AFM and AM-AFM curves, with the round trip: docs/reconstruction.md; ``reconstruct`` is the
command on a file), ``fit(distance, amplitude, phase, ...)`` and ``fit_fm(distance, frequency_shift, ...)`` (a
law's parameters fitted to an AM or FM curve over afmkit's exact orbits: docs/fitting.md; ``fit_file`` is the
command on a file, ``plot_fit`` draws data vs fit).
"""
from __future__ import annotations

import inspect
import json
import sys

import numpy as np

from . import _afmkit
from ._commands import Result

# keyword options given in SI units here, in the command's units (nm) there
_SI_TO_COMMAND = {"invols": 1e9, "tip_radius": 1e9, "bin_width": 1e9}
_LAW_COLUMNS = ("approach distance (nm)", "approach force (nN)", "retract distance (nm)", "retract force (nN)")
_LAW_KEYS = ("approach_distance", "approach_force", "retract_distance", "retract_force")


class PreparedCurve:
    """What ``prepare`` found. Attributes in SI units (``units`` names them); ``results`` is the command's document
    (nm, nN, Pa: ``results["units"]``), ``params`` the parameters as run (SI lengths, as the keywords here)."""

    # params: the parameters as run, in this module's units (SI lengths): prepare_file(**r.params) repeats the run
    units = {"approach_distance": "m", "approach_force": "N", "retract_distance": "m", "retract_force": "N",
             "contact_point": "m", "contact_point_error": "m", "youngs_modulus": "Pa", "youngs_modulus_error": "Pa",
             "noise": "N", "bin_width": "m", "snap_in": "(m, N)", "pull_off": "(m, N)"}

    def __init__(self, results: dict, params: dict, law: dict):
        self.results = results
        self.params = {k: (v / _SI_TO_COMMAND[k] if k in _SI_TO_COMMAND and isinstance(v, (int, float)) else v)
                       for k, v in params.items()}
        self.law = law  # SI arrays: approach_distance [m], approach_force [N], retract_distance [m], retract_force [N]
        self.status: str = results["status"]
        first = results["curves"][0]
        self.curves = results["curves"]
        self.contact_point = _si(first["contact"]["position"], 1e-9)
        self.contact_point_error = _si(first["contact"]["error"], 1e-9)
        fit = first["contact"].get("fit") or {}
        self.youngs_modulus = _si(fit.get("youngs_modulus"), 1.0)
        self.youngs_modulus_error = _si(fit.get("youngs_modulus_error"), 1.0)
        self.noise = _si(results["noise"], 1e-9)
        self.bin_width = _si(results["bin_width"], 1e-9)
        self.snap_in = _event(results["snap_in"])
        self.pull_off = _event(results["pull_off"])

    def law_arguments(self) -> dict:
        """The keywords that make the tapping and impact functions use the prepared law: ``law="table"``, the law file
        written with ``output=`` and ``allow_energy_gain`` as prepared, e.g.
        ``afmkit.tapping.orbit(**r.law_arguments(), units="physical", ...)``."""
        path = self.params.get("output", "")
        if not path:
            raise ValueError("the prepared law was not written: give output='law.csv' to prepare() to write it")
        return {"law": "table", "force_curve": path, "allow_energy_gain": bool(self.params.get("allow_energy_gain"))}

    def __repr__(self) -> str:
        return (f"PreparedCurve(status={self.status!r}, contact_point={self.contact_point:.6g} m, "
                f"youngs_modulus={self.youngs_modulus:.6g} Pa, noise={self.noise:.3g} N, "
                f"approach={len(self.law['approach_distance'])} points, "
                f"retract={len(self.law['retract_distance'])} points)")


def _si(value, factor: float) -> float:
    return float("nan") if value is None else float(value) * factor


def _event(e: dict):
    """(distance [m], force [N]) of a detected event, else None."""
    return (e["distance"] * 1e-9, e["force"] * 1e-9) if e["detected"] else None


def _options(kwargs: dict) -> dict:
    out = {}
    for key, value in kwargs.items():
        factor = _SI_TO_COMMAND.get(key)
        out[key] = value * factor if factor is not None and value is not None else value
        if value is None:
            del out[key]
    return out


def _law_from_columns(columns: dict) -> dict:
    """The law's four columns (cells "" past the end of a shorter branch) as SI arrays."""
    law = {}
    for name, key in zip(_LAW_COLUMNS, _LAW_KEYS):
        cells = [c for c in np.asarray(columns[name]).tolist() if c != "" and c is not None]
        law[key] = np.asarray([float(c) for c in cells], dtype=float) * 1e-9  # nm → m, nN → N
    return law


def _segments(height, deflection, deflection_volts, force, segment):
    height = np.asarray(height, dtype=float)
    channels = [None if c is None else np.asarray(c, dtype=float) for c in (deflection, deflection_volts, force)]
    if all(c is None for c in channels):
        raise TypeError("afmkit.spectroscopy.prepare: give deflection, deflection_volts or force")
    for c in channels:
        if c is not None and c.shape != height.shape:
            raise ValueError(f"afmkit.spectroscopy.prepare: every channel needs the shape of height {height.shape}, "
                             f"got {c.shape}")
    if segment is None:  # approach down to the lowest height, then the retract
        turn = int(np.argmin(height))
        bounds = [("approach", 0, turn + 1), ("retract", turn, height.size)]
    else:
        labels = np.asarray(segment)
        if labels.shape != height.shape:
            raise ValueError("afmkit.spectroscopy.prepare: segment needs the shape of height")
        names = {0: "approach", 1: "retract", 2: "pause"}
        bounds, start = [], 0
        for i in range(1, labels.size + 1):
            if i == labels.size or labels[i] != labels[start]:
                lab = labels[start].item() if hasattr(labels[start], "item") else labels[start]
                bounds.append((names.get(lab, str(lab)), start, i))
                start = i
    return [(kind, height[a:b], *[None if c is None else c[a:b] for c in channels]) for kind, a, b in bounds]


def prepare(height, deflection=None, *, deflection_volts=None, force=None, segment=None, spring_constant,
            invols=None, **options) -> PreparedCurve:
    """Prepares one measured force curve given as arrays (or repeated curves: lists of arrays) in SI units.

    height [m]: piezo height, increasing away from the sample; deflection [m] (positive away from the sample), or
    deflection_volts [V] (with ``invols`` [m/V]), or force [N] (positive repulsive). ``segment``: per sample
    "approach"/"retract"/"pause" (or 0/1/2); None: the approach runs down to the lowest height, the retract follows.
    ``spring_constant`` [N/m]. Other options: see the module's documentation."""
    many = isinstance(height, (list, tuple)) and len(height) > 0 and np.ndim(height[0]) == 1
    def pick(x, i):
        return None if x is None else (x[i] if many else x)
    count = len(height) if many else 1
    curves = [_segments(pick(height, i) if many else height, pick(deflection, i), pick(deflection_volts, i),
                        pick(force, i), pick(segment, i)) for i in range(count)]
    kwargs = _options(dict(options, spring_constant=spring_constant, invols=invols))
    raw = _afmkit.spectroscopy_prepare_arrays(curves, kwargs)
    results, params, rows = json.loads(raw["results"]), json.loads(raw["params"]), json.loads(raw["rows"])
    columns = {name: [r[i] for r in rows] for i, name in enumerate(_LAW_COLUMNS)}
    return PreparedCurve(results, params, _law_from_columns(columns))


def prepare_file(input, **options) -> PreparedCurve:
    """Prepares every curve of the instrument file ``input`` (JPK .jpk-force, Asylum .ibw, text exports with
    ``format``, ``height_column``, … as the command's keys). Options as ``prepare`` (SI units: ``invols`` [m/V],
    ``tip_radius`` [m], ``bin_width`` [m]); ``spring_constant`` [N/m] and ``invols`` override the file's."""
    r = _afmkit.run("spectroscopy prepare", _options(dict(options, input=input)), Result)
    return PreparedCurve(dict(r.results), r.params, _law_from_columns(dict(r)))


def _file_signature():
    """prepare_file's keywords: the command's keys (its --help), lengths in SI units here."""
    spec = next(s for s in _afmkit.commands() if s["path"] == "spectroscopy prepare")
    params = [inspect.Parameter("input", inspect.Parameter.POSITIONAL_OR_KEYWORD)]
    for p in spec["params"]:
        if p["key"] == "input":
            continue
        default = None if p["key"] in ("spring_constant", "invols") else p["default"]
        if p["key"] in _SI_TO_COMMAND and default:
            default = default / _SI_TO_COMMAND[p["key"]]
        params.append(inspect.Parameter(p["key"], inspect.Parameter.KEYWORD_ONLY, default=default))
    return inspect.Signature(params, return_annotation=PreparedCurve)


prepare_file.__signature__ = _file_signature()


def plot(data: dict, path: str) -> None:
    """Draws raw vs prepared curves (the data ``afmkit spectroscopy prepare --plot`` hands over, SI units) to a PNG."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (raw_ax, prep_ax, zoom_ax) = plt.subplots(1, 3, figsize=(15, 4.2), constrained_layout=True)
    for i, c in enumerate(data["curves"]):
        label = "" if i else " (raw)"
        for branch, colour in (("approach", "tab:blue"), ("retract", "tab:red")):
            b = c[branch]
            raw_ax.plot(np.asarray(b["height"]) * 1e6, np.asarray(b["raw_force"]) * 1e9, lw=0.6, color=colour,
                        alpha=0.7, label=branch + label if i == 0 else None)
            for ax in (prep_ax, zoom_ax):
                ax.plot(np.asarray(b["distance"]) * 1e9, np.asarray(b["force"]) * 1e9, ".", ms=1.5, color=colour,
                        alpha=0.25, label=f"{branch} samples" if i == 0 else None)
        bl = c["baseline"]
        z = np.linspace(bl["height_from"], bl["height_to"], 2)
        raw_ax.plot(z * 1e6, (bl["offset"] + bl["slope"] * z) * 1e9, "k--", lw=1.2,
                    label="baseline fit" if i == 0 else None)
        fit = c.get("fit")
        if fit and i == 0:
            lo = min(np.min(c["approach"]["distance"]), 0.0)
            d = np.linspace(lo, 0.0, 200)  # distance from the prepared contact point
            delta = np.maximum(0.0, fit["contact_point"] - (c["contact"] + d))
            for ax in (prep_ax, zoom_ax):
                ax.plot(d * 1e9, (fit["coefficient"] * delta ** 1.5 + fit["offset"]) * 1e9, "k-", lw=1,
                        label=f"{ {'hertz': 'Hertz', 'dmt': 'DMT'}.get(fit['model'], fit['model'])} fit")
    for ax in (prep_ax, zoom_ax):
        for branch, colour in (("approach", "navy"), ("retract", "darkred")):
            ax.plot(np.asarray(data[branch]["distance"]) * 1e9, np.asarray(data[branch]["force"]) * 1e9, "-",
                    color=colour, lw=1.6, label=f"{branch} (binned table)")
        for name, marker in (("snap_in", "v"), ("pull_off", "^")):
            e = data[name]
            if e["detected"]:
                ax.plot([e["distance"] * 1e9], [e["force"] * 1e9], marker, color="k", ms=8,
                        label=name.replace("_", "-"))
        ax.axvline(0.0, color="grey", lw=0.8, ls=":")
        ax.axhline(0.0, color="grey", lw=0.8, ls=":")
    # the zoom: the contact and the adhesion, from the deepest bin out to 3 times as far beyond the contact (or to
    # the pull-off and snap-in, when farther)
    deepest = min(np.min(data["approach"]["distance"]), np.min(data["retract"]["distance"]))
    reach = 3 * abs(deepest)
    for name in ("snap_in", "pull_off"):
        if data[name]["detected"]:
            reach = max(reach, 1.5 * data[name]["distance"])
    zoom_ax.set_xlim(deepest * 1e9 * 1.05, reach * 1e9)
    inside = np.concatenate([np.asarray(data[b]["force"])[np.asarray(data[b]["distance"]) <= reach]
                             for b in ("approach", "retract")])
    if inside.size:
        pad = 0.05 * (inside.max() - inside.min() + 1e-30)
        zoom_ax.set_ylim((inside.min() - pad) * 1e9, (inside.max() + pad) * 1e9)
    zoom_ax.set(xlabel="tip–sample distance (nm)", ylabel="force (nN)", title="prepared, near the contact")
    raw_ax.set(xlabel="piezo height z (µm)", ylabel="force k·d (nN)", title="raw (calibrated)")
    prep_ax.set(xlabel="tip–sample distance (nm)", ylabel="force (nN)",
                title=f"prepared (noise σ = {data['noise'] * 1e12:.3g} pN, status {data['status']})")
    raw_ax.legend(fontsize=7)
    prep_ax.legend(fontsize=7)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_main(argv) -> int:
    """``afmkit spectroscopy prepare --plot``: argv = [data.json, out.png]."""
    if len(argv) != 2:
        print("usage: plot_main DATA.json OUT.png", file=sys.stderr)
        return 2
    with open(argv[0], encoding="utf-8") as f:
        data = json.load(f)
    try:
        plot(data, argv[1])
    except ImportError as e:
        print(f"afmkit: the plot needs Matplotlib (Debian python3-matplotlib): {e}", file=sys.stderr)
        return 2
    return 0


from .spectroscopy_reconstruct import Reconstruction, reconstruct, reconstruct_am, reconstruct_fm  # noqa: E402
from .spectroscopy_fit import FitResult, fit, fit_fm, predict, predict_fm  # noqa: E402
from .spectroscopy_fit import plot as plot_fit  # noqa: E402
from .spectroscopy_fit import run as fit_file  # noqa: E402

__all__ = ["prepare", "prepare_file", "PreparedCurve", "plot", "reconstruct_fm", "reconstruct_am", "reconstruct",
           "Reconstruction", "fit", "fit_fm", "fit_file", "predict", "predict_fm", "plot_fit", "FitResult"]
