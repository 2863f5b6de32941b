"""The afmkit report: every figure of both papers and the figures beyond them, computed with afmkit, in one HTML
page with captions and a table of key numbers (``afmkit report``, or ``python3 -m afmkit.report``).

:func:`build` does the work (bad input raises :class:`ReportError`, a ValueError; a figure that fails
:class:`ReportFailure`, a RuntimeError); figure modules are listed in :data:`FIGURE_MODULES`.
"""
from .build import FIGURE_MODULES, ReportError, ReportFailure, build, figure_ids

__all__ = ["build", "figure_ids", "FIGURE_MODULES", "ReportError", "ReportFailure"]
