"""afmkit: dynamics and control of atomic force microscopes, from Python (docs/python.md).

Every command of the ``afmkit`` program is a function whose keyword arguments are the command's TOML keys::

    import afmkit
    r = afmkit.tapping.hb(units="physical", quality_factor=100, separation_min=-5, separation_max=30)
    r["amplitude"], r.amplitude, r.units["amplitude"], r.results.folds, r.to_pandas(), r.to_xarray()

    afmkit.impact(...), afmkit.tapping.orbit | hb | sweep | fm(...), afmkit.control.tf | roots | margin | chart |
    tune | simulate | export(...), afmkit.scan(...), afmkit.demo(...)

``afmkit.control.RealtimeFilter`` runs the real-time filter on NumPy buffers. Bad input raises
``afmkit.InvalidParameter`` / ``afmkit.InputError`` (both ValueError) with the command line's messages, or TypeError
for a keyword of the wrong Python type; a solver that does not converge raises ``afmkit.NumericalFailure``.
"""
from . import _afmkit
from ._afmkit import InputError, InvalidParameter, NumericalFailure
from ._commands import Result, command_functions, make_command
from . import control, laws, spectroscopy, tapping

__version__ = _afmkit.__version__

# impact, scan, demo: the program's top-level commands, from its command registry (_afmkit.commands())
_functions = command_functions("")
globals().update(_functions)

__all__ = [*_functions, "tapping", "control", "spectroscopy", "laws", "Result", "InvalidParameter", "InputError",
           "NumericalFailure"]
