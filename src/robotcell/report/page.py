"""The common parts of robotcell's HTML pages: style, the figures-loaded mark, PNG figures,
tables, number formatting and the slot of the 3D scene.

Every report (:mod:`robotcell.report.calibration`, :mod:`robotcell.report.identification`,
:mod:`robotcell.report.accuracy`) is one self-contained page made of these parts: its figures are
PNG ``data:`` URIs and its 3D scene a plotly figure with plotly.js inlined. matplotlib is imported
only when a figure is drawn.
"""

from __future__ import annotations

import base64
import html
import io
import math
from typing import Any

from robotcell.view.plot import MAX_PAGE_BYTES, embed_within
from robotcell.view.pyplot import pyplot
from robotcell.view.scene import Scene

__all__ = ["CSS", "SCENE_SLOT", "SCRIPT", "fmt", "png", "scene_figure", "table"]


def png(fig: Any) -> str:
    """A matplotlib figure as a ``data:image/png;base64,...`` URI; the figure is closed."""
    plt = pyplot()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


#: Where the 3D scene goes in a page, until the room it has is known.
SCENE_SLOT = "<!-- the 3D scene -->"


def scene_figure(scenes: list[Scene], room: int, what: str) -> str:
    """An interactive 3D scene as a ``<figure>`` of a report, with its caption, in at most
    ``room`` bytes: the first of ``scenes`` (the full one, then lighter ones) that fits
    (:func:`robotcell.view.plot.embed_within`); a paragraph that says it is left out when none
    does."""
    fragment, drawn = embed_within(scenes, room - 2_000, height="620px")
    if drawn is None:
        return (f"<p>The 3D scene of {what} is left out: it would make this page larger than "
                f"{MAX_PAGE_BYTES / 1e6:g} MB.</p>")
    return (f'<figure class="view">{fragment}<figcaption>{html.escape(what[0].upper() + what[1:])} '
            f"in the {html.escape(drawn.frame)} frame (mm), on equal axes: drag to turn, scroll "
            "to zoom, hover for names and values, click a legend entry to hide or show it; "
            f"{html.escape('; '.join(drawn.notes))}.</figcaption></figure>")


def fmt(v: Any) -> str:
    """A value of a result as the text of a table cell: floats to 4 decimals (significant
    digits for tiny or huge ones), lists and matrices as rows, ``None`` as "not determined"."""
    if isinstance(v, float):
        if not math.isfinite(v):
            return "n/a"
        # Four decimals for everyday magnitudes; significant digits for tiny or huge ones (a
        # covariance in rad^2, a sigma of 1e-7), which four decimals would show as 0.0000.
        return f"{v:.4f}" if v == 0 or 1e-3 <= abs(v) < 1e7 else f"{v:.4g}"
    if isinstance(v, list):
        if v and isinstance(v[0], list):
            return "<br>".join(fmt(row) for row in v)
        return "[" + ", ".join(fmt(x) for x in v) + "]"
    if v is None:
        return "not determined"
    return html.escape(str(v))


def table(head: list[str], rows: list[list[object]]) -> str:
    """An HTML table: a header row ``head`` and one row per entry of ``rows``, cells by
    :func:`fmt`."""
    th = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    body = "".join("<tr>" + "".join(f"<td>{fmt(v)}</td>" for v in r) + "</tr>" for r in rows)
    return f"<table><tr>{th}</tr>{body}</table>"


#: The style of every page.
CSS = """
body { font-family: sans-serif; max-width: 960px; margin: 2em auto; color: #222; }
.verdict { padding: 0.8em 1em; border-radius: 6px; font-size: 1.2em; }
.good { background: #d8f3dc; } .check { background: #fff3bf; } .poor { background: #ffd6d6; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; }
td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
img { max-width: 100%; border: 1px solid #ddd; margin: 0.5em 0; }
"""

# Marks the page once every figure has loaded with a size, so a browser test can read it.
SCRIPT = """
window.addEventListener('load', function () {
  var imgs = Array.prototype.slice.call(document.images);
  var ok = imgs.length > 0 && imgs.every(function (i) { return i.complete && i.naturalWidth > 0; });
  document.body.setAttribute('data-figures', ok ? 'loaded' : 'missing');
});
"""
