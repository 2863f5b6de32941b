"""Figures of the report: every figure of both papers, reproduced with afmkit, and the figures beyond them.

Each module here (``seed000``, ``seed003``, ``scan``) lists its figure functions in ``FIGURES``, in report order;
a figure function takes the folder to write its PNG into and returns a :class:`Figure`.
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class Figure:
    """One figure of the report: its PNG (in the report folder), caption and key numbers."""

    id: str  #: stable identifier, also the anchor and the file stem ("seed000-fig3")
    title: str  #: one line, naming the paper and figure it reproduces (or "Beyond the papers: …")
    caption: str  #: what it shows, with which parameters (values and units), what to notice
    filename: str  #: PNG file name relative to the report folder
    numbers: list = field(default_factory=list)  #: key numbers: (quantity, value with unit, where it comes from)
    seconds: float = 0.0  #: time taken to compute and draw it (filled in by the report)


def figure(figure_id: str):
    """Marks a figure function with the id of the :class:`Figure` it returns (selectable before it runs)."""

    def mark(fn):
        fn.figure_id = figure_id
        return fn

    return mark
