"""Tapping-mode AFM (seed 1): periodic orbits, harmonic-balance curves, separation sweeps (docs/theory-tapping.md).

``orbit``, ``hb``, ``sweep`` and ``fm`` are the commands ``afmkit tapping orbit | hb | sweep | fm``; keyword arguments are their
TOML keys, and each returns an :class:`afmkit.Result`.
"""
from ._commands import make_command

orbit = make_command("tapping orbit")
hb = make_command("tapping hb")
sweep = make_command("tapping sweep")
fm = make_command("tapping fm")

__all__ = ["orbit", "hb", "sweep", "fm"]
