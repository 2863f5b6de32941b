"""First-harmonic rejection (seed 2): transfer functions, roots, delay margins, stability charts, tuning,
simulation, the C-header export, and the real-time filter on NumPy buffers (docs/theory-control.md).

``tf``, ``roots``, ``margin``, ``chart``, ``tune``, ``simulate`` and ``export`` are the commands
``afmkit control …``; keyword arguments are their TOML keys, and each returns an :class:`afmkit.Result`.

Every key in units of Ω or T has an SI form given instead of it, never guessed: ``delay_seconds`` (s),
``alpha_rad_per_s`` (rad/s), ``rotation_frequency_hz`` (Hz), ``frequency_max_hz`` (Hz), … (docs/python.md#control).

A design is an object: :class:`Controller` (``Controller(harmonics=10, alpha=0.1, beta=-0.1)``, or
``tune(...).controller``) holds exactly the keywords that define it; every command takes it as
``controller=design`` (keywords given in the call take precedence), and it has ``d.tf()``, ``d.margin()``, …,
``d.state_space()`` (A, B, C, D for ``control.ss``) and ``d.frequency_response()`` (ω, G(iω) for ``control.frd``).
"""
from __future__ import annotations

import functools
import inspect
import json

import numpy as np

from . import _afmkit
from ._afmkit import RealtimeFilter
from ._commands import Result, make_command

_PATHS = ("tf", "roots", "margin", "chart", "tune", "simulate", "export")
_SI_SUFFIXES = ("_rad_per_s", "_hz", "_seconds")


def _shared_keys() -> list:
    """The keys every control command has: the controller, the plant and the delay (with their SI forms)."""
    specs = {s["path"]: [p["key"] for p in s["params"]] for s in _afmkit.commands()}
    common = set.intersection(*(set(specs["control " + c]) for c in _PATHS))
    return [k for k in specs["control tf"] if k in common and k not in ("output", "json")]


_KEYS = _shared_keys()


def _base(key: str) -> str:
    """The key a keyword stands for: ``delay`` for ``delay_seconds``, itself otherwise."""
    for suffix in _SI_SUFFIXES:
        if key.endswith(suffix) and key[: -len(suffix)] in _KEYS:
            return key[: -len(suffix)]
    return key


class Controller:
    """A controller design of the first-harmonic rejection loop: exactly the keywords that define it (the control
    commands' shared keys: ``controller``, ``harmonics``, ``alpha``, ``beta``, ``a``, ``b``, ``rejected``, ``gain``,
    ``rotation_frequency``, the Smith predictor's keys, and, when given, ``plant``, ``plant_rate``, ``delay``, each
    in units of Ω and T or in its SI form such as ``delay_seconds``).

    Validated when made (afmkit.InvalidParameter naming the key, as the commands). ``d.params`` are the keywords;
    ``d.settings`` / ``d.settings_si`` the resolved values (Ω, T; rad/s, s). Every command takes it:
    ``afmkit.control.margin(controller=d)``, ``d.margin()``, ``d.simulate(periods=40)``; keywords given in the call
    take precedence over the design's (``d.margin(delay_seconds=2e-3)``).
    """

    def __init__(self, **params):
        unknown = sorted(set(params) - set(_KEYS))
        if unknown:
            raise TypeError(f"afmkit.control.Controller: unexpected keyword(s) {', '.join(unknown)} (a design holds "
                            f"the controller, plant and delay keys: {', '.join(_KEYS)})")
        self._params = {k: v for k, v in params.items() if v is not None}
        resolved = json.loads(_afmkit.control_settings(self._params))  # validates, as the commands do
        self.settings: dict = resolved["settings"]
        self.settings_si: dict = resolved["settings_si"]

    @property
    def params(self) -> dict:
        """The keywords of the design (a copy)."""
        return dict(self._params)

    def __repr__(self):
        return "Controller(" + ", ".join(f"{k}={v!r}" for k, v in self._params.items()) + ")"

    def __eq__(self, other):
        return isinstance(other, Controller) and self._params == other._params

    def keywords(self, given: dict) -> dict:
        """The keywords of a command run with this design and the call's `given` ones: the call's take precedence
        (a quantity given in the call in any of its units replaces the design's value in all of them)."""
        replaced = {_base(k) for k in given}
        out = {k: v for k, v in self._params.items() if _base(k) not in replaced}
        out.update(given)
        return out

    # ---- the commands with this design
    def tf(self, **kwargs) -> Result:
        return tf(controller=self, **kwargs)

    def roots(self, **kwargs) -> Result:
        return roots(controller=self, **kwargs)

    def margin(self, **kwargs) -> Result:
        return margin(controller=self, **kwargs)

    def chart(self, **kwargs) -> Result:
        return chart(controller=self, **kwargs)

    def simulate(self, **kwargs) -> Result:
        return simulate(controller=self, **kwargs)

    def export(self, **kwargs) -> Result:
        return export(controller=self, **kwargs)

    # ---- interoperation (python-control and others)
    def state_space(self, system: str = "controller", **kwargs):
        """``(A, B, C, D)`` as NumPy arrays in rad/s: ``system="controller"``, from the measurement m to w = −u
        (C(s) = C (sI − A)⁻¹ B + D, the response of ``tf(system="controller", frequency_unit="rad/s")``; bank and
        single oscillator: the infinite bank and the Smith predictor have no finite realisation), or
        ``"plant"``, the delay-free plant from u to y (the delay is ``d.settings_si["delay"]`` in s: e^{−sτ}).
        ``control.ss(*d.state_space())`` is the python-control system. Keywords: as for the commands."""
        if system not in ("controller", "plant"):
            raise ValueError(f"system = {system!r}: must be 'controller' or 'plant'")
        m = _afmkit.control_state_space(self.keywords(kwargs))[system]
        return tuple(np.array(m[k], dtype=float) for k in "ABCD")

    def frequency_response(self, system: str = "controller", **kwargs):
        """``(omega, response)``: angular frequencies in rad/s and the complex response G(iω) in SI units
        (controller 1/s, plant s, loop, sensitivity, closed loop dimensionless) of ``tf`` with these keywords
        (``frequency_min_hz=…, frequency_max_hz=…, points=…``, ``log_spacing``). ``control.frd(response, omega)``
        is the python-control frequency-response data."""
        r = self.tf(system=system, frequency_unit="rad/s", **kwargs)
        return np.asarray(r["frequency"]), np.asarray(r["real"]) + 1j * np.asarray(r["imag"])

    def to_python_control(self, system: str = "controller", **kwargs):
        """The python-control ``StateSpace`` of :meth:`state_space` (needs the package ``control``)."""
        try:
            import control as ct
        except ImportError:
            raise ImportError("Controller.to_python_control() needs python-control (pip install control); "
                              "state_space() gives the matrices without it") from None
        return ct.ss(*self.state_space(system, **kwargs))


def _design(value):
    """The Controller `value` stands for: a Controller, or the Result of ``tune`` (its optimum)."""
    if isinstance(value, Controller):
        return value
    if isinstance(value, Result) and value.command == "control tune":
        return value.controller
    return None


# The keys that define a controller of each kind (and its Smith predictor); the plant's keys define its gain rule.
_COMMON = {"controller", "rotation_frequency", "gain", "plant", "plant_rate"}
_OF_KIND = {"single": {"a", "b"}, "bank": {"harmonics", "alpha", "beta", "rejected"}, "infinite": {"alpha", "beta"},
            "smith": {"smith_bank", "smith_structure", "model_plant", "model_rate", "model_delay"}}


def _tuned(r: Result) -> Controller:
    """The design ``tune`` found: the keys of its record that define the controller (not the delay, which tune
    spans from 0 to delay_max) with the optimum couplings (units of Ω)."""
    kind = r.params.get("controller", "bank")
    inner = r.params.get("smith_bank", "bank") if kind == "smith" else kind
    wanted = _COMMON | _OF_KIND[kind] | _OF_KIND[inner]
    params = {k: v for k, v in r.params.items() if k in _KEYS and _base(k) in wanted}
    optimum = dict(r.results["optimum"])
    params = {k: v for k, v in params.items() if _base(k) not in optimum}
    params.update(optimum)
    return Controller(**params)


def _with_designs(command):
    """`command` taking ``controller=`` a Controller (or a tune Result) as well as a controller kind."""

    @functools.wraps(command)
    def run(*args, controller=None, **kwargs):
        design = _design(controller)
        if design is not None:
            return command(*args, **design.keywords(kwargs))
        return command(*args, controller=controller, **kwargs)

    sig = inspect.signature(command)
    run.__signature__ = sig.replace(parameters=[
        p.replace(annotation="str | Controller") if p.name == "controller" else p for p in sig.parameters.values()])
    return run


tf = _with_designs(make_command("control tf"))
roots = _with_designs(make_command("control roots"))
margin = _with_designs(make_command("control margin"))
chart = _with_designs(make_command("control chart"))
simulate = _with_designs(make_command("control simulate"))
export = _with_designs(make_command("control export"))
_tune = _with_designs(make_command("control tune"))


@functools.wraps(_tune)
def tune(*args, **kwargs) -> Result:
    r = _tune(*args, **kwargs)
    r.controller = _tuned(r)  # the design found: d.margin(), afmkit.control.simulate(controller=d), …
    return r


tune.__doc__ = (_tune.__doc__ or "") + "\n\nThe Result's ``controller`` is the design found (a Controller)."

__all__ = ["tf", "roots", "margin", "chart", "tune", "simulate", "export", "Controller", "RealtimeFilter"]
