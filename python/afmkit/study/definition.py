"""What a study is: named axes over parameters of one afmkit command, fixed parameters, the outputs wanted.

A study is a value: validated when made, compared by its fingerprint (the store it writes remembers it and refuses
another study's results).
"""
from __future__ import annotations

import functools
import hashlib
import json
import math
import os
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: computations a study can run at each point: the afmkit command behind each
COMPUTATIONS = {
    "tapping.orbit": "tapping orbit",
    "tapping.sweep": "tapping sweep",
    "tapping.hb": "tapping hb",
    "tapping.fm": "tapping fm",
    "control.roots": "control roots",
    "control.margin": "control margin",
    "control.simulate": "control simulate",
}


@functools.lru_cache(maxsize=None)
def parameters_of(command: str) -> dict:
    """The parameters of afmkit `command` (key -> kind, unit, default, …), as the module describes them."""
    from .. import _afmkit

    spec = next(s for s in _afmkit.commands() if s["path"] == command)
    return {p["key"]: p for p in spec["params"]}


class StudyError(ValueError):
    """A study that cannot be run as described; `field` names the part that is wrong."""

    def __init__(self, field_name: str, message: str):
        super().__init__(message)
        self.field = field_name


#: Memory per value of an axis while the study is made: the float64 of the grid, the Python float of the axis
#: tuple and its slot, and the value in the study's JSON definition (bytes, rounded up).
AXIS_BYTES_PER_VALUE = 64


def require_memory(field_name: str, count: float, bytes_each: float) -> None:
    """StudyError naming `field_name` when `count` items of `bytes_each` bytes exceed the memory afmkit may use
    (half of what is available, capped by AFMKIT_MEMORY_LIMIT; the commands' check), before anything is allocated."""
    from .. import _afmkit

    try:
        _afmkit.require_memory(field_name, float(count), float(bytes_each))
    except _afmkit.InvalidParameter as e:
        raise StudyError(field_name, str(e)) from None


def read_toml(path) -> dict:
    """The TOML document of a study file; StudyError naming the file (and where it is wrong) otherwise."""
    if not isinstance(path, (str, os.PathLike)):
        raise StudyError("file", f"study file = {path!r} is not allowed: must be a path (str or os.PathLike)")
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as e:
        raise StudyError("file", f"study file '{path}' cannot be read: {e.strerror or e}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data[:e.start].count(b"\n") + 1
        raise StudyError("file", f"study file '{path}' is not UTF-8 text: byte 0x{data[e.start]:02x} at line {line} "
                                 f"(offset {e.start}); a study file must be UTF-8") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise StudyError("file", f"study file '{path}' is not valid TOML: {e}") from None
    except RecursionError:
        raise StudyError("file", f"study file '{path}' is nested too deeply to be read") from None


@dataclass(frozen=True)
class Axis:
    """One named axis: a numeric parameter of the computation's command and its values (in the command's units)."""

    name: str
    values: tuple

    @staticmethod
    def make(name: str, spec) -> "Axis":
        """From a list of values, or {start, stop, points} (evenly spaced, both ends included), or
        {values = [...]}."""
        values = spec
        if isinstance(spec, dict):
            spec = dict(spec)
            if "values" in spec:
                values = spec.pop("values")
            else:
                try:
                    start, stop, points = spec.pop("start"), spec.pop("stop"), spec.pop("points")
                except KeyError as e:
                    raise StudyError(f"axes.{name}", f"axes.{name}: needs values = [...] or start, stop and points "
                                                     f"(missing {e.args[0]})") from None
                if not isinstance(points, int) or isinstance(points, bool) or points < 1:
                    raise StudyError(f"axes.{name}", f"axes.{name}: points = {points!r} must be an integer >= 1")
                _finite(name, [start, stop])
                require_memory(f"axes.{name}", points, AXIS_BYTES_PER_VALUE)  # before the values exist
                values = np.linspace(float(start), float(stop), points).tolist()
            if spec:
                raise StudyError(f"axes.{name}", f"axes.{name}: unknown field(s) {', '.join(sorted(spec))} "
                                                 f"(allowed: values, or start, stop, points)")
        values = _numbers(name, values)
        if not values:
            raise StudyError(f"axes.{name}", f"axes.{name} is empty: an axis needs at least one value")
        _finite(name, values)
        if len(set(values)) != len(values):
            raise StudyError(f"axes.{name}", f"axes.{name} repeats a value: every value must be distinct")
        return Axis(name, tuple(values))


def _numbers(name, values) -> list:
    """The values of axis `name` as floats: a flat list, tuple or 1-D array of real numbers. Refused (naming the axis),
    never coerced: booleans (True is not 1.0), nested lists or arrays (not flattened), strings, complex numbers."""
    if isinstance(values, np.ndarray):
        if values.ndim != 1:
            raise StudyError(f"axes.{name}", f"axes.{name}: values must be a flat list of numbers, not a "
                                             f"{values.ndim}-D array")
        if values.dtype.kind not in "iuf":
            raise StudyError(f"axes.{name}", f"axes.{name}: values must be real numbers, not {values.dtype} "
                                             f"(booleans and text are not axis values)")
        return [float(v) for v in values]
    if not isinstance(values, (list, tuple)):
        raise StudyError(f"axes.{name}", f"axes.{name} = {values!r}: must be a list of numbers or "
                                         f"{{start, stop, points}}")
    out = []
    for i, v in enumerate(values):
        if isinstance(v, (bool, np.bool_)):
            raise StudyError(f"axes.{name}", f"axes.{name}[{i}] = {v!r}: a boolean is not an axis value (must be a "
                                             f"real number)")
        if isinstance(v, (list, tuple, dict, np.ndarray)):
            raise StudyError(f"axes.{name}", f"axes.{name}[{i}] is a nested {type(v).__name__}: an axis is a flat "
                                             f"list of numbers")
        if not isinstance(v, (int, float, np.integer, np.floating)):
            raise StudyError(f"axes.{name}", f"axes.{name}[{i}] = {v!r}: must be a real number, not "
                                             f"{type(v).__name__}")
        try:
            out.append(float(v))
        except OverflowError:
            raise StudyError(f"axes.{name}", f"axes.{name}[{i}] = {v!r} is beyond the range of a float") from None
    return out


def _finite(name, values):
    for v in values:
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
            raise StudyError(f"axes.{name}", f"axes.{name} contains {v!r}: every value must be a finite number")


@dataclass(frozen=True)
class Study:
    """A parameter study: `computation` (see COMPUTATIONS) at every point of the grid of `axes`, with the fixed
    `parameters` (TOML keys of the command), recording `outputs` (selectors, docs/study.md)."""

    computation: str
    axes: tuple
    outputs: tuple
    parameters: dict = field(default_factory=dict)
    name: str = "study"

    @staticmethod
    def make(computation: str, axes: dict, outputs, parameters: dict | None = None, name: str = "study") -> "Study":
        if computation not in COMPUTATIONS:
            raise StudyError("computation", f"computation = {computation!r} is not allowed: must be one of "
                                            f"{', '.join(COMPUTATIONS)}")
        if not isinstance(axes, dict) or not axes:
            raise StudyError("axes", "axes: a study needs at least one axis (name = values)")
        made = tuple(a if isinstance(a, Axis) else Axis.make(n, a) for n, a in axes.items())
        if isinstance(outputs, str):
            outputs = [outputs]
        outputs = tuple(outputs or ())
        if not outputs or not all(isinstance(o, str) and o.strip() for o in outputs):
            raise StudyError("outputs", "outputs: a study needs at least one output (a results key or agg(column))")
        if len(set(outputs)) != len(outputs):
            raise StudyError("outputs", "outputs: an output is listed twice")
        parameters = dict(parameters or {})
        for a in made:
            if a.name in parameters:
                raise StudyError(f"axes.{a.name}", f"axes.{a.name} is also a fixed parameter: give it in one place")
        for key in ("output", "json", "config"):
            if key in parameters or any(a.name == key for a in made):
                raise StudyError(f"parameters.{key}", f"parameters.{key}: not a study parameter (the study writes "
                                                      f"its own store)")
        study = Study(computation, made, outputs, parameters, name)
        study._check_names()
        return study

    @staticmethod
    def from_toml(path) -> "Study":
        """A study file (docs/study.md):

            name = "..."
            computation = "tapping.orbit"
            outputs = ["max(amplitude | stable)", ...]
            [parameters]   # fixed, TOML keys of the command
            [axes]         # name = [values] or { start, stop, points }
        """
        path = Path(path)
        doc = read_toml(path)
        allowed = {"name", "computation", "outputs", "parameters", "axes", "run"}
        unknown = sorted(set(doc) - allowed)
        if unknown:
            raise StudyError(unknown[0], f"{path}: unknown field '{unknown[0]}' (allowed: {', '.join(sorted(allowed))})")
        for required in ("computation", "axes", "outputs"):
            if required not in doc:
                raise StudyError(required, f"{path}: '{required}' is required")
        return Study.make(doc["computation"], doc["axes"], doc["outputs"], doc.get("parameters", {}),
                          doc.get("name", path.stem))

    # ---- derived -------------------------------------------------------------------------------------------------
    @property
    def command(self) -> str:
        return COMPUTATIONS[self.computation]

    @property
    def shape(self) -> tuple:
        return tuple(len(a.values) for a in self.axes)

    @property
    def size(self) -> int:
        return math.prod(self.shape)  # exact (np.prod would wrap around beyond 2^63)

    def definition(self) -> dict:
        """The study as plain data (what the fingerprint covers)."""
        return {"computation": self.computation, "parameters": self.parameters,
                "axes": [[a.name, list(a.values)] for a in self.axes], "outputs": list(self.outputs)}

    def fingerprint(self) -> str:
        text = json.dumps(self.definition(), sort_keys=True, allow_nan=False)
        return hashlib.sha256(text.encode()).hexdigest()[:32]

    def _check_names(self) -> None:
        params = parameters_of(self.command)
        for a in self.axes:
            p = params.get(a.name)
            if p is None:
                raise StudyError(f"axes.{a.name}", f"axes.{a.name}: unknown parameter '{a.name}' of afmkit "
                                                   f"{self.command} (numeric parameters: "
                                                   f"{', '.join(k for k, q in params.items() if q['kind'] in ('real', 'integer'))})")
            if p["kind"] not in ("real", "integer"):
                raise StudyError(f"axes.{a.name}", f"axes.{a.name}: '{a.name}' is a {p['kind']} parameter; an axis "
                                                   f"must be a real or integer parameter")
            if p["kind"] == "integer" and any(v != int(v) for v in a.values):
                raise StudyError(f"axes.{a.name}", f"axes.{a.name}: '{a.name}' takes integers")
        for key in self.parameters:
            if key not in params:
                raise StudyError(f"parameters.{key}", f"parameters.{key}: unknown parameter '{key}' of afmkit "
                                                      f"{self.command} (allowed: {', '.join(params)})")

    def point(self, index) -> dict:
        """The keyword arguments of the command at grid point `index` (a tuple, one position per axis, as the store's
        arrays are indexed): the fixed parameters and the axes' values there, exactly as the study ran it, so that
        ``afmkit.<command>(**study.point(i))`` (and ``afmkit <command> --config`` of :meth:`point_toml`) reproduces
        that point bit for bit."""
        index = tuple(index) if isinstance(index, (tuple, list)) else (index,)
        if len(index) != len(self.axes):
            raise StudyError("index", f"index {index!r} has {len(index)} position(s): the study has "
                                      f"{len(self.axes)} axes ({', '.join(a.name for a in self.axes)})")
        params = parameters_of(self.command)
        out = dict(self.parameters)
        for a, i in zip(self.axes, index):
            if not isinstance(i, (int, np.integer)) or isinstance(i, bool) or not -len(a.values) <= i < len(a.values):
                raise StudyError("index", f"index {i!r} of axis {a.name} is out of range: must be an integer in "
                                          f"[0, {len(a.values) - 1}]")
            v = a.values[int(i)]
            out[a.name] = int(v) if params[a.name]["kind"] == "integer" else float(v)
        return out

    def point_toml(self, index) -> str:
        """The TOML configuration of grid point `index` for ``afmkit <command> --config FILE`` (numbers written so
        that they read back exactly)."""
        def value(v) -> str:
            if isinstance(v, bool):
                return "true" if v else "false"
            if isinstance(v, (int, np.integer)):
                return str(int(v))
            if isinstance(v, (float, np.floating)):
                f = float(v)
                return "nan" if math.isnan(f) else ("inf" if f > 0 else "-inf") if math.isinf(f) else repr(f)
            if isinstance(v, str):
                return json.dumps(v)  # a basic TOML string: the same escapes as JSON for what keys hold
            if isinstance(v, (list, tuple, np.ndarray)):
                return "[" + ", ".join(value(x) for x in v) + "]"
            raise StudyError("parameters", f"parameter value {v!r} cannot be written to TOML")
        lines = [f"# afmkit {self.command}: point {tuple(int(i) for i in np.atleast_1d(index))} of study "
                 f"'{self.name}'"]
        lines += [f"{k} = {value(v)}" for k, v in self.point(index).items()]
        return "\n".join(lines) + "\n"

    def units(self) -> dict:
        """The unit of every axis (the command's parameter units; "nm (physical) or L (normalised)" resolved by the
        study's `units` parameter)."""
        params = parameters_of(self.command)
        system = self.parameters.get("units", params["units"]["default"] if "units" in params else None)
        out = {}
        for a in self.axes:
            unit = params[a.name]["unit"]
            both = re.fullmatch(r"(.+) \(physical\) or (.+) \(normalised\)", unit)
            out[a.name] = (both.group(1) if system == "physical" else both.group(2)) if both and system else unit
        return out
