"""Tapping-mode AFM (seed 1): periodic orbits, harmonic-balance curves, separation sweeps (docs/theory-tapping.md).

``orbit``, ``hb`` and ``sweep`` are the commands ``afmkit tapping orbit | hb | sweep``; keyword arguments are their
TOML keys, and each returns an :class:`afmkit.Result`.
"""
from ._commands import make_command

orbit = make_command("tapping orbit")
hb = make_command("tapping hb")
sweep = make_command("tapping sweep")

__all__ = ["orbit", "hb", "sweep"]
