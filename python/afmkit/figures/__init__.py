"""Figures of the report: every figure of both papers, reproduced with afmkit, and the figures beyond them.

Each module here (``seed000``, ``seed003``, ``scan``) lists its figure functions in ``FIGURES``, in report order.
A figure function takes its parameters as keywords (model parameters, ranges, resolutions; the defaults are the
report's) and returns a :class:`matplotlib.figure.Figure`; given ``out`` (a folder, or a file name ending in
``.png``) it also writes the PNG. The figure's caption and key numbers, as the report prints them, are in its
``report`` attribute (a :class:`ReportEntry`)::

    from afmkit.figures import seed000
    fig = seed000.fig3(free_amplitude=10, stiffness_ratios=[1, 100], q_range=(0.5, 1.2))  # nothing written
    fig.savefig("fig3.svg"); print(fig.report.caption)

Like ``plt.subplots``, the figure is open in pyplot until the caller closes it (``plt.close(fig)``). A parameter
out of range raises ``ValueError`` naming it (before anything is computed where the figure checks it itself; model
parameters are checked by the afmkit command that uses them, with ``afmkit.InvalidParameter``, also a ValueError).
"""
from __future__ import annotations

import functools
import math
import numbers as _numbers
import os
import pathlib
from dataclasses import dataclass, field

DPI = 110  #: resolution of the PNG files (dots per inch)


@dataclass
class ReportEntry:
    """What the report prints with one figure: its id, title, caption and key numbers, and its PNG file name."""

    id: str  #: stable identifier, also the anchor and the file stem ("seed000-fig3")
    title: str  #: one line, naming the paper and figure it reproduces (or "Beyond the papers: …")
    caption: str  #: what it shows, with which parameters (values and units), what to notice
    filename: str  #: PNG file name (relative to the folder it was written into; "" when nothing was written)
    numbers: list = field(default_factory=list)  #: key numbers: (quantity, value with unit, where it comes from)
    seconds: float = 0.0  #: time taken to compute and draw it (filled in by the report)


def figure(figure_id: str):
    """Marks a figure function with the id of the figure it draws (selectable before it runs); ``out`` is checked
    before anything is computed."""

    def mark(fn):
        @functools.wraps(fn)
        def checked(out=None, **keywords):
            check_out(out)
            return fn(out, **keywords)

        checked.figure_id = figure_id
        return checked

    return mark


def check_out(out) -> None:
    """``out`` must be None (write nothing), a folder or a ``.png`` file name."""
    if out is not None and not isinstance(out, (str, os.PathLike)):
        raise ValueError(f"out = {out!r} is not allowed: must be None, a folder or a .png file name (str or "
                         f"os.PathLike)")


#: zlib level of the PNG files: 3 instead of Pillow's 6 costs ~6 % more bytes and a third less encoding time (the
#: pixels are the same: PNG is lossless; bench/report_speed.py compares them)
PNG_COMPRESS_LEVEL = 3


def save_png(fig, path) -> None:
    """Writes ``fig`` to ``path`` as ``fig.savefig(path, dpi=DPI)`` does, pixel for pixel, in one drawing pass.

    savefig draws a figure with a layout engine (``constrained_layout``) twice: once with drawing disabled to run
    the layout, then again to render; here the figure is rendered once (layout included) by an Agg canvas at DPI
    and its buffer written with the same call savefig ends in (matplotlib.image.imsave: same metadata). The
    figure's dpi and canvas are restored."""
    import matplotlib.image as mpimg
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    old_canvas, old_dpi = fig.canvas, fig.dpi
    canvas = old_canvas if type(old_canvas) is FigureCanvasAgg else FigureCanvasAgg(fig)
    try:
        fig.set_dpi(DPI)
        canvas.draw()
        mpimg.imsave(path, canvas.buffer_rgba(), format="png", origin="upper", dpi=DPI,
                     pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
    finally:
        fig.set_dpi(old_dpi)
        if canvas is not old_canvas:
            fig.set_canvas(old_canvas)


def finish(fig, out, figure_id: str, **entry):
    """Attaches the report entry to ``fig`` (``fig.report``) and writes ``fig`` as PNG when ``out`` is given: into
    the folder ``out`` as ``<figure_id>.png`` (the folder is created), or to ``out`` itself if it ends in ``.png``.
    Returns ``fig``."""
    filename = ""
    if out is not None:
        path = pathlib.Path(out)
        if path.suffix.lower() != ".png":
            path.mkdir(parents=True, exist_ok=True)
            path = path / f"{figure_id}.png"
        save_png(fig, path)
        filename = path.name
    fig.report = ReportEntry(id=figure_id, filename=filename, **entry)
    return fig


# ---------------------------------------------------------------------------------------------------------------
# checks of the keyword parameters (ValueError naming the keyword and the allowed range)

def _finite(x) -> bool:
    return isinstance(x, _numbers.Real) and not isinstance(x, bool) and math.isfinite(x)  # NumPy scalars too


def number(name: str, value, *, low=None, high=None, positive=False) -> float:
    """A finite real number, > 0 if ``positive``, in [low, high] where given."""
    rng = ("must be a finite number" + (" > 0" if positive else "") + (f" >= {low:g}" if low is not None else "")
           + (f" <= {high:g}" if high is not None else ""))
    if (not _finite(value) or (positive and value <= 0) or (low is not None and value < low)
            or (high is not None and value > high)):
        raise ValueError(f"{name} = {value!r} is out of range: {rng}")
    return float(value)


def integer(name: str, value, *, low: int, high: int) -> int:
    """An integer in [low, high]."""
    if not isinstance(value, _numbers.Integral) or isinstance(value, bool) or not low <= value <= high:
        raise ValueError(f"{name} = {value!r} is out of range: must be an integer in [{low}, {high}]")
    return int(value)


def interval(name: str, value) -> tuple:
    """A pair (low, high) of finite numbers with low < high."""
    try:
        lo, hi = value
    except (TypeError, ValueError):
        lo = hi = None
    if not (_finite(lo) and _finite(hi) and lo < hi):
        raise ValueError(f"{name} = {value!r} is not allowed: must be a pair (low, high) of finite numbers with "
                         f"low < high")
    return float(lo), float(hi)


def number_list(name: str, value, *, low=None, high=None, positive=False, longest: int = 64) -> list:
    """A non-empty list (at most ``longest``) of finite numbers, each checked as :func:`number`."""
    try:
        items = list(value)
    except TypeError:
        items = None
    if isinstance(value, (str, bytes)) or not items or len(items) > longest:
        raise ValueError(f"{name} = {value!r} is not allowed: must be a list of 1 to {longest} numbers")
    return [number(f"{name}[{i}]", v, low=low, high=high, positive=positive) for i, v in enumerate(items)]
