"""The commands of the ``afmkit`` program as Python functions.

Each function takes keyword arguments named as the command's TOML keys (``build/bin/afmkit <command> --help``,
docs/commands.md), validated by the same code with the same messages, and returns a :class:`Result`.
"""
from __future__ import annotations

import inspect
import textwrap

import numpy as np

from . import _afmkit


class _Summary(dict):
    """The summary results of a run (the command's ``--json`` document without the table): a dict, whose keys are
    also attributes (``r.results.folds``; nested documents likewise: ``r.results.box.real_min``)."""

    def __getattr__(self, name):
        try:
            return _summary(self[name])
        except KeyError:
            raise AttributeError(f"no summary result '{name}' (results: {', '.join(self)})") from None

    def __dir__(self):
        return list(super().__dir__()) + [k for k in self if k.isidentifier()]


def _summary(value):
    if isinstance(value, dict) and not isinstance(value, _Summary):
        return _Summary(value)
    if isinstance(value, list):
        return [_summary(v) for v in value]
    return value


# Tables along one independent variable: its column is the dimension (when its values are distinct).
_INDEX = {"control tf": "frequency", "control simulate": "t", "impact": "t", "tapping fm": "separation"}


def _needs(module: str, method: str):
    try:
        return __import__(module)
    except ImportError:
        raise ImportError(f"afmkit.Result.{method}() needs {module} (Debian: apt install python3-{module}; or pip "
                          f"install {module})") from None


class Result(dict):
    """What one command computed: a read-only mapping of its table's columns (name -> NumPy array), with the
    columns' units and meanings and the summary results.

    ``r["amplitude"]`` or ``r.amplitude`` is a column (float64; bool for flags such as ``stable``; str for labels);
    ``dict(r)``, ``pd.DataFrame(r)`` and ``for name in r`` work as for a dict of columns; ``len(r)`` is the number
    of rows (as a DataFrame's), ``r.columns`` the column names in order. ``r.units["amplitude"]`` is a column's
    unit, ``r.meaning["amplitude"]`` what it holds; ``r.results`` the summary document (the command's ``--json``
    output without the table; keys also as attributes: ``r.results.folds``); ``r.params`` the parameters as run
    (``f(**r.params)`` repeats the run). ``r.to_pandas()`` and ``r.to_xarray()`` give the table with its units;
    ``r.plot()`` draws the common view of the result (Matplotlib).
    """

    def __init__(self, command: str, raw: dict):
        # A copy or a pickle (__reduce__) comes here; a command's run makes its Result in the module (_afmkit.run
        # with result_type=Result), with the same attributes.
        super().__init__(raw["table"])
        self.command = command
        # the summary, or (from a command that makes it where it is read) its maker: see `results`
        self._results = raw["results"]
        self._params = raw["params"]
        self.columns: list[str] = [c[0] for c in raw["columns"]]
        self.units: dict[str, str] = {c[0]: c[1] for c in raw["columns"]}
        self.meaning: dict[str, str] = {c[0]: c[2] for c in raw["columns"]}
        #: The grid the command declares its rows to be (its sidecar's "grid": dims, columns, shape, coords), or
        #: None: to_xarray() shapes the table on it.
        self.grid: dict | None = raw.get("grid")

    @property
    def params(self) -> dict:
        """The parameters as run (computed defaults filled in, only the keys of the unit system and law in use):
        ``f(**r.params)`` repeats the run. Made when first read (a run hands over its record unconverted)."""
        params = self.__dict__["_params"]
        if not isinstance(params, dict):  # the record's capsule: the dict made now, once
            params = self.__dict__["_params"] = _afmkit.made_params(params)
        return params

    @property
    def results(self) -> _Summary:
        """The summary document (the command's ``--json`` output without the table; keys also as attributes:
        ``r.results.folds``). Made when first read: a short command's summary of hundreds of values (``tapping
        orbit``'s search report) costs a noticeable part of the call, which a caller reading only the columns does
        not pay."""
        results = self.__dict__["_results"]
        if not isinstance(results, dict):  # the maker (a capsule): the summary made now, once
            results = self.__dict__["_results"] = _afmkit.made_summary(results)
        if not isinstance(results, _Summary):
            results = self.__dict__["_results"] = _summary(results)
        return results

    # ---- the mapping (read-only)
    @property
    def table(self) -> dict:
        """The columns as a plain dict (name -> array)."""
        return dict(self)

    def __getitem__(self, column: str) -> np.ndarray:
        try:
            return super().__getitem__(column)
        except KeyError:
            raise KeyError(f"{self.command}: no column '{column}' (columns: {', '.join(self.columns)})") from None

    def get(self, column, default=None):
        return super().get(column, default)

    def __len__(self) -> int:
        """The number of rows."""
        return len(next(iter(self.values()))) if super().__len__() else 0

    def _read_only(self, *args, **kwargs):
        raise TypeError(f"afmkit.Result is read-only: copy it first (dict(r), r.to_pandas())")

    __setitem__ = __delitem__ = __ior__ = _read_only
    clear = pop = popitem = setdefault = update = _read_only

    def __reduce__(self):  # copy, pickle (Dask, multiprocessing)
        raw = {"results": self.results, "params": self.params, "table": dict(self), "grid": self.grid,
               "columns": [(c, self.units[c], self.meaning[c]) for c in self.columns]}
        return (Result, (self.command, raw))

    def __getattr__(self, name: str):
        # called only when normal lookup fails: columns whose names are not attributes of the object
        if not name.startswith("_") and name in self.keys():
            return self[name]
        raise AttributeError(f"afmkit.Result of {self.__dict__.get('command', '?')} has no attribute or column "
                             f"'{name}' (columns: {', '.join(self.__dict__.get('columns', []))})")

    def __dir__(self):
        return list(super().__dir__()) + [c for c in self.keys() if c.isidentifier()]

    def __eq__(self, other):
        return self is other

    __hash__ = object.__hash__

    # ---- views
    def __repr__(self) -> str:
        cols = ", ".join(f"{c} [{self.units[c]}]" for c in self.columns)
        return f"<afmkit.Result of {self.command}: {len(self)} rows; columns: {cols or 'none'}>"

    def _repr_html_(self, max_rows: int = 10) -> str:
        from html import escape
        n = len(self)
        half = max_rows // 2
        shown = list(range(n)) if n <= max_rows else [*range(half), -1, *range(n - half, n)]
        head = "".join(f'<th title="{escape(self.meaning[c])}">{escape(c)}<br><small>{escape(self.units[c])}</small>'
                       f"</th>" for c in self.columns)
        body = []
        for i in shown:
            if i < 0:
                body.append(f'<tr><td colspan="{len(self.columns)}">… {n - 2 * half} more rows …</td></tr>')
                continue
            cells = "".join(f"<td>{escape(_cell(self[c][i]))}</td>" for c in self.columns)
            body.append(f"<tr>{cells}</tr>")
        summary = "".join(f"<tr><th>{escape(str(k))}</th><td>{escape(_short(v))}</td></tr>"
                          for k, v in self.results.items())
        return (f"<div><b>afmkit.Result</b> of <code>{escape(self.command)}</code>: {n} rows, "
                f"{len(self.columns)} columns<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody>"
                f"</table><details><summary>summary results</summary><table>{summary}</table></details></div>")

    # ---- other libraries
    def plot(self, ax=None, **kwargs):
        """The common view of this command's result, drawn with Matplotlib; returns the Axes (an array of Axes for
        a view with several panels).

        ``tapping sweep``: amplitude and phase against separation per direction, unstable points as open circles,
        jumps as dashed arrows; ``tapping fm``: frequency shift and drive against separation (``x="min_gap"``);
        ``tapping hb``: amplitude and phase per branch, folds as diamonds; ``control chart``: the spectral
        abscissa (its zero contour: the stability boundary) or delay margin on the grid, one panel per delay
        (``delay=``: one of them; ``quantity=``); ``control tf``: Bode plot; ``control simulate``, ``impact``:
        signals against time; ``scan``: an image (``channel="topography"|"deflection"|"truth"``).
        ``ax``: an Axes, or a sequence of Axes (one per panel, in that order; fewer Axes: the first panels);
        None: a new figure. ``phase="lag"|"lead"`` (None: as the command reports it: lag for tapping, the
        response's argument, a lead, for tf) and ``degrees`` choose how a phase is drawn. Axis labels carry the
        columns' units. Other commands raise NotImplementedError naming the commands with a view."""
        from . import _plots
        return _plots.plot(self, ax, **kwargs)

    def to_pandas(self):
        """The table as a pandas DataFrame; ``df.attrs``: ``units`` and ``meaning`` (column -> text), ``command``,
        ``results`` (the summary) and ``params``."""
        pd = _needs("pandas", "to_pandas")
        df = pd.DataFrame({c: self[c] for c in self.columns})
        df.attrs.update(command=self.command, units=dict(self.units), meaning=dict(self.meaning),
                        results=self.results, params=dict(self.params))
        return df

    def to_xarray(self):
        """The table as an xarray Dataset: on the grid's dimensions when the rows are a grid (``control chart``:
        delay x beta x alpha, or the chart's own axes; ``control tune``: its coarse grid), else along the
        independent variable (``control tf``: frequency; ``simulate``, ``impact``: t; ``tapping fm``: separation) or
        one dimension ``row``.
        Every variable and coordinate has ``units`` and ``long_name`` attributes; the Dataset's attributes hold the
        command, the summary results (as JSON text) and the parameters (as JSON text)."""
        xr = _needs("xarray", "to_xarray")
        import json

        def attrs(c):
            return {"units": self.units[c], "long_name": self.meaning[c]}

        grid = self.grid
        if grid is not None and len(self) == int(np.prod(grid["shape"], dtype=np.int64)):
            # the rows are the declared grid in row-major order (the command checks it): reshaped, not searched
            dims, shape = list(grid["dims"]), tuple(grid["shape"])
            axes = set(grid["columns"])
            data_vars = {c: (dims, self[c].reshape(shape), attrs(c)) for c in self.columns if c not in axes}
            coord_vars = {d: (d, np.asarray(grid["coords"][d], dtype=float), attrs(a))
                          for d, a in zip(dims, grid["columns"])}
        else:
            dim = _INDEX.get(self.command)
            if dim not in self.keys() or len(np.unique(self[dim])) != len(self):
                dim = "row"
            data_vars = {c: (dim, self[c], attrs(c)) for c in self.columns if c != dim}
            coord_vars = {dim: (dim, self[dim], attrs(dim))} if dim != "row" else {"row": ("row", np.arange(len(self)))}
        ds = xr.Dataset(data_vars, coords=coord_vars)
        if grid is not None:  # coordinates in increasing order (a chart's delays are in the order given)
            unsorted = [d for d in ds.dims if d in coord_vars and not ds.indexes[d].is_monotonic_increasing]
            if unsorted:
                ds = ds.sortby(unsorted)
        ds.attrs.update(command=self.command, results=json.dumps(self.results, default=str),
                        params=json.dumps(self.params, default=str))
        return ds


def _cell(x) -> str:
    if isinstance(x, (float, np.floating)):
        return f"{x:.6g}"
    return str(x)


def _short(v) -> str:
    text = str(v)
    return text if len(text) <= 120 else text[:117] + "…"


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
    lines += ["", "config: a TOML file, or a run's JSON sidecar, read first (as --config); keyword arguments",
              "override it.",
              "Returns an afmkit.Result: a read-only mapping of the table's columns (NumPy arrays; flags bool) with",
              "units, the summary results (r.results), the parameters as run (r.params), to_pandas(), to_xarray(),",
              "plot() (the common view of the command's result: docs/python.md#plots)."]
    return "\n".join(lines)


def _signature_default(p: dict):
    """The default a signature shows: the declared value when it is the value used, else None ("not given") — for
    a key that follows another (departure_hamaker: the value of hamaker) and a default the command chooses from
    other values (docstring: what it is; r.params records the value used)."""
    return None if p["follows"] or p["default_text"] else p["default"]


# ---- the registry: the program's commands (C++, _afmkit.commands()) and where each is in Python

#: Commands of the program that are not the function afmkit.<path with dots> (afmkit.tapping.orbit for
#: `tapping orbit`): the name of their Python counterpart in the package. `report` and `study run` are Python
#: programs the command line starts; `tapping grid` writes a store, which a study of tapping.orbit does from Python.
_ELSEWHERE = {
    "spectroscopy prepare": "spectroscopy.prepare_file",  # a wrapper returning a PreparedCurve (SI units)
    "spectroscopy fit": "spectroscopy_fit.run",           # afmkit.spectroscopy.fit: the same fit on arrays
    "report": "report.build",
    "study run": "study.run",
    "tapping grid": "study.run",
}


def commands() -> list:
    """Every leaf command of the afmkit program, in registration order (the one list of commands: the C++
    program's command tree): dicts with path, help, runnable (a command function runs it) and params."""
    global _COMMANDS
    if _COMMANDS is None:
        _COMMANDS = _afmkit.commands(program=True)
    return _COMMANDS


_COMMANDS = None


def python_name(path: str) -> str:
    """Where command ``path`` is in the package, relative to ``afmkit`` ("tapping.orbit", "report.build")."""
    return _ELSEWHERE.get(path, path.replace(" ", "."))


def command_functions(module: str) -> dict:
    """The command functions of ``afmkit.<module>`` ("" for afmkit itself), generated from the registry: every
    command the module's functions run whose Python name is ``<module>.<name>``, as {name: function}."""
    out = {}
    for spec in commands():
        parent, _, name = python_name(spec["path"]).rpartition(".")
        if spec["runnable"] and parent == module:
            out[name] = make_command(spec["path"])
    return out


def make_command(path: str):
    """The Python function of command ``path`` ("tapping orbit"); its ``__afmkit_command__`` is the path."""
    spec = next((s for s in commands() if s["path"] == path and s["runnable"]), None)
    if spec is None:
        raise ValueError(f"no afmkit command '{path}' that a function runs (commands: "
                         f"{', '.join(s['path'] for s in commands() if s['runnable'])})")
    keys = {p["key"] for p in spec["params"]}

    def command(**kwargs) -> Result:
        law = kwargs.get("law")
        if law is not None and not isinstance(law, str) and "law" in keys:  # an afmkit.laws object: its keywords
            from . import laws  # here (afmkit.laws imports this module), and only for a law object (it costs)
            kwargs = laws.expand(path, kwargs, keys)
        # None: not given (the default, which for some keys is another key's value or computed: _signature_default)
        return _afmkit.run(path, kwargs, Result)

    name = path.split()[-1]
    command.__name__ = name
    command.__qualname__ = name
    command.__module__ = "afmkit." + path.split()[0] if " " in path else "afmkit"
    command.__doc__ = _docstring(spec)
    command.__afmkit_command__ = path
    params = [inspect.Parameter("config", inspect.Parameter.KEYWORD_ONLY, default=None, annotation=str)]
    params += [inspect.Parameter(p["key"], inspect.Parameter.KEYWORD_ONLY, default=_signature_default(p),
                                 annotation=_KINDS[p["kind"]]) for p in spec["params"]]
    command.__signature__ = inspect.Signature(params, return_annotation=Result)
    return command


def _spec(path: str) -> dict:
    spec = next((s for s in commands() if s["path"] == path), None)
    if spec is None:
        raise ValueError(f"no afmkit command '{path}' (commands: {', '.join(s['path'] for s in commands())})")
    return spec


def declared_defaults(path: str) -> dict:
    """The default of every key of command ``path`` as the program declares it; None for a key whose default is
    computed elsewhere (its help says what it is: "one per core", "the file's [run] store, else ...")."""
    return {p["key"]: None if p["default_text"] else p["default"] for p in _spec(path)["params"]}


def argument_parser(path: str, prog: str | None = None, description: str | None = None, *,
                    given_only: bool = False, add_help: bool = True):
    """An argparse parser of the options of command ``path`` as the program declares them (one declaration: the
    C++ ParamSet, as ``afmkit <path> --help`` shows them): ``--output-dir`` for key ``output_dir``, the kind's
    type and choices, the help with unit, range and default; the positional key as a positional argument. A key
    not given parses to its declared default (declared_defaults), or to None (a flag: False) with ``given_only``
    (when something else comes between the options and the defaults: a study file's [run] table)."""
    import argparse

    spec = _spec(path)
    parser = argparse.ArgumentParser(prog=prog or f"afmkit {path}", description=description or spec["help"],
                                     add_help=add_help)
    types = {"real": float, "integer": int, "text": str, "file": str}
    for p in spec["params"]:
        default = None if p["default_text"] or given_only else p["default"]
        facts = [f"unit {p['unit']}"] if p["unit"] and p["unit"] != "count" else []
        facts += [p["allowed"]] if p["allowed"] else []
        if not p["positional"]:
            facts.append(f"default: {p['default_text']}" if p["default_text"] else f"default: {p['default']!r}")
        help_text = (f"{p['help']} ({'; '.join(facts)})" if facts else p["help"]).replace("%", "%%")
        flag = "--" + p["key"].replace("_", "-")
        if p["kind"] == "flag":
            parser.add_argument(flag, dest=p["key"], action="store_true",
                                default=False if given_only else bool(p["default"]), help=help_text)
        elif p["kind"] == "reals":
            parser.add_argument(flag, dest=p["key"], type=lambda t: [float(x) for x in t.split(",")],
                                default=default, help=help_text)
        elif p["positional"]:
            parser.add_argument(p["key"], help=help_text)
        else:
            parser.add_argument(flag, dest=p["key"], type=types[p["kind"]], default=default,
                                choices=p["choices"] or None, help=help_text)
    return parser
