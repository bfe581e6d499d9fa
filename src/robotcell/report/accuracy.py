"""HTML report of a filtering: how good the poses or the program will be, point by point.

One self-contained page (``robotcell compensate ... --report FILE.html``, ``robotcell program
compensate ... --report FILE.html``): per point the predicted TCP error without filtering (the
identified arm at the joints the controller computes for the point as written, against it), the
correction, and the 3D RMS of the filtered position's error from the identification's covariance
and model error, as a figure and a table. Figures are PNG ``data:`` URIs
(:mod:`robotcell.report.page`; matplotlib imported only when a report is written).
"""

from __future__ import annotations

import html
import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from robotcell.io.fileio import atomic_write
from robotcell.report.page import CSS, SCRIPT, png, table
from robotcell.view.pyplot import pyplot

if TYPE_CHECKING:
    from robotcell.accuracy.poses import CompensatedPoses
    from robotcell.accuracy.program import CompensatedProgram

__all__ = ["write_accuracy_report", "write_poses_report", "write_program_report"]


def _figure(error_mm: np.ndarray, dpos_mm: np.ndarray, sigma_mm: np.ndarray) -> str:
    """Per point: predicted error without filtering, correction, 3D RMS error after (mm, log)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(9, 3.4))
    k = np.arange(1, len(error_mm) + 1)
    ax.semilogy(k, np.maximum(error_mm, 1e-6), "o", color="tab:red", ms=4,
                label="predicted error without filtering")
    ax.semilogy(k, np.maximum(dpos_mm, 1e-6), "x", color="tab:gray", ms=4, label="correction")
    if np.isfinite(sigma_mm).any():
        ax.semilogy(k, np.maximum(sigma_mm, 1e-6), "s", color="tab:blue", ms=4,
                    label="3D RMS error of the filtered position")
    ax.set_xlabel("point")
    ax.set_ylabel("TCP position [mm]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return png(fig)


def write_accuracy_report(path: str | Path, title: str, names: list[str], error: ArrayLike,
                          dpos: ArrayLike, sigma: ArrayLike) -> Path:
    """Write the page (atomically; nothing else is written).

    Parameters
    ----------
    path : str or Path
        The HTML file.
    title : str
        What was filtered (a file name).
    names : list of str
        Point names.
    error, dpos, sigma : array_like, shape (N,)
        Predicted error without filtering, correction, and the 3D RMS of the error after
        filtering (m; sigma NaN without a covariance).

    Returns
    -------
    Path
    """
    from robotcell.accuracy.filter import sigma_text

    e, d, s = (np.asarray(v, dtype=float) * 1e3 for v in (error, dpos, sigma))
    known = np.isfinite(s).all() and s.size > 0
    rms = float(math.sqrt(np.mean(e**2))) if e.size else 0.0
    head = (f"<p>{len(names)} points. Without filtering the TCP misses by {rms:.3f} mm RMS, "
            f"{e.max(initial=0.0):.3f} mm at most (predicted: the identified arm against the "
            "controller's nominal model). Filtered, it lands within the identification's "
            + (f"uncertainty: 3D RMS error {s.max():.4f} mm at most (the RMS length of the "
               "error the identification's covariance and model error predict, "
               f"{html.escape(sigma_text())}).</p>" if known else
               "uncertainty (the identified model carries no covariance to state it).</p>"))
    rows = [[n, float(a), float(b), float(c) if known else "-"] for n, a, b, c in zip(names, e, d, s)]
    rows_html = table(["point", "error without filtering (mm)", "correction (mm)",
                    "3D RMS error filtered (mm)"], rows)
    name = html.escape(title)
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>robotcell accuracy: {name}</title>
<style>{CSS}</style><script>{SCRIPT}</script></head>
<body>
<h1>Absolute accuracy of {name}</h1>{head}
<figure><img src="{_figure(e, d, s)}" alt="errors per point"></figure>
<h2>Per point</h2>{rows_html}
</body></html>
"""
    out = Path(path)
    atomic_write(out, page)
    return out


def write_poses_report(path: str | Path, poses: str | Path, result: CompensatedPoses) -> Path:
    """Write the page of a filtered poses file (``robotcell compensate --report``).

    Parameters
    ----------
    path : str or Path
        The HTML file.
    poses : str or Path
        The poses file that was filtered (its name titles the page).
    result : CompensatedPoses
        What :func:`robotcell.accuracy.poses.compensate_poses` returned.

    Returns
    -------
    Path
    """
    r = result.result
    names = [f"pose {i + 1}" for i in range(len(result.rows))]
    return write_accuracy_report(path, Path(poses).name, names, r.error, r.dpos, r.sigma)


def write_program_report(path: str | Path, program: str | Path,
                         result: CompensatedProgram) -> Path:
    """Write the page of a filtered program (``robotcell program compensate --report``).

    Parameters
    ----------
    path : str or Path
        The HTML file.
    program : str or Path
        The program file that was filtered (its name titles the page).
    result : CompensatedProgram
        What :func:`robotcell.accuracy.program.compensate_program` returned.

    Returns
    -------
    Path
    """
    pp = result.points
    return write_accuracy_report(path, Path(program).name, [p.name for p in pp],
                                 [p.error for p in pp], [p.dpos for p in pp],
                                 [p.sigma for p in pp])
