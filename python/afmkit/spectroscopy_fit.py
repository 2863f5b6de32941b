"""Fitting a force law to a measured AM-AFM amplitude/phase-versus-distance curve or FM-AFM frequency-shift curve
(docs/fitting.md).

``fit(distance, amplitude, phase, *, law="dmt", parameters=[...], initial={...}, fixed={...}, spring_constant=...,
resonance_frequency=..., quality_factor=..., free_amplitude=...)`` takes NumPy arrays in SI units (m, rad, N/m, Hz)
and returns a :class:`FitResult`: estimates with standard errors, the correlation matrix, identifiability
warnings, the fitted curves and the status. ``fit_fm(distance, frequency_shift, dissipation=None, *, ...,
amplitude=...)`` is the same for an FM-AFM curve (Hz, J per cycle). ``predict`` and ``predict_fm`` are the forward
models alone (synthetic data), ``plot`` draws data vs fit (Matplotlib), and ``run`` is the command ``afmkit
spectroscopy fit`` on a file (keyword arguments are its TOML keys, in the command's units).

Command line: ``python3 -m afmkit._fit_plot --plot TABLE.csv OUT.png`` draws the plot of a table written by
``afmkit spectroscopy fit`` (what its ``--plot`` does).
"""
from __future__ import annotations

import dataclasses
import os
import sys
import tempfile

import numpy as np

from . import _afmkit
from ._commands import make_command

run = make_command("spectroscopy fit")

DEFAULT_PARAMETERS = ("hamaker", "effective_modulus", "distance_offset", "phase_offset")
DEFAULT_FM_PARAMETERS = ("hamaker", "effective_modulus", "distance_offset")


@dataclasses.dataclass
class FitResult:
    """What :func:`fit` or :func:`fit_fm` found. Arrays of the curve are in the sweep's order (approach: distance
    decreasing).

    ``mode``: "am" or "fm"; ``estimates``, ``standard_errors``, ``units``: dicts by parameter name (SI: m, Pa, J, rad,
    Hz, ...); ``correlation``: P×P array in the order of ``names``; ``identifiable``: dict of bool; ``warnings``:
    list of str; ``status``: "ok" or "not_converged" (``solver_status`` says why); ``curve_evaluations``,
    ``orbit_evaluations``, ``seconds``; ``law_values``: every law value used (SI). AM: ``amplitude``, ``phase``,
    ``fitted_*``, ``rms_amplitude`` (A/A0), ``rms_phase`` (rad); FM: ``frequency_shift``, ``dissipation`` (None when
    not measured), ``fitted_*``, ``rms_frequency_shift`` (Hz), ``rms_dissipation`` (J). The residuals measured −
    fitted: ``residuals()``.
    """

    mode: str
    status: str
    solver_status: str
    names: list
    estimates: dict
    standard_errors: dict
    units: dict
    initial: dict
    transforms: dict
    correlation: np.ndarray
    identifiable: dict
    warnings: list
    condition_number: float
    distance: np.ndarray
    contact: np.ndarray
    jumped: np.ndarray
    reduced_chi2: float
    iterations: int
    curve_evaluations: int
    orbit_evaluations: int
    failed_evaluations: int
    seconds: float
    law_values: dict
    # AM
    amplitude: np.ndarray | None = None
    phase: np.ndarray | None = None
    fitted_amplitude: np.ndarray | None = None
    fitted_phase: np.ndarray | None = None
    amplitude_noise: float = float("nan")
    phase_noise: float = float("nan")
    rms_amplitude: float = float("nan")
    rms_phase: float = float("nan")
    free_amplitude: float = float("nan")
    # FM
    frequency_shift: np.ndarray | None = None
    dissipation: np.ndarray | None = None
    fitted_frequency_shift: np.ndarray | None = None
    fitted_dissipation: np.ndarray | None = None
    frequency_shift_noise: float = float("nan")
    dissipation_noise: float = float("nan")
    rms_frequency_shift: float = float("nan")
    rms_dissipation: float = float("nan")

    def residuals(self) -> dict:
        """Measured − fitted, SI: AM ``amplitude`` [m] and ``phase`` [rad, wrapped to (−π, π]]; FM
        ``frequency_shift`` [Hz] and ``dissipation`` [J] (the channels measured)."""
        if self.mode == "fm":
            out = {"frequency_shift": self.frequency_shift - self.fitted_frequency_shift}
            if self.dissipation is not None:
                out["dissipation"] = self.dissipation - self.fitted_dissipation
            return out
        out = {"amplitude": self.amplitude - self.fitted_amplitude}
        if self.phase is not None:
            out["phase"] = np.angle(np.exp(1j * (self.phase - self.fitted_phase)))
        return out

    @property
    def converged(self) -> bool:
        return self.status == "ok"

    def plot(self, path: str) -> str:
        """Data vs fit as a PNG at ``path`` (see :func:`plot`)."""
        return plot(self, path)

    def __repr__(self) -> str:
        lines = [f"FitResult(status={self.status!r}, {len(self.distance)} points)"]
        for n in self.names:
            lines.append(f"  {n} = {self.estimates[n]:.6g} ± {self.standard_errors[n]:.3g} {self.units[n]}")
        lines += [f"  warning: {w}" for w in self.warnings]
        return "\n".join(lines)


def _settings(spring_constant, resonance_frequency, quality_factor, free_amplitude, drive_frequency):
    return dict(spring_constant=float(spring_constant), resonance_frequency=float(resonance_frequency),
                quality_factor=float(quality_factor), free_amplitude=float(free_amplitude),
                drive_frequency=0.0 if drive_frequency is None else float(drive_frequency))


# The solver's settings (huber, fd_step, max_evaluations, tolerance, integrator_tolerance, shooting_tolerance,
# correlation_limit, condition_limit, flat_column) and their defaults: declared once, by the library's
# spectroscopy::FitOptions (the command line's `afmkit spectroscopy fit` has the same), which also checks their ranges.
_SOLVER_DEFAULTS = _afmkit.spectroscopy_fit_solver_defaults()


def _law_arguments(law, values, force_curve, values_name: str):
    """A law given as a string, or as an :mod:`afmkit.laws` object: its name, its values (SI) joined to ``values``
    (a key in both is refused) and, for ``laws.Table``, its file as the force curve."""
    from . import laws
    if not isinstance(law, laws.Law):
        return law, values, force_curve
    if isinstance(law, laws.Python):
        raise TypeError("law: a law written in Python (afmkit.laws.Python) cannot be fitted: the fit adjusts the "
                        "parameters of a built-in law (law='dmt', afmkit.laws.DMT(...), ...) or of a table")
    if isinstance(law, laws.Table):
        if force_curve:
            raise ValueError("force_curve is given besides law=afmkit.laws.Table(...), which is a force curve: "
                             "give one of them")
        return "table", values, law.path()
    merged = dict(values or {})
    for key, value in law.si_values().items():
        if key in merged:
            raise ValueError(f"{key} is given both in the law ({law!r}) and in {values_name}: give it once")
        merged[key] = value
    return law.name, merged, force_curve


def _options(law="dmt", parameters=DEFAULT_PARAMETERS, initial=None, fixed=None, direction="approach",
             force_curve="", allow_energy_gain=False, parallel=True, **solver) -> dict:
    """The options :func:`fit` and :func:`fit_fm` share, with their defaults (docs/fitting.md)."""
    for key in solver:
        if key not in _SOLVER_DEFAULTS:
            raise TypeError(f"fit() got an unexpected keyword argument '{key}'")
    # each setting as the type of its default (an integer count may be given as 100.0)
    settings = {key: type(default)(solver.get(key, default)) for key, default in _SOLVER_DEFAULTS.items()}
    law, fixed, force_curve = _law_arguments(law, fixed, force_curve, "fixed")
    return dict(law=str(law), parameters=[str(p) for p in parameters], initial=dict(initial or {}),
                fixed=dict(fixed or {}), direction=str(direction), force_curve=str(force_curve),
                allow_energy_gain=bool(allow_energy_gain), parallel=bool(parallel), **settings)


def fit(distance, amplitude, phase=None, *, spring_constant, resonance_frequency, quality_factor, free_amplitude,
        drive_frequency=None, amplitude_noise: float = 0.0, phase_noise: float = 0.0, **options) -> FitResult:
    """Weighted nonlinear least squares of a law (and calibration) to an AM-AFM curve, SI units throughout.

    distance [m], amplitude [m], phase [rad] (phase lag, pi/2 at resonance; None: amplitude only): 1-D arrays.
    spring_constant [N/m], resonance_frequency [Hz], quality_factor, free_amplitude [m], drive_frequency [Hz] (None:
    at resonance). amplitude_noise (A/A0) and phase_noise [rad]: 0 estimates them from the data. Options (keyword):
    law ("dmt", or a law object such as ``afmkit.laws.DMT(tip_radius=8)`` or ``afmkit.laws.Table(...)``: its values
    are fixed values, or initial values of the fitted ones); parameters: the fitted names (law keys, distance_offset [m], amplitude_scale, phase_offset [rad];
    default hamaker, effective_modulus, distance_offset, phase_offset); initial: initial values of fitted parameters
    and fixed calibration values (SI); fixed: the law's other values (SI: hamaker J, effective_modulus Pa,
    tip_radius m, ...); direction ("approach" or "retract"); huber (5: Huber's loss beyond this many σ, 0: least
    squares); force_curve, allow_energy_gain; fd_step (1e-3), max_evaluations (100), tolerance (1e-4),
    integrator_tolerance (1e-9), shooting_tolerance (1e-10), correlation_limit (0.99), condition_limit (1e10),
    flat_column (1e-3), parallel (True). Raises afmkit.InvalidParameter on bad input and afmkit.NumericalFailure when
    the model fails at the initial values; a fit that does not converge returns status "not_converged".
    """
    raw = _afmkit.spectroscopy_fit(
        np.asarray(distance, dtype=float), np.asarray(amplitude, dtype=float),
        None if phase is None else np.asarray(phase, dtype=float),
        **_settings(spring_constant, resonance_frequency, quality_factor, free_amplitude, drive_frequency),
        amplitude_noise=float(amplitude_noise), phase_noise=float(phase_noise), options=_options(**options))
    result = _result(raw)
    result.free_amplitude = float(free_amplitude)
    return result


def _result(raw: dict) -> FitResult:
    names = list(raw["names"])
    by_name = lambda values: {n: v for n, v in zip(names, values)}  # noqa: E731
    fields = {f.name for f in dataclasses.fields(FitResult)}
    common = dict(
        mode=raw["mode"], status=raw["status"], solver_status=raw["solver_status"], names=names,
        estimates=by_name(float(x) for x in raw["estimates"]),
        standard_errors=by_name(float(x) for x in raw["standard_errors"]), units=by_name(raw["units"]),
        initial=by_name(float(x) for x in raw["initial"]), transforms=by_name(raw["transforms"]),
        correlation=np.asarray(raw["correlation"]), identifiable=by_name(bool(b) for b in raw["identifiable"]),
        warnings=list(raw["warnings"]), law_values=dict(raw["law_values"]))
    rest = {k: v for k, v in raw.items() if k in fields and k not in common}
    return FitResult(**common, **rest)


def fit_fm(distance, frequency_shift, dissipation=None, *, spring_constant, resonance_frequency, quality_factor,
           amplitude, frequency_shift_noise: float = 0.0, dissipation_noise: float = 0.0, **options) -> FitResult:
    """Weighted nonlinear least squares of a law (and calibration) to an FM-AFM curve, SI units throughout.

    distance [m], frequency_shift [Hz] (Δf = f − f0 at constant amplitude), dissipation [J per cycle] (None: Δf only):
    1-D arrays. spring_constant [N/m], resonance_frequency [Hz], quality_factor, amplitude [m] (the oscillation
    amplitude held by the amplitude loop). frequency_shift_noise [Hz] and dissipation_noise [J]: 0 estimates them
    from the data. Options as :func:`fit`, except parameters: law keys, distance_offset [m] and
    frequency_shift_offset [Hz] (default hamaker, effective_modulus, distance_offset). The forward model is the
    exact FM orbits of ``afmkit tapping fm`` (docs/fitting.md#fm-afm). Raises afmkit.InvalidParameter on bad input
    and afmkit.NumericalFailure when the model fails at the initial values.
    """
    options.setdefault("parameters", DEFAULT_FM_PARAMETERS)
    raw = _afmkit.spectroscopy_fit_fm(
        np.asarray(distance, dtype=float), np.asarray(frequency_shift, dtype=float),
        None if dissipation is None else np.asarray(dissipation, dtype=float),
        spring_constant=float(spring_constant), resonance_frequency=float(resonance_frequency),
        quality_factor=float(quality_factor), amplitude=float(amplitude),
        frequency_shift_noise=float(frequency_shift_noise), dissipation_noise=float(dissipation_noise),
        options=_options(**options))
    return _result(raw)


def predict(distance, *, law="dmt", values=None, calibration=None, spring_constant, resonance_frequency,
            quality_factor, free_amplitude, drive_frequency=None, direction: str = "approach",
            force_curve: str = "", allow_energy_gain: bool = False) -> dict:
    """The fit's forward model: amplitude [m] and phase [rad] at each distance [m] (in the order given), for the law
    values ``values`` (SI) and the calibration (distance_offset [m], amplitude_scale, phase_offset [rad]). ``law``: a
    name or an :mod:`afmkit.laws` object (its values join ``values``)."""
    law, values, force_curve = _law_arguments(law, values, force_curve, "values")
    return _afmkit.spectroscopy_predict(
        np.asarray(distance, dtype=float), str(law), dict(values or {}), dict(calibration or {}), force_curve,
        bool(allow_energy_gain),
        **_settings(spring_constant, resonance_frequency, quality_factor, free_amplitude, drive_frequency),
        direction=direction)


def predict_fm(distance, *, law="dmt", values=None, calibration=None, spring_constant, resonance_frequency,
               quality_factor, amplitude, direction: str = "approach", force_curve: str = "",
               allow_energy_gain: bool = False) -> dict:
    """The FM fit's forward model: frequency shift [Hz] (+ frequency_shift_offset) and dissipation [J per cycle] at
    each distance [m] (in the order given), for the law values ``values`` (SI) and the calibration
    (distance_offset [m], frequency_shift_offset [Hz])."""
    law, values, force_curve = _law_arguments(law, values, force_curve, "values")
    return _afmkit.spectroscopy_predict_fm(
        np.asarray(distance, dtype=float), str(law), dict(values or {}), dict(calibration or {}), force_curve,
        bool(allow_energy_gain), spring_constant=float(spring_constant),
        resonance_frequency=float(resonance_frequency), quality_factor=float(quality_factor),
        amplitude=float(amplitude), direction=direction)


def _draw(distance_nm, panels, title, path):
    """Data vs fit, one panel per (ylabel, data, fit, colour) of ``panels``, against distance in nm."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = len(panels)
    lines = title.count("\n") + 1
    fig, axes = plt.subplots(rows, 1, figsize=(6.4, 2.6 * rows + 0.25 * lines + 0.4), sharex=True, squeeze=False)
    for k, (label, data, fitted, colour) in enumerate(panels):
        ax = axes[k][0]
        ax.plot(distance_nm, data, "o", ms=3, color="0.55", label="data")
        ax.plot(distance_nm, fitted, "-", color=colour, lw=1.5, label="fit")
        ax.set_ylabel(label)
        if k == 0:
            ax.legend(loc="best", frameon=False)
            ax.set_title(title, fontsize=9)
    axes[-1][0].set_xlabel("distance (nm)")
    fig.tight_layout()
    # written through a temporary of its own, then moved into place: a reader never sees half a PNG
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".plot-", suffix=".png", dir=folder)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=120, format="png")
        os.replace(tmp, path)
    finally:
        plt.close(fig)
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


_EV = 1.602176634e-19  # J


def _am_panels(amplitude_a0, fitted_a0, phase_deg, fitted_phase_deg):
    panels = [("amplitude A / A0", amplitude_a0, fitted_a0, "C3")]
    if phase_deg is not None:
        panels.append(("phase (deg)", phase_deg, fitted_phase_deg, "C0"))
    return panels


def _fm_panels(df_hz, fitted_df_hz, dissipation_ev, fitted_dissipation_ev):
    panels = [("frequency shift Δf (Hz)", df_hz, fitted_df_hz, "C3")]
    if dissipation_ev is not None:
        panels.append(("dissipation (eV/cycle)", dissipation_ev, fitted_dissipation_ev, "C0"))
    return panels


def plot(result: FitResult, path: str) -> str:
    """Data vs fit as a PNG at ``path``: AM A/A0 and phase in degrees, FM Δf in Hz and dissipation in eV per cycle,
    against distance in nm."""
    title = "\n".join(f"{n} = {result.estimates[n]:.4g} ± {result.standard_errors[n]:.2g} {result.units[n]}"
                       for n in result.names)
    if result.mode == "fm":
        diss = None if result.dissipation is None else result.dissipation / _EV
        fitted = None if result.dissipation is None else result.fitted_dissipation / _EV
        panels = _fm_panels(result.frequency_shift, result.fitted_frequency_shift, diss, fitted)
    else:
        a0 = result.free_amplitude
        phase = None if result.phase is None else np.degrees(result.phase)
        fitted_phase = None if result.phase is None else np.degrees(result.fitted_phase)
        panels = _am_panels(result.amplitude / a0, result.fitted_amplitude / a0, phase, fitted_phase)
    return _draw(result.distance * 1e9, panels, title, path)


def plot_table(table: str, path: str) -> str:
    """The plot of a table written by ``afmkit spectroscopy fit`` (its sidecar gives A0 and the estimates)."""
    import json

    with open(table + ".json", encoding="utf-8") as f:
        sidecar = json.load(f)
    data = np.genfromtxt(table, delimiter=",", names=True)
    results = sidecar["results"]
    units = results.get("units", {}).get("estimates", {})  # per estimate: the unit of its value
    title = "\n".join(f"{n} = {e['value']:.4g} ± {e['standard_error']:.2g} {units.get(n, {}).get('value', '')}"
                       for n, e in results["estimates"].items())
    columns = data.dtype.names
    if "frequency_shift" in columns:
        has_diss = "dissipation" in columns
        panels = _fm_panels(data["frequency_shift"], data["fitted_frequency_shift"],
                            data["dissipation"] if has_diss else None, data["fitted_dissipation"] if has_diss else None)
    else:
        a0 = float(sidecar["parameters"]["free_amplitude"])
        has_phase = "phase" in columns
        panels = _am_panels(data["amplitude"] / a0, data["fitted_amplitude"] / a0,
                            data["phase"] if has_phase else None, data["fitted_phase"] if has_phase else None)
    return _draw(data["distance"], panels, title, path)


def _main(argv) -> int:
    if len(argv) != 3 or argv[0] != "--plot":
        print("usage: python3 -m afmkit._fit_plot --plot TABLE.csv OUT.png", file=sys.stderr)
        return 2
    try:
        plot_table(argv[1], argv[2])
    except (OSError, ValueError, KeyError) as e:
        print(f"afmkit: spectroscopy fit --plot: cannot draw {argv[2]} from {argv[1]}: {e}", file=sys.stderr)
        return 1
    print(f"wrote the plot to {argv[2]}")
    return 0


__all__ = ["fit", "fit_fm", "predict", "predict_fm", "plot", "plot_table", "run", "FitResult"]

if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
