"""HTML report of a filtering: how good the poses or the program will be, point by point.

One self-contained page (``robotcell compensate ... --report FILE.html``, ``robotcell program
compensate ... --report FILE.html``): per point the predicted TCP error without filtering (the
identified arm at the joints the controller computes for the point as written, against it), the
correction, and the 3D RMS of the filtered position's error from the identification's covariance
and model error, as a figure and a table. Figures are PNG ``data:`` URIs (:mod:`robotcell.report.calibration`; matplotlib imported
only when a report is written).
"""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from robotcell.io.fileio import atomic_write
from robotcell.report.calibration import _CSS, _SCRIPT, _png
from robotcell.report.identification import _pyplot, _table

__all__ = ["write_accuracy_report"]


def _figure(error_mm: np.ndarray, dpos_mm: np.ndarray, sigma_mm: np.ndarray) -> str:
    """Per point: predicted error without filtering, correction, 3D RMS error after (mm, log)."""
    plt = _pyplot()
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
    return _png(fig)


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
    e, d, s = (np.asarray(v, dtype=float) * 1e3 for v in (error, dpos, sigma))
    known = np.isfinite(s).all() and s.size > 0
    rms = float(math.sqrt(np.mean(e**2))) if e.size else 0.0
    head = (f"<p>{len(names)} points. Without filtering the TCP misses by {rms:.3f} mm RMS, "
            f"{e.max(initial=0.0):.3f} mm at most (predicted: the identified arm against the "
            "controller's nominal model). Filtered, it lands within the identification's "
            + (f"uncertainty: 3D RMS error {s.max():.4f} mm at most (the RMS length of the "
               "error the identification's covariance and model error predict).</p>" if known else
               "uncertainty (the identified model carries no covariance to state it).</p>"))
    rows = [[n, float(a), float(b), float(c) if known else "-"] for n, a, b, c in zip(names, e, d, s)]
    table = _table(["point", "error without filtering (mm)", "correction (mm)",
                    "3D RMS error filtered (mm)"], rows)
    name = html.escape(title)
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>robotcell accuracy: {name}</title>
<style>{_CSS}</style><script>{_SCRIPT}</script></head>
<body>
<h1>Absolute accuracy of {name}</h1>{head}
<figure><img src="{_figure(e, d, s)}" alt="errors per point"></figure>
<h2>Per point</h2>{table}
</body></html>
"""
    out = Path(path)
    atomic_write(out, page)
    return out
