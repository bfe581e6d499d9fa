"""HTML reports of calibration results: one self-contained page, its figures embedded.

A report is made from the JSON a calibration writes (``robotcell calibrate ... --json``, or
``CalibrationResult.to_json()``), so it can be produced later and elsewhere. It shows, at a glance,
whether the calibration is good (a verdict with its reasons), the result, the 1-sigma
uncertainties, residuals per touch, and a 3D view of the measured points with their residual
vectors magnified. The figures are PNG images embedded in the page (``data:`` URIs), so the
HTML file alone is the whole report: it can be mailed or copied anywhere. matplotlib is imported
only here, and only when a report is written.
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from robotcell.calibration.result import PROCEDURES
from robotcell.calibration.verdict import CONDITION_GOOD, CONDITION_POOR
from robotcell.calibration.verdict import verdict as judge
from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write, read_text
from robotcell.io.tables import MAX_ABS_VALUE
from robotcell.kinematics.transforms import check_pose

__all__ = ["CONDITION_GOOD", "CONDITION_POOR", "load_result", "verdict", "write_report"]

_REQUIRED = ("procedure", "residuals_mm", "rms_mm", "max_mm", "warnings")


def load_result(path: str | Path) -> dict[str, Any]:
    """Read a calibration result written by ``robotcell calibrate ... --json``.

    Raises
    ------
    InputError
        The file is missing, not JSON, or not a calibration result as ``calibrate`` writes it:
        a field missing or of the wrong type, an unknown ``procedure``, a number that is not
        finite (anywhere), a length (a key ending in ``_mm``, the translation of ``matrix``)
        beyond :data:`~robotcell.io.tables.MAX_ABS_VALUE` mm, or a ``matrix`` (a track's
        ``rotation``) that is not a rigid transform (a proper rotation).
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


def _not_finite(v: Any, where: str) -> str | None:
    """Where in ``v`` (parsed JSON) a number is not finite (NaN, Infinity, an integer of 400
    digits), or None."""
    if isinstance(v, dict):
        return next((w for k, x in v.items() if (w := _not_finite(x, f"{where}.{k}"))), None)
    if isinstance(v, list):
        return next((w for i, x in enumerate(v) if (w := _not_finite(x, f"{where}[{i}]"))), None)
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        try:
            ok = math.isfinite(float(v))
        except OverflowError:
            ok = False
        return None if ok else where
    return None


def _lengths(v: Any) -> list[float]:
    """The numbers in ``v`` (a number or nested lists of them)."""
    if isinstance(v, list):
        return [x for item in v for x in _lengths(item)]
    return [v] if isinstance(v, (int, float)) and not isinstance(v, bool) else []


def _is_points(v: Any, n: int | None) -> bool:
    """A list of ``n`` (any number when None) lists of 3 finite numbers."""
    return (isinstance(v, list) and (n is None or len(v) == n)
            and all(isinstance(p, list) and len(p) == 3 and all(map(_is_number, p)) for p in v))


def _malformed(data: dict[str, Any]) -> str | None:
    """What is wrong with the fields of a result that the report uses, or None."""
    if not isinstance(data["procedure"], str):
        return "'procedure' must be a text"
    if data["procedure"] not in PROCEDURES:
        return (f"'procedure' {data['procedure']!r} is none robotcell calibrates "
                f"({', '.join(PROCEDURES)})")
    where = _not_finite(data, "")
    if where is not None:
        return f"{where.lstrip('.')!r} is not a finite number"
    for key, value in data.items():
        if key.endswith("_mm") and any(abs(v) > MAX_ABS_VALUE for v in _lengths(value)):
            return (f"{key!r} holds a length beyond {MAX_ABS_VALUE:.0e} mm, which no "
                    "calibration measures")
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
        "rotation": lambda v: _is_points(v, 3),
    }
    for key, ok in checks.items():
        if data.get(key) is not None and not ok(data[key]):
            return f"{key!r} has the wrong type or size"
    if data.get("matrix") is not None:
        T = np.array(data["matrix"], dtype=float)
        if np.abs(T[:3, 3]).max() > MAX_ABS_VALUE:
            return f"'matrix' holds a translation beyond {MAX_ABS_VALUE:.0e} mm"
        T[:3, 3] *= 1e-3
        ok, reasons = check_pose(T)
        if not ok:
            return f"'matrix' is not a rigid transform (R orthonormal, det R = 1): {reasons[0]}"
    if data.get("rotation") is not None:  # the track's L_Q_R
        T = np.eye(4)
        T[:3, :3] = data["rotation"]
        ok, reasons = check_pose(T)
        if not ok:
            return f"'rotation' is not a proper rotation (orthonormal, det = 1): {reasons[0]}"
    return None


def verdict(result: dict[str, Any]) -> tuple[str, list[str]]:
    """Grade a result: ``"good"``, ``"check"`` or ``"poor"``, with the reasons.

    The same rule as the terminal report and ``--json``:
    :func:`robotcell.calibration.verdict.verdict` (see ``docs/calibration.md``, "Verdict").

    Parameters
    ----------
    result : dict
        A calibration result as JSON (mm, deg).

    Returns
    -------
    grade : str
    reasons : list of str
    """
    v = judge(result)
    return v.level, v.reasons


#: Names of the frames of docs/conventions.md, for figure labels.
_FRAME_NAMES = {"R": "robot base R", "world": "world", "L": "track L", "B": "turntable B",
                "F": "flange F", "W": "workpiece W", "TCP": "TCP"}
#: A key of a result's pose ``T_a_b`` (its sigma or covariance), giving frames a and b.
_POSE_KEY = re.compile(r"T_(R|world|L|B|F)_(\w+?)_(?:position_mm|rotation_deg|covariance_mm_rad)")


def _frames(result: dict[str, Any]) -> tuple[str, list[tuple[str, np.ndarray]]]:
    """The frame the measured points are in, and the poses to draw in it.

    The result's ``matrix`` is the pose ``T_a_b`` its key names (e.g. ``T_world_B_position_mm``):
    the figure is drawn in frame a, with frame a at the origin and frame b at ``matrix``. A tool
    on the flange (``T_F_TCP``) and a result without ``matrix`` (the track) have their points in
    the robot base, where there is no pose of theirs to draw.

    Returns
    -------
    name : str
        Name of the frame of the figure, e.g. ``"world"``.
    frames : list of (str, ndarray of shape (4, 4))
        Label and pose (translation in mm) of each frame to draw.
    """
    keys = [*result, *(result.get("sigma") or {})]
    match = next((m for m in map(_POSE_KEY.fullmatch, keys) if m), None)
    if match is None or match[1] == "F" or not isinstance(result.get("matrix"), list):
        return _FRAME_NAMES["R"], [(_FRAME_NAMES["R"], np.eye(4))]
    a, b = _FRAME_NAMES[match[1]], _FRAME_NAMES.get(match[2], match[2])
    return a, [(a, np.eye(4)), (b, np.array(result["matrix"], dtype=float))]


def _png(fig: Any) -> str:
    """A matplotlib figure as a ``data:image/png;base64,...`` URI; the figure is closed."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _figure_view(result: dict[str, Any]) -> str:
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
    where, frames = _frames(result)
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
    title = f"Frames and measured points (in {where}, mm)"
    if gain is not None:
        title += f"\nresidual vectors magnified {gain:.0f}x"
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return _png(fig)


def _figure_residuals(result: dict[str, Any]) -> str:
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
    return _png(fig)


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        if not math.isfinite(v):
            return "n/a"
        # Four decimals for everyday magnitudes; significant digits for tiny or huge ones (a
        # covariance in rad^2, a sigma of 1e-7), which four decimals would show as 0.0000.
        return f"{v:.4f}" if v == 0 or 1e-3 <= abs(v) < 1e7 else f"{v:.4g}"
    if isinstance(v, list):
        if v and isinstance(v[0], list):
            return "<br>".join(_fmt(row) for row in v)
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    if v is None:
        return "not determined"
    return html.escape(str(v))


#: Units of the fields whose name does not end with one.
_UNITS = {"_covariance_mm_rad": "6x6 over the origin x, y, z (mm) and the rotation vector rx, ry, rz "
                                "(rad): entries in mm², mm·rad, rad²"}

_SKIP = {"procedure", "residuals_mm", "residuals_xyz_mm", "labels", "points_mm", "warnings",
         "undetermined", "next_step", "sigma", "verdict"}

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
    """Write an HTML report: one self-contained file, its figures embedded as PNG data URIs.

    Parameters
    ----------
    result : dict
        A calibration result as JSON (mm, deg), e.g. from :func:`load_result`.
    path : str or Path
        The HTML file to write. Nothing else is written beside it.

    Returns
    -------
    list of Path
        The files written: the HTML page.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    where = _frames(result)[0]
    view = _figure_view(result)
    resid = _figure_residuals(result)
    grade, reasons = verdict(result)
    proc = html.escape(str(result["procedure"]))

    def head(key: str) -> str:
        units = [u for suffix, u in _UNITS.items() if key.endswith(suffix)]
        return html.escape(key) + "".join(f"<br><small>{html.escape(u)}</small>" for u in units)

    rows = "".join(f"<tr><th>{head(k)}</th><td>{_fmt(v)}</td></tr>"
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
<figure><img src="{view}" alt="3D view of frames and measured points">
<figcaption>Frames and measured points in the {html.escape(where)} frame (mm).</figcaption></figure>
<figure><img src="{resid}" alt="residual per touch"></figure>
<h2>Residuals per touch (mm)</h2>
<table><tr><th>touch</th><th>|residual|</th><th>x, y, z</th></tr>{touches}</table>
</body></html>
"""
    atomic_write(out, page)
    return [out]
