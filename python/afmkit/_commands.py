"""The commands of the ``afmkit`` program as Python functions.

Each function takes keyword arguments named as the command's TOML keys (``build/bin/afmkit <command> --help``,
docs/commands.md), validated by the same code with the same messages, and returns a :class:`Result`.
"""
from __future__ import annotations

import inspect
import textwrap

import numpy as np

from . import _afmkit


class Result:
    """What one command computed: its table as NumPy arrays, the columns' units and meanings, the summary results.

    ``r["amplitude"]`` is a column (float64, or str for label columns); ``r.units["amplitude"]`` its unit;
    ``r.results`` the summary document (the command's ``--json`` output without the table); ``r.params`` the
    parameters as run.
    """

    def __init__(self, command: str, raw: dict):
        self.command = command
        self.results: dict = raw["results"]
        self.params: dict = raw["params"]
        self.columns: list[str] = [c[0] for c in raw["columns"]]
        self.units: dict[str, str] = {c[0]: c[1] for c in raw["columns"]}
        self.meaning: dict[str, str] = {c[0]: c[2] for c in raw["columns"]}
        self.table: dict[str, np.ndarray] = raw["table"]

    def __getitem__(self, column: str) -> np.ndarray:
        try:
            return self.table[column]
        except KeyError:
            raise KeyError(f"{self.command}: no column '{column}' (columns: {', '.join(self.columns)})") from None

    def __contains__(self, column: str) -> bool:
        return column in self.table

    def __len__(self) -> int:
        return len(next(iter(self.table.values()))) if self.table else 0

    def __repr__(self) -> str:
        cols = ", ".join(f"{c} [{self.units[c]}]" for c in self.columns)
        return f"<afmkit.Result of {self.command}: {len(self)} rows; columns: {cols or 'none'}>"


_KINDS = {"real": float, "integer": int, "text": str, "file": str, "flag": bool, "reals": list}


def _followed(p: dict, keys) -> str:
    """The key whose value `p` takes when not given ("" if none): declared (follows) or chosen by the command and
    said so in --help ("= plant_rate")."""
    text = p["default_text"]
    return p["follows"] or (text[2:] if text.startswith("= ") and text[2:] in keys else "")


def _docstring(spec: dict) -> str:
    keys = {p["key"] for p in spec["params"]}
    lines = [spec["help"], "", "Keyword arguments (the TOML keys of `afmkit " + spec["path"] + "`):", ""]
    group = None
    for p in spec["params"]:
        if p["group"] != group:
            group = p["group"]
            lines.append(f"{group}:")
        facts = [p["kind"]]
        if p["unit"]:
            facts.append(f"unit {p['unit']}")
        if _followed(p, keys):
            facts.append(f"default None: defaults to {_followed(p, keys)} (its value is used and recorded in "
                         f"r.params)")
        elif p["default_text"]:
            facts.append(f"default None: {p['default_text']} (the value used is recorded in r.params)")
        else:
            facts.append(f"default {p['default']!r}")
        if p["allowed"]:
            facts.append(p["allowed"])
        lines.append(f"  {p['key']} ({'; '.join(facts)})")
        lines.extend(textwrap.wrap(p["help"], 100, initial_indent="      ", subsequent_indent="      "))
    lines += ["", "config: a TOML file read first (as --config); keyword arguments override it.",
              "Returns an afmkit.Result (table columns as NumPy arrays, units, summary results)."]
    return "\n".join(lines)


def _signature_default(p: dict):
    """The default a signature shows: the declared value when it is the value used, else None ("not given") — for
    a key that follows another (departure_hamaker: the value of hamaker) and a default the command chooses from
    other values (docstring: what it is; r.params records the value used)."""
    return None if p["follows"] or p["default_text"] else p["default"]


def make_command(path: str):
    """The Python function of command ``path`` ("tapping orbit")."""
    spec = next(s for s in _afmkit.commands() if s["path"] == path)

    def command(**kwargs) -> Result:
        # None: not given (the default, which for some keys is another key's value or computed: _signature_default)
        return Result(path, _afmkit.run(path, {k: v for k, v in kwargs.items() if v is not None}))

    name = path.split()[-1]
    command.__name__ = name
    command.__qualname__ = name
    command.__module__ = "afmkit." + path.split()[0] if " " in path else "afmkit"
    command.__doc__ = _docstring(spec)
    params = [inspect.Parameter("config", inspect.Parameter.KEYWORD_ONLY, default=None, annotation=str)]
    params += [inspect.Parameter(p["key"], inspect.Parameter.KEYWORD_ONLY, default=_signature_default(p),
                                 annotation=_KINDS[p["kind"]]) for p in spec["params"]]
    command.__signature__ = inspect.Signature(params, return_annotation=Result)
    return command
