"""HTML report of a kinematic identification: one self-contained page, figures embedded.

The page (``robotcell identify ... --report FILE.html``) shows the verdict, the position error of
the nominal and the identified model (mean, RMS, max; per row and as a histogram; the orientation
error with pose measurements; the J2/J3 check with a stated coupling), given the measurements an
interactive 3D scene of them (:mod:`robotcell.view.identification`: the measured targets, the
residuals magnified, the identified arm beside the nominal one), the K-fold cross-validated
error, the parameters held and why, every parameter with its 1-sigma and the largest
correlations, and the observability index O1 of the measured configurations against random
ones. Figures are PNG ``data:`` URIs made with :mod:`robotcell.report.page`, the scene
a plotly figure with plotly.js inlined (matplotlib and plotly imported only when a report is
written).
"""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.sigmaparts import sigma_basis
from robotcell.identification.measurements import TargetMeasurements
from robotcell.identification.result import (
    OWN_MEASUREMENTS,
    SIGMA_RELATIVE_TO,
    IdentificationResult,
)
from robotcell.identification.validation import CrossValidation
from robotcell.io.fileio import atomic_write
from robotcell.report.page import CSS, SCENE_SLOT, SCRIPT, png, scene_figure, table
from robotcell.view.identification import identification_scene
from robotcell.view.plot import MAX_PAGE_BYTES
from robotcell.view.pyplot import pyplot

__all__ = ["write_identification_report"]

#: Correlations listed in the report (largest absolute values first).
N_CORRELATIONS = 10


def _figure_errors(before: NDArray[np.float64], after: NDArray[np.float64], title: str) -> str:
    """Histogram of the per-row errors of both models, and the errors per row (mm)."""
    plt = pyplot()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.4))
    both = np.maximum(np.concatenate([before, after]), 1e-6)
    bins = np.geomspace(both.min(), both.max() * 1.001 + 1e-9, 30)  # log: both models visible
    ax1.hist(np.maximum(before, 1e-6), bins=bins, color="tab:red", alpha=0.6, label="nominal model")
    ax1.hist(np.maximum(after, 1e-6), bins=bins, color="tab:blue", alpha=0.8, label="identified model")
    ax1.set_xscale("log")
    ax1.set_xlabel("position error [mm]")
    ax1.set_ylabel("rows")
    ax1.legend(fontsize=8)
    rows = np.arange(len(before))
    ax2.semilogy(rows, np.maximum(before, 1e-6), "o", color="tab:red", ms=3, label="nominal model")
    ax2.semilogy(rows, np.maximum(after, 1e-6), "o", color="tab:blue", ms=3, label="identified model")
    ax2.set_xlabel("row")
    ax2.set_ylabel("position error [mm]")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return png(fig)


def _figure_observability(o1: float, o1_random: NDArray[np.float64]) -> str:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 2.8))
    ax.hist(o1_random, bins=12, color="tab:gray", label=f"{len(o1_random)} random sets")
    ax.axvline(o1, color="tab:blue", linewidth=2, label="measured configurations")
    ax.set_xlabel("observability index O1")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return png(fig)


def _stats(e: NDArray[np.float64]) -> list[float]:
    return [float(e.mean()), float(math.sqrt(np.mean(e**2))), float(e.max())]


def _errors_html(result: IdentificationResult) -> str:
    """The tables of the position (and orientation) errors of both models."""
    all0 = np.linalg.norm(result.residuals_before, axis=-1).ravel() * 1e3
    all1 = np.linalg.norm(result.residuals, axis=-1).ravel() * 1e3
    errors = table(["model", "mean (mm)", "RMS (mm)", "max (mm)"],
                   [["nominal (base and targets fitted)", *_stats(all0)],
                    ["identified", *_stats(all1)]])
    if result.rotation_residuals is not None:
        r0 = np.degrees(np.linalg.norm(result.rotation_residuals_before, axis=-1))
        r1 = np.degrees(np.linalg.norm(result.rotation_residuals, axis=-1))
        errors += table(["model", "orientation mean (deg)", "RMS (deg)", "max (deg)"],
                        [["nominal (base and target fitted)", *_stats(r0)],
                         ["identified", *_stats(r1)]])
    return errors


def _cross_validation_html(cross_validation: CrossValidation | None) -> str:
    """The held-out errors of both models, or that they were not computed."""
    if cross_validation is None:
        return "<p>not run (<code>--folds K</code>)</p>"
    cv = cross_validation
    b, a = cv.before.max(axis=1) * 1e3, cv.after.max(axis=1) * 1e3
    fig_cv = _figure_errors(b, a, f"Held-out position error, {cv.folds}-fold cross-validation")
    return (f"<p>Every row predicted by the models fitted without its fold ({cv.folds} folds).</p>"
            + table(["model", "mean (mm)", "RMS (mm)", "max (mm)"],
                    [["start model (base and targets fitted)", *_stats(cv.before.ravel() * 1e3)],
                     ["identified (written)", *_stats(cv.after.ravel() * 1e3)]])
            + f'<figure><img src="{fig_cv}" alt="cross-validated errors"></figure>')


def _parameters_html(result: IdentificationResult) -> tuple[str, str, str]:
    """The parameters held and why, every parameter with its 1-sigma, the largest
    correlations."""
    fixed = ("<ul>" + "".join(f"<li><b>{html.escape(n)}</b>: {html.escape(w)}</li>"
                              for n, w in result.fixed) + "</ul>"
             if result.fixed else "<p>none: every candidate parameter is identifiable</p>")
    prows = []
    for p in result.parameters:
        v, nom, s, unit = p.vendor()
        prows.append([p.name, unit, nom if math.isfinite(nom) else "", v,
                      v - nom if math.isfinite(nom) else "", s if p.free else "fixed"])
    params = table(["name", "unit", "nominal", "identified", "change", "1-sigma"], prows)
    C = result.correlation
    iu = np.triu_indices(len(result.free), 1)
    order = np.argsort(-np.abs(C[iu]))[:N_CORRELATIONS]
    corr = table(["parameter", "parameter", "correlation"],
                 [[result.free[iu[0][k]], result.free[iu[1][k]], float(C[iu][k])] for k in order])
    return fixed, params, corr


def _observability_html(observability: tuple[float, NDArray[np.float64]] | None) -> str:
    """O1 of the measured configurations against random sets, or that it was not computed."""
    if observability is None:
        return "<p>not computed</p>"
    o1, rand = observability
    better = float(np.mean(rand < o1)) * 100
    return (f"<p>Borm and Menq's O1 (geometric mean of the singular values of the scaled "
            f"identification Jacobian): measured configurations {o1:.4g}; "
            f"{len(rand)} random sets of as many configurations within the joint limits: "
            f"median {np.median(rand):.4g}, best {rand.max():.4g}. The measured set is "
            f"better than {better:.0f} % of them. <code>select_configurations</code> "
            f"(<code>robotcell identify --propose N</code>) proposes configurations that "
            f"maximise O1.</p>"
            f'<figure><img src="{_figure_observability(o1, rand)}" alt="observability"></figure>')


def write_identification_report(
    result: IdentificationResult,
    path: str | Path,
    cross_validation: CrossValidation | None = None,
    observability: tuple[float, NDArray[np.float64]] | None = None,
    measurements: TargetMeasurements | None = None,
) -> Path:
    """Write the HTML report of an identification (one file, figures embedded).

    Parameters
    ----------
    result : IdentificationResult
    path : str or Path
        The HTML file to write (atomically; a missing folder is created); nothing else is written.
    cross_validation : CrossValidation, optional
        Held-out errors (:func:`~robotcell.identification.cross_validate`).
    observability : (float, ndarray), optional
        O1 of the measured configurations and of random sets
        (:func:`~robotcell.identification.compare_observability`).
    measurements : TargetMeasurements, optional
        The measurements identified: given, the page shows their 3D scene
        (:func:`~robotcell.view.identification.identification_scene`).

    Returns
    -------
    Path
        The file written.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    grade, why = result.verdict
    e0 = np.linalg.norm(result.residuals_before, axis=-1).max(axis=1) * 1e3
    e1 = result.row_errors * 1e3
    errors = _errors_html(result)
    extra = ""
    if result.coupling_check:
        c = result.coupling_check
        extra = f"<h2>J2/J3 coupling</h2><p>{html.escape(c['verdict'])}.</p>"
    fig_fit = _figure_errors(e0, e1, "Position error on the measured rows (largest target per row)")
    per_row = table(["row", "nominal (mm)", "identified (mm)", "outlier"],
                     [[lab, float(a), float(b), "yes" if i in result.outliers else ""]
                      for i, (lab, a, b) in enumerate(zip(result.labels, e0, e1))])
    cv_html = _cross_validation_html(cross_validation)
    fixed, params, corr = _parameters_html(result)
    obs_html = _observability_html(observability)
    scene_html = "" if measurements is None else f"<h2>3D view of the measurements</h2>{SCENE_SLOT}"
    name = html.escape(result.nominal.name)
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>robotcell identification: {name}</title>
<style>{CSS}</style><script>{SCRIPT}</script></head>
<body>
<h1>Kinematic identification of {name}</h1>
<p>{len(result.labels)} rows, {result.residuals.shape[1]} target(s) per row; stated accuracy
{result.touch_sigma * 1e3:.4f} mm per coordinate.</p>
<div class="verdict {grade}"><b>{grade.upper()}</b>: {html.escape(why)}</div>
<h2>Position error before and after identification</h2>{errors}
<p>Condition number {result.condition:.1f}, redundancy {result.dof}, variance factor
{result.variance_factor:.3f} (1 when the stated accuracy is right).</p>
<figure><img src="{fig_fit}" alt="errors before and after"></figure>
<h2>Predicted error</h2><ul>{"".join(f"<li>{html.escape(t)}</li>" for t in result.error_lines())}</ul>
{extra}{scene_html}
<h2>Cross-validation</h2>{cv_html}
<h2>Parameters held at their nominal value, and why</h2>{fixed}
<h2>Parameters (mm, deg) with 1-sigma</h2>
<p>Each 1-sigma {html.escape(sigma_basis(SIGMA_RELATIVE_TO, own=OWN_MEASUREMENTS))}.</p>{params}
<h2>Largest correlations</h2>{corr}
<h2>Observability of the measured configurations</h2>{obs_html}
<h2>Errors per row (mm)</h2>{per_row}
</body></html>
"""
    if measurements is not None:
        scenes = [identification_scene(result, measurements.q, measurements.points, arrows=a)
                  for a in (True, False)]
        figure = scene_figure(scenes, MAX_PAGE_BYTES - len(page.encode()),
                              "the measured targets and the identified arm")
        page = page.replace(SCENE_SLOT, figure, 1)
    atomic_write(out, page)
    return out
