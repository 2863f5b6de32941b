"""Force reconstruction from measured FM and AM curves, on NumPy arrays (docs/reconstruction.md).

    r = reconstruct_fm(z, df, spring_constant=1800.0, resonance_frequency=25e3, amplitude=0.5e-9)
    r.force, r.units["force"], r.residual_rms, r.notes
    r.write_law("law.csv")   # then afmkit.tapping.orbit(units="physical", law="table", force_curve="law.csv", ...)

SI units in and out: m, Hz, rad, N/m, N, J. Phase: afmkit's lag convention (docs/conventions.md): pi/2 for the free
cantilever at resonance, in (0, pi). Bad input raises afmkit.InvalidParameter (a ValueError) naming the parameter.
"""
from __future__ import annotations

import numpy as np

from . import _afmkit
from ._commands import make_command

__all__ = ["Reconstruction", "reconstruct_fm", "reconstruct_am", "reconstruct"]

#: The command ``afmkit spectroscopy reconstruct`` on a file (keyword arguments = its TOML keys, e.g.
#: ``reconstruct(input="df.csv", amplitude=0.5, output="")``): the command line's units (nm, kHz, nN).
reconstruct = make_command("spectroscopy reconstruct")

_FM_UNITS = {
    "distance": "m", "frequency_shift": "Hz", "force": "N", "energy": "J", "force_uncertainty": "N",
    "round_trip_frequency_shift": "Hz", "residual": "Hz", "residual_rms": "Hz", "residual_max": "Hz",
    "noise": "Hz", "interaction_length": "m", "tail_decay_length": "m", "tail_sensitivity": "N",
}
_AM_UNITS = {
    "separation": "m", "amplitude": "m", "phase": "rad", "dissipation": "J", "gap": "m",
    "equivalent_frequency_shift": "dimensionless", "force": "N", "force_uncertainty": "N", "gap_dissipation": "J", "approach_force": "N",
    "retract_force": "N", "contact_gap": "m", "round_trip_amplitude_ratio": "dimensionless",
    "round_trip_phase": "rad", "residual_amplitude_ratio": "dimensionless", "residual_phase": "rad",
    "rms_amplitude_ratio": "dimensionless", "rms_phase": "rad", "dropped": "count",
}
_LAW_UNITS = {"distance": "m", "approach_force": "N", "retract_force": "N"}


class Reconstruction:
    """The result of a reconstruction: every array and number as an attribute (and r["name"]), their units in
    ``units``, the table law as arrays in ``law`` (distance, approach_force, retract_force; SI), the notes on
    ill-posedness in ``notes``, the round-trip residuals and the forward model used (``round_trip_model``)."""

    def __init__(self, data: dict, units: dict):
        self._data = dict(data)
        self._law_text = self._data.pop("law_text")
        self.units = dict(units)
        self.units["law"] = dict(_LAW_UNITS)
        for key, value in self._data.items():
            setattr(self, key, value)

    def __getitem__(self, key):
        return self._data[key]

    def keys(self):
        return self._data.keys()

    @property
    def table(self):
        """The reconstructed law as an :class:`afmkit.laws.Table`, which the commands take as ``law=``
        (``afmkit.tapping.sweep(law=r.table, ...)``)."""
        from .laws import Table
        law = self._data["law"]
        return Table(law["distance"], law["approach_force"], law["retract_force"])

    def write_law(self, path: str) -> str:
        """Write the table-law file (distance (nm), approach force (nN), retract force (nN)) that
        ``--law table --force-curve`` and ``afmkit.tapping.*(law="table", force_curve=path)`` read."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self._law_text)
        return path

    def __repr__(self):
        return f"Reconstruction(method={self._data.get('method')!r}, points={len(self._data['force'])}, notes={len(self.notes)})"


def _array(name, value):
    a = np.asarray(value, dtype=float)
    if a.ndim != 1:
        raise _afmkit.InvalidParameter(f"{name} must be a one-dimensional array (got shape {a.shape})")
    return a


def reconstruct_fm(distance, frequency_shift, *, spring_constant, resonance_frequency, amplitude,
                   method="sader_jarvis", tail="zero", noise_realisations=8, seed=1, round_trip=True,
                   round_trip_model="exact", round_trip_points=40, quality_factor=1e4):
    """FM-AFM: the force F(z) [N] from the frequency shift Δf(z) [Hz] measured at constant amplitude ``amplitude``
    [m] against the closest distance z [m], by ``method`` = "sader_jarvis" (Sader & Jarvis 2004) or "matrix"
    (Giessibl 2001); ``tail`` = "zero" (default) or "exponential" beyond the last point. The round trip runs the
    law through afmkit's exact FM orbits (``round_trip_model="exact"``: the self-excited cantilever of
    ``afmkit.tapping.fm`` with quality factor ``quality_factor``, at ``round_trip_points`` of the distances, 0: all)
    or Giessibl's first-order large-amplitude formula (``"first_order"``)."""
    d = _afmkit._reconstruct_fm(_array("distance", distance), _array("frequency_shift", frequency_shift),
                                float(spring_constant), float(resonance_frequency), float(amplitude), str(method),
                                str(tail), int(noise_realisations), int(seed), bool(round_trip),
                                str(round_trip_model), int(round_trip_points), float(quality_factor))
    return Reconstruction(d, _FM_UNITS)


def reconstruct_am(distance, amplitude, phase, *, spring_constant, resonance_frequency, quality_factor,
                   free_amplitude, drive_frequency=None, method="payam", tail="zero", round_trip_points=40,
                   round_trip=True):
    """AM-AFM: the conservative force F(D) [N] at the lower turning point D = l − A, the dissipated energy per
    cycle [J] and the table law whose branches differ by it, from amplitude A(l) [m] and phase φ(l) [rad] measured
    against the separation l [m] (``distance``), at free amplitude A0 [m], Q, k [N/m], f0 [Hz] and drive frequency
    (default f0); ``method`` = "payam" (default), "katan" or "hoelscher". The round trip runs the law through
    afmkit's exact orbits (tapping sweep, approach) at ``round_trip_points`` separations (0: all)."""
    d = _afmkit._reconstruct_am(_array("distance", distance), _array("amplitude", amplitude),
                                _array("phase", phase), float(spring_constant), float(resonance_frequency),
                                float(quality_factor), float(free_amplitude),
                                0.0 if drive_frequency is None else float(drive_frequency), str(method), str(tail),
                                int(round_trip_points), bool(round_trip))
    return Reconstruction(d, _AM_UNITS)
