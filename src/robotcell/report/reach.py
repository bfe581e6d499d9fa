"""The page of a reachability map (:func:`robotcell.studies.reach.reach_map`): the targets seen
from above and from the side, coloured by score (unreachable ones as red crosses), and the track
position and table angle along the targets, in one self-contained HTML file (the figure embedded
as a PNG data URI; matplotlib imported only when it is drawn); and the map written as CSV and page
in one call, as ``robotcell reach`` does.
"""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

import numpy as np
from numpy.typing import ArrayLike

from robotcell.cell import Cell
from robotcell.io.fileio import atomic_write
from robotcell.io.tables import write_columns
from robotcell.studies.reach import ReachMap, reach_columns, reach_map
from robotcell.view.pyplot import pyplot

__all__ = ["reach_html", "write_reach_map"]


def reach_html(rm: ReachMap, points: ArrayLike, title: str = "Reachability map",
               frame: str = "world") -> str:
    """A self-contained HTML page of a reachability map.

    Parameters
    ----------
    rm : ReachMap
    points : array_like, shape (N, 3)
        Target positions in their frame (m); drawn in millimetres.
    title : str
    frame : str
        Name of the targets' frame, for the axis labels.

    Returns
    -------
    str
        HTML with the figure embedded as a PNG data URI: the targets seen from above and from
        the side, coloured by score (unreachable ones as red crosses), and the track position
        (mm) and table angle (deg) along the targets.
    """
    plt = pyplot()
    p = np.asarray(points, dtype=float).reshape(-1, 3) * 1e3
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    ok = rm.reachable
    for ax, (i, j) in zip(axes[:2], ((0, 1), (0, 2))):
        sc = ax.scatter(p[ok, i], p[ok, j], c=rm.score[ok], cmap="viridis", vmin=0, vmax=1, s=14)
        ax.scatter(p[~ok, i], p[~ok, j], marker="x", color="red", s=18, label="unreachable")
        ax.set_xlabel(f"{'xyz'[i]} in {frame} (mm)")
        ax.set_ylabel(f"{'xyz'[j]} in {frame} (mm)")
        ax.set_aspect("equal", adjustable="datalim")
        if np.any(~ok):
            ax.legend(loc="best")
    axes[0].set_title("from above")
    axes[1].set_title("from the side")
    fig.colorbar(sc, ax=axes[1], label="score (1: clear of limits and singularities)")
    idx = np.arange(ok.size) + 1
    ax = axes[2]
    ax.plot(idx, rm.track * 1e3, color="tab:blue", marker=".", label="track (mm)")
    ax.set_xlabel("target")
    ax.set_ylabel("track position (mm)", color="tab:blue")
    ax2 = ax.twinx()
    ax2.plot(idx, np.degrees(rm.table), marker=".", color="tab:orange" if rm.table.ndim == 1
             else None)
    ax2.set_ylabel("table / positioner axes (deg)", color="tab:orange")
    ax.set_title("external axes along the targets")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    png = base64.b64encode(buf.getvalue()).decode("ascii")
    n, n_ok = ok.size, int(np.count_nonzero(ok))
    mean = float(np.mean(rm.score)) if n else 0.0
    margin = np.degrees(np.nanmin(rm.limit_margin)) if n_ok else float("nan")
    summary = (f"{n_ok} of {n} targets reachable ({100.0 * n_ok / max(n, 1):.1f} %); mean score "
               f"{mean:.3f}; smallest distance to a joint limit {margin:.1f} deg")
    return ("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(title)}</title></head><body>\n"
            f"<h1>{html.escape(title)}</h1>\n<p>{html.escape(summary)}</p>\n"
            f"<img alt=\"reachability map\" src=\"data:image/png;base64,{png}\">\n"
            "</body></html>\n")


def write_reach_map(cell: Cell, T: ArrayLike, output: str | Path | TextIO,
                    html_path: str | Path | None = None, title: str = "Reachability map",
                    frame: str = "world", tool: str | ArrayLike | None = None,
                    table: ArrayLike | None = 0.0, track: ArrayLike | None = None,
                    progress: Callable[[int, int], None] | None = None) -> ReachMap:
    """:func:`reach_map` of the targets, written as CSV (:func:`reach_columns`) and HTML.

    Parameters
    ----------
    cell : Cell
    T : array_like, shape (N, 4, 4)
        Targets in ``frame`` (m).
    output : str or Path or text stream
        The CSV (written atomically to a path).
    html_path : str or Path, optional
        The page of :func:`reach_html`, atomically.
    title : str
        Its title.
    frame, tool, table, track, progress
        As for :func:`reach_map`.

    Returns
    -------
    ReachMap
    """
    arr = np.asarray(T, dtype=float).reshape(-1, 4, 4)
    rm = reach_map(cell, arr, frame=frame, tool=tool, table=table, track=track,
                   progress=progress)
    write_columns(output, reach_columns(rm, cell), 6)
    if html_path is not None:
        atomic_write(html_path, reach_html(rm, arr[:, :3, 3], title=title, frame=frame))
    return rm
