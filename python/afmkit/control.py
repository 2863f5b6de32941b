"""First-harmonic rejection (seed 2): transfer functions, roots, delay margins, stability charts, tuning,
simulation, the C-header export, and the real-time filter on NumPy buffers (docs/theory-control.md).

``tf``, ``roots``, ``margin``, ``chart``, ``tune``, ``simulate`` and ``export`` are the commands
``afmkit control …``; keyword arguments are their TOML keys, and each returns an :class:`afmkit.Result`.
"""
from ._afmkit import RealtimeFilter
from ._commands import make_command

tf = make_command("control tf")
roots = make_command("control roots")
margin = make_command("control margin")
chart = make_command("control chart")
tune = make_command("control tune")
simulate = make_command("control simulate")
export = make_command("control export")

__all__ = ["tf", "roots", "margin", "chart", "tune", "simulate", "export", "RealtimeFilter"]
