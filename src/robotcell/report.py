"""HTML reports of calibration results, with PNG figures.

A report is made from the JSON a calibration writes (``robotcell calibrate ... --json``, or
``CalibrationResult.to_json()``), so it can be produced later and elsewhere. It shows, at a glance,
whether the calibration is good (a verdict with its reasons), the result, the 1-sigma
uncertainties, residuals per touch, and a 3D view of the measured points with their residual
vectors magnified. matplotlib is imported only here, and only when a report is written.
"""

from __future__ import annotations

import html
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from robotcell.errors import InputError
from robotcell.fileio import atomic_write, read_text

__all__ = ["CONDITION_GOOD", "CONDITION_POOR", "load_result", "verdict", "write_report"]

#: Condition numbers up to this are a good measurement design (Schroer, as cited by Nahvi and
#: Hollerbach, ICRA 1996).
CONDITION_GOOD = 100.0
#: Above this the result is not trustworthy.
CONDITION_POOR = 1000.0

_REQUIRED = ("procedure", "residuals_mm", "rms_mm", "max_mm", "warnings")


def load_result(path: str | Path) -> dict[str, Any]:
    """Read a calibration result written by ``robotcell calibrate ... --json``.

    Raises
    ------
    InputError
        The file is missing, not JSON, or lacks the fields of a calibration result.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    try:
        data = json.loads(read_text(p))
    except (json.JSONDecodeError, RecursionError) as exc:
        raise InputError(f"{path}: not valid JSON ({exc}); give the output of "
                         "'robotcell calibrate ... --json'") from None
    missing = [k for k in _REQUIRED if not isinstance(data, dict) or k not in data]
    if missing:
        raise InputError(f"{path}: not a calibration result (missing {', '.join(missing)}); give "
                         "the output of 'robotcell calibrate ... --json'")
    bad = _malformed(data)
    if bad:
        raise InputError(f"{path}: not a calibration result: {bad}; give the unchanged output "
                         "of 'robotcell calibrate ... --json'")
    return data


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _is_points(v: Any, n: int | None) -> bool:
    """A list of ``n`` (any number when None) lists of 3 finite numbers."""
    return (isinstance(v, list) and (n is None or len(v) == n)
            and all(isinstance(p, list) and len(p) == 3 and all(map(_is_number, p)) for p in v))


def _malformed(data: dict[str, Any]) -> str | None:
    """What is wrong with the fields of a result that the report uses, or None."""
    if not isinstance(data["procedure"], str):
        return "'procedure' must be a text"
    res = data["residuals_mm"]
    if not isinstance(res, list) or not all(map(_is_number, res)):
        return "'residuals_mm' must be a list of numbers"
    n = len(res)
    for key in ("rms_mm", "max_mm"):
        if not _is_number(data[key]):
            return f"{key!r} must be a number"
    for key in ("warnings", "undetermined"):
        v = data.get(key, [])
        if (v is not None or key == "warnings") and (
                not isinstance(v, list) or not all(isinstance(w, str) for w in v)):
            return f"{key!r} must be a list of texts"
    checks = {
        "condition": lambda v: _is_number(v),
        "labels": lambda v: isinstance(v, list) and len(v) == n
        and all(isinstance(x, (str, int)) for x in v),
        "residuals_xyz_mm": lambda v: _is_points(v, n),
        "points_mm": lambda v: _is_points(v, None),
        "pivot_mm": lambda v: _is_points([v], 1),
        "sigma": lambda v: isinstance(v, dict),
        "matrix": lambda v: isinstance(v, list) and len(v) == 4
        and all(isinstance(r, list) and len(r) == 4 and all(map(_is_number, r)) for r in v),
    }
    for key, ok in checks.items():
        if data.get(key) is not None and not ok(data[key]):
            return f"{key!r} has the wrong type or size"
    return None


def verdict(result: dict[str, Any]) -> tuple[str, list[str]]:
    """Grade a result: ``"good"``, ``"check"`` or ``"poor"``, with the reasons.

    ``poor``: condition number above :data:`CONDITION_POOR` or a touch flagged as an outlier.
    ``check``: any other warning, a condition number above :data:`CONDITION_GOOD`, or unknown
    uncertainty (no redundant touches and no prior noise). ``good`` otherwise.

    Parameters
    ----------
    result : dict
        A calibration result as JSON (mm, deg).

    Returns
    -------
    grade : str
    reasons : list of str
    """
    reasons: list[str] = []
    grade = "good"
    cond = result.get("condition")
    warnings = list(result.get("warnings", []))
    if cond is not None and cond > CONDITION_POOR:
        grade = "poor"
        reasons.append(f"condition number {cond:.0f} > {CONDITION_POOR:.0f}: the touches do not "
                       "determine the result")
    if any("outlier" in w for w in warnings):
        grade = "poor"
        reasons.append("a touch is an outlier: re-touch it")
    if grade != "poor":
        if cond is not None and cond > CONDITION_GOOD:
            grade = "check"
            reasons.append(f"condition number {cond:.0f} > {CONDITION_GOOD:.0f}: spread the touches")
        if warnings:
            grade = "check"
            reasons.append(f"{len(warnings)} warning(s), listed below")
        if result.get("noise_source") == "none":
            grade = "check"
            reasons.append("no redundant touches: the uncertainty is unknown")
    if grade == "good":
        reasons.append(f"RMS {result['rms_mm']:.3f} mm, max {result['max_mm']:.3f} mm, "
                       f"condition {cond:.0f}" if cond is not None else "no warnings")
    return grade, reasons


def _frames(result: dict[str, Any]) -> list[tuple[str, np.ndarray]]:
    """Poses the result contains, as (label, 4x4 with translation in mm)."""
    out = []
    if isinstance(result.get("matrix"), list):
        out.append((result["procedure"], np.array(result["matrix"], dtype=float)))
    out.append(("robot base", np.eye(4)))
    return out


def _figure_view(result: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    res = np.array(result.get("residuals_xyz_mm") or [], dtype=float).reshape(-1, 3)
    pts = result.get("points_mm")
    anchor = None
    if pts is not None:
        anchor = np.array(pts, dtype=float).reshape(-1, 3)
    elif result.get("pivot_mm") is not None:
        anchor = np.repeat(np.array(result["pivot_mm"], dtype=float)[None], len(res), axis=0)
    frames = _frames(result)
    cloud = [T[:3, 3] for _, T in frames]
    if anchor is not None:
        cloud += list(anchor)
    cloud = np.array(cloud)
    size = float(np.ptp(cloud, axis=0).max()) if len(cloud) > 1 else 100.0
    size = max(size, 50.0)
    for label, T in frames:
        L = 0.15 * size
        for k, color in enumerate(("tab:red", "tab:green", "tab:blue")):
            ax.quiver(*T[:3, 3], *(T[:3, k] * L), color=color, linewidth=2)
        ax.text(*T[:3, 3], f" {label}", fontsize=9)
    gain = None
    if anchor is not None and len(res) == len(anchor) and len(res):
        ax.scatter(*anchor.T, color="black", s=18, label="measured points")
        longest = float(np.linalg.norm(res, axis=1).max())
        gain = 0.1 * size / longest if longest > 0 else 1.0
        ax.quiver(*anchor.T, *(res.T * gain), color="tab:orange", linewidth=1.5,
                  label="residuals")
        ax.legend(loc="upper left")
    ax.set_xlabel("X [mm]")
    ax.set_ylabel("Y [mm]")
    ax.set_zlabel("Z [mm]")
    title = "Frames and measured points (robot base, mm)"
    if gain is not None:
        title += f"\nresidual vectors magnified {gain:.0f}x"
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _figure_residuals(result: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    r = np.array(result["residuals_mm"], dtype=float)
    labels = result.get("labels") or [str(i + 1) for i in range(len(r))]
    fig, ax = plt.subplots(figsize=(7, 3.2))
    # The calibration flags outliers with each touch's leverage taken into account; show its
    # verdict rather than a fixed threshold.
    flagged = {lab for lab in labels
               if any(w.startswith(f"touch {lab} is an outlier") for w in result.get("warnings", []))}
    colors = ["tab:red" if lab in flagged else "tab:blue" for lab in labels]
    ax.bar(range(len(r)), r, color=colors)
    ax.axhline(result["rms_mm"], color="tab:green", linestyle="--", label=f"RMS {result['rms_mm']:.3f} mm")
    if flagged:
        ax.bar([], [], color="tab:red", label="outlier (see warnings)")
    ax.set_xticks(range(len(r)), labels, rotation=45 if len(r) > 8 else 0, fontsize=8)
    ax.set_ylabel("residual [mm]")
    ax.set_title("Residual per touch (measured - model)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return "n/a" if not math.isfinite(v) else f"{v:.4f}"
    if isinstance(v, list):
        if v and isinstance(v[0], list):
            return "<br>".join(_fmt(row) for row in v)
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    if v is None:
        return "not determined"
    return html.escape(str(v))


_SKIP = {"procedure", "residuals_mm", "residuals_xyz_mm", "labels", "points_mm", "warnings",
         "undetermined", "next_step", "sigma"}

_CSS = """
body { font-family: sans-serif; max-width: 960px; margin: 2em auto; color: #222; }
.verdict { padding: 0.8em 1em; border-radius: 6px; font-size: 1.2em; }
.good { background: #d8f3dc; } .check { background: #fff3bf; } .poor { background: #ffd6d6; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; }
td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
img { max-width: 100%; border: 1px solid #ddd; margin: 0.5em 0; }
"""

# Marks the page once every figure has loaded with a size, so a browser test can read it.
_SCRIPT = """
window.addEventListener('load', function () {
  var imgs = Array.prototype.slice.call(document.images);
  var ok = imgs.length > 0 && imgs.every(function (i) { return i.complete && i.naturalWidth > 0; });
  document.body.setAttribute('data-figures', ok ? 'loaded' : 'missing');
});
"""


def write_report(result: dict[str, Any], path: str | Path) -> list[Path]:
    """Write an HTML report and its PNG figures next to it.

    Parameters
    ----------
    result : dict
        A calibration result as JSON (mm, deg), e.g. from :func:`load_result`.
    path : str or Path
        The HTML file to write; figures are written beside it as ``<stem>_view.png`` and
        ``<stem>_residuals.png``.

    Returns
    -------
    list of Path
        The files written: the HTML page first, then the figures.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    view = out.with_name(out.stem + "_view.png")
    resid = out.with_name(out.stem + "_residuals.png")
    _figure_view(result, view)
    _figure_residuals(result, resid)
    grade, reasons = verdict(result)
    proc = html.escape(str(result["procedure"]))
    rows = "".join(f"<tr><th>{html.escape(k)}</th><td>{_fmt(v)}</td></tr>"
                   for k, v in result.items() if k not in _SKIP)
    sig = "".join(f"<tr><th>{html.escape(k)}</th><td>{_fmt(v)}</td></tr>"
                  for k, v in (result.get("sigma") or {}).items())
    labels = result.get("labels") or [str(i + 1) for i in range(len(result["residuals_mm"]))]
    xyz = result.get("residuals_xyz_mm") or [[float("nan")] * 3] * len(labels)
    touches = "".join(
        f"<tr><td>{html.escape(str(lab))}</td><td>{r:.4f}</td><td>{_fmt(list(v))}</td></tr>"
        for lab, r, v in zip(labels, result["residuals_mm"], xyz))
    def items(key: str) -> str:
        vals = result.get(key) or []
        return "<ul>" + "".join(f"<li>{html.escape(str(v))}</li>" for v in vals) + "</ul>" if vals else "<p>none</p>"

    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>robotcell report: {proc}</title>
<style>{_CSS}</style><script>{_SCRIPT}</script></head>
<body>
<h1>Calibration report: {proc}</h1>
<div class="verdict {grade}"><b>{grade.upper()}</b>: {html.escape('; '.join(reasons))}</div>
<h2>Next step</h2><p>{html.escape(str(result.get('next_step') or ''))}</p>
<h2>Result (mm, deg)</h2><table>{rows}</table>
<h2>1-sigma uncertainty</h2><table>{sig or '<tr><td>not available</td></tr>'}</table>
<h2>Not determined by the measurements</h2>{items('undetermined')}
<h2>Warnings</h2>{items('warnings')}
<h2>Figures</h2>
<img src="{view.name}" alt="3D view of frames and measured points">
<img src="{resid.name}" alt="residual per touch">
<h2>Residuals per touch (mm)</h2>
<table><tr><th>touch</th><th>|residual|</th><th>x, y, z</th></tr>{touches}</table>
</body></html>
"""
    atomic_write(out, page)
    return [out, view, resid]
