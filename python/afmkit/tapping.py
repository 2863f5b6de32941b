"""Tapping-mode AFM (seed 1): periodic orbits, harmonic-balance curves, separation sweeps (docs/theory-tapping.md).

``orbit``, ``hb``, ``sweep`` and ``fm`` are the commands ``afmkit tapping orbit | hb | sweep | fm``; keyword arguments are their
TOML keys, and each returns an :class:`afmkit.Result`.
"""
from ._commands import command_functions

# orbit, hb, sweep, fm: every `afmkit tapping …` command a function runs, from the program's command registry
# (`tapping grid` writes a store: a study of tapping.orbit, afmkit.study)
_functions = command_functions("tapping")
globals().update(_functions)

__all__ = list(_functions)
