"""The report's HTML page (no script, no external resource: it opens offline in any browser)."""
from __future__ import annotations

import datetime
import html

_STYLE = """
body { font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em; color: #222; }
h1 { font-size: 1.6em; } h2 { font-size: 1.25em; margin-top: 2em; border-bottom: 1px solid #ccc; }
figure { margin: 1.5em 0; } figure img { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { font-size: 0.95em; line-height: 1.4; margin-top: 0.4em; }
table { border-collapse: collapse; font-size: 0.92em; } td, th { border: 1px solid #ccc; padding: 0.3em 0.6em; }
th { background: #f3f3f3; text-align: left; } .muted { color: #666; font-size: 0.9em; }
nav li { margin: 0.15em 0; }
"""


def _e(text) -> str:
    return html.escape(str(text))


def render(figures, speed, *, version: str, seconds: float, jobs: int) -> str:
    numbers = [(fig, q, v, src) for fig in figures for (q, v, src) in fig.numbers]
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>afmkit report</title><style>{_STYLE}</style></head><body>",
        "<h1>afmkit report: both papers reproduced, and what afmkit adds</h1>",
        "<p>Tapping-mode AFM and impact dynamics (Materassi, Basso &amp; Genesio 2003, “seed 1”) and first-harmonic "
        "rejection for rotational-scanning AFM (Novičenko &amp; Vaitekonis, “seed 2”). Every curve below was "
        "computed by afmkit when this page was written; captions give the parameters (docs/conventions.md for "
        "signs, phases and units).</p>",
        f'<p class="muted">afmkit {_e(version)}, {len(figures)} figures in {seconds:.1f} s with {jobs} process(es), '
        f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC.</p>",
        "<nav><h2>Contents</h2><ol>",
    ]
    parts += [f'<li><a href="#{_e(f.id)}">{_e(f.title)}</a></li>' for f in figures]
    parts += ['<li><a href="#numbers">Key numbers</a></li>', "</ol></nav>"]
    # the figures first, then the key numbers (each row links back to its figure)
    for f in figures:
        parts += [f'<h2 id="{_e(f.id)}">{_e(f.title)}</h2>', "<figure>",
                  f'<img src="{_e(f.filename)}" alt="{_e(f.title)}">',
                  f'<figcaption>{_e(f.caption)} <span class="muted">({f.seconds:.1f} s)</span></figcaption>',
                  "</figure>"]
    parts += ['<h2 id="numbers">Key numbers</h2>',
              "<table><tr><th>quantity</th><th>value</th><th>how it was obtained</th><th>figure</th></tr>"]
    for fig, q, v, src in numbers:
        parts.append(f'<tr><td>{_e(q)}</td><td>{_e(v)}</td><td>{_e(src)}</td>'
                     f'<td><a href="#{_e(fig.id)}">{_e(fig.id)}</a></td></tr>')
    for q, v, src in speed:
        parts.append(f"<tr><td>{_e(q)}</td><td>{_e(v)}</td><td>{_e(src)}</td><td>speed</td></tr>")
    parts.append("</table>")
    parts.append("</body></html>\n")
    return "\n".join(parts)
