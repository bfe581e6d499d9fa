"""HTML reports of calibration results: one self-contained page, its figures embedded.

A report is made from the JSON a calibration writes (``robotcell calibrate ... --json``, or
``CalibrationResult.to_json()``), so it can be produced later and elsewhere. It shows, at a glance,
whether the calibration is good (a verdict with its reasons), the result, the 1-sigma
uncertainties, residuals per touch, and an interactive 3D scene of the touches, the fitted
geometry and the residual vectors magnified (:mod:`robotcell.view.calibration`, drawn with
plotly). The residual figure is a PNG image (:mod:`robotcell.report.page`) embedded in the page (a ``data:`` URI) and plotly.js
is inlined, so the HTML file alone is the whole report (about 4.9 MB): it can be mailed or copied
anywhere and opens offline. matplotlib and plotly are imported only when a report is written.
"""

from __future__ import annotations

import html
import re
from pathlib import Path
from typing import Any

import numpy as np

from robotcell.calibration.result import CalibrationResult, result_json
from robotcell.calibration.resultcheck import is_points
from robotcell.calibration.sigmaparts import PARTS, part_lines, sigma_basis
from robotcell.calibration.verdict import CONDITION_GOOD, CONDITION_POOR
from robotcell.calibration.verdict import verdict as judge
from robotcell.cell.calibrate.registry import attach, for_result
from robotcell.io.fileio import atomic_write, read_json
from robotcell.io.poseformats import pose_to_vendor
from robotcell.report.page import CSS, SCENE_SLOT, SCRIPT, fmt, png, scene_figure
from robotcell.view.calibration import calibration_scene, outliers
from robotcell.view.plot import MAX_PAGE_BYTES
from robotcell.view.pyplot import pyplot

__all__ = ["CONDITION_GOOD", "CONDITION_POOR", "load_result", "verdict", "write_report"]

def load_result(path: str | Path) -> dict[str, Any]:
    """Read a calibration result written by ``robotcell calibrate ... --json``, as the JSON it
    was written as, checked by :meth:`CalibrationResult.from_json
    <robotcell.calibration.result.CalibrationResult.from_json>`.

    Raises
    ------
    InputError
        As :meth:`CalibrationResult.from_json
        <robotcell.calibration.result.CalibrationResult.from_json>`, and for a file that is
        missing or not JSON.
    """
    data = read_json(path, f"give the {result_json()}")
    return CalibrationResult.from_json(data, str(path)).to_json()


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
                "F": "flange F", "W": "workpiece W", "TCP": "TCP",
                "ref": "the reference robot's base", "other": "the other robot's base"}
#: A key of a result's pose ``T_a_b`` (its sigma or covariance), giving frames a and b.
_POSE_KEY = re.compile(
    r"T_(R|world|L|B|F|ref)_(\w+?)_(?:position_mm|rotation_deg|covariance_mm_rad)")


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
    proc = for_result(result.get("procedure"))
    own = None if proc is None or proc.figure_frames is None else proc.figure_frames(result)
    if own is not None:
        return own
    keys = [*result, *(result.get("sigma") or {})]
    match = next((m for m in map(_POSE_KEY.fullmatch, keys) if m), None)
    if match is None or match[1] == "F" or not isinstance(result.get("matrix"), list):
        return _FRAME_NAMES["R"], [(_FRAME_NAMES["R"], np.eye(4))]
    a, b = _FRAME_NAMES[match[1]], _FRAME_NAMES.get(match[2], match[2])
    return a, [(a, np.eye(4)), (b, np.array(result["matrix"], dtype=float))]


def _workpiece_frames(result: dict[str, Any]
                      ) -> tuple[str, list[tuple[str, np.ndarray]]] | None:
    """:func:`_frames` of a workpiece on a turntable: the turntable's parent frame, B and W."""
    if not isinstance(result.get("turntable_matrix"), list):
        return None
    # The touches are where the table had turned each of them, in the turntable's parent
    # (the world in a cell, else the robot base): drawn there, with B and W at table 0.
    T_P_B = np.array(result["turntable_matrix"], dtype=float)
    T_B_W = np.array(result["matrix"], dtype=float)
    parent = "the turntable's parent frame"
    return parent, [(parent, np.eye(4)), (_FRAME_NAMES["B"], T_P_B),
                    ("workpiece W at table 0", T_P_B @ T_B_W)]


# The frames of the figure of a workpiece's results, registered with the procedure (the
# registry stands below the reports and cannot name them).
attach("workpiece", figure_frames=_workpiece_frames)


def _scene(result: dict[str, Any], room: int) -> str:
    """The interactive 3D scene of the result (:func:`robotcell.view.calibration
    .calibration_scene`) as a figure of the page, plotly.js inlined."""
    where, frames = _frames(result)
    scenes = [calibration_scene(result, where, frames, arrows=a) for a in (True, False)]
    return scene_figure(scenes, room, "the frames, touches and fitted geometry")


def _figure_residuals(result: dict[str, Any]) -> str:
    plt = pyplot()
    r = np.array(result["residuals_mm"], dtype=float)
    labels = result.get("labels") or [str(i + 1) for i in range(len(r))]
    fig, ax = plt.subplots(figsize=(7, 3.2))
    flagged = outliers(result, [str(lab) for lab in labels])
    colors = ["tab:red" if bad else "tab:blue" for bad in flagged]
    ax.bar(range(len(r)), r, color=colors)
    ax.axhline(result["rms_mm"], color="tab:green", linestyle="--", label=f"RMS {result['rms_mm']:.3f} mm")
    if flagged.any():
        ax.bar([], [], color="tab:red", label="outlier (see warnings)")
    ax.set_xticks(range(len(r)), labels, rotation=45 if len(r) > 8 else 0, fontsize=8)
    ax.set_ylabel("residual [mm]")
    ax.set_title("Residual per touch (measured - model)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return png(fig)


#: Units of the fields whose name does not end with one.
_UNITS = {"_covariance_mm_rad": "6x6 over the origin x, y, z (mm) and the rotation vector rx, ry, rz "
                                "(rad): entries in mm², mm·rad, rad²"}

#: Fields shown elsewhere in the page (verdict, residual table, lists).
_SKIP = {"procedure", "residuals_mm", "residuals_xyz_mm", "labels", "points_mm", "warnings",
         "undetermined", "next_step", "sigma", "verdict", "xyzabc", "sigma_relative_to",
         "sigma_parts"}

#: Result fields a technician reads, in the order shown: what each is and its unit. Its 1-sigma
#: is ``sigma[field]``, or ``<field without unit>_sigma_deg`` (the angle of a unit vector).
_QUANTITIES: dict[str, tuple[str, str]] = {
    "tcp_mm": ("TCP in the flange frame (X, Y, Z)", "mm"),
    "pivot_mm": ("reference tip in the robot base (X, Y, Z)", "mm"),
    "direction": ("track direction in the robot base (unit vector X, Y, Z)", "1"),
    "scale": ("track scale (measured / commanded travel)", "1"),
    "offset_mm": ("carriage offset: robot base in L at track 0 (X, Y, Z)", "mm"),
    "rotation_source": ("rotation of the robot on the carriage", ""),
    "axis": ("rotation axis Z_B (unit vector X, Y, Z)", "1"),
    "radius_mm": ("radius of the touched point about the axis", "mm"),
    "tilt_deg": ("tilt of the axis from vertical", "deg"),
    "height_mm": ("origin above the touched point (height)", "mm"),
    "spread_deg": ("arc covered by the touches", "deg"),
    "tilt_point_mm": ("point of the tilt axis at the common normal (X, Y, Z)", "mm"),
    "tilt_axis": ("tilt axis direction (unit vector X, Y, Z)", "1"),
    "rotate_point_mm": ("point of the rotate axis at the common normal, tilt at 0 (X, Y, Z)", "mm"),
    "rotate_axis": ("rotate axis direction, tilt at 0 (unit vector X, Y, Z)", "1"),
    "normal_length_mm": ("length of the common normal of the two axes", "mm"),
    "axis_angle_deg": ("angle between the two axes", "deg"),
    "tilt_zero_deg": ("zero of the tilt axis", "deg"),
    "rotate_zero_deg": ("zero of the rotate axis", "deg"),
    "rotation_determined": ("orientation determined by the touches", ""),
}

#: How well the touches fit, in the order shown.
_QUALITY: dict[str, tuple[str, str]] = {
    "rms_mm": ("residual RMS", "mm"), "max_mm": ("largest residual", "mm"),
    "mean_mm": ("mean residual", "mm"), "min_mm": ("smallest residual", "mm"),
    "condition": ("condition number (below 100: the touches determine every quantity)", ""),
}

_DECIMALS = {"mm": 3, "deg": 4, "": 1}


def _numbers(v: Any, unit: str) -> str:
    """A value or list of values with the decimals of its unit (mm 3, deg 4, none 1, else 6)."""
    if isinstance(v, bool) or not isinstance(v, (int, float, list)):
        return fmt(v)
    values = v if isinstance(v, list) else [v]
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in values):
        return fmt(v)
    d = _DECIMALS.get(unit, 6)
    return ", ".join(fmt(float(x)) if x != 0 and abs(x) < 10.0 ** -d else f"{x:.{d}f}"
                     for x in values)


def _row(name: str, value: str, sigma: str, unit: str) -> str:
    return (f"<tr><th>{html.escape(name)}</th><td>{value}</td><td>{sigma}</td>"
            f"<td>{html.escape(unit)}</td></tr>")


def _result_rows(result: dict[str, Any]) -> tuple[str, set[str], set[str]]:
    """Rows (quantity, value, 1-sigma, unit) of the result, and the fields and sigmas used."""
    sigma = result.get("sigma") or {}
    used: set[str] = set()
    used_sigma: set[str] = set()
    rows = []
    match = next((m for m in map(_POSE_KEY.fullmatch, [*result, *sigma]) if m), None)
    xyzabc = result.get("xyzabc")
    if xyzabc is None and is_points(result.get("rotation"), 3) and is_points(
            [result.get("offset_mm")], 1):  # the track: the robot base on the carriage
        R = np.array(result["rotation"], dtype=float)
        if np.allclose(R @ R.T, np.eye(3), atol=1e-6) and np.linalg.det(R) > 0:
            T = np.eye(4)
            T[:3, :3], T[:3, 3] = R, np.array(result["offset_mm"]) * 1e-3
            xyzabc = pose_to_vendor(T, "kuka").tolist()
            used |= {"rotation", "offset_mm"}
    if isinstance(xyzabc, list) and len(xyzabc) == 6:
        a, b = (("a", "b") if match is None else
                (_FRAME_NAMES.get(match[1], match[1]), _FRAME_NAMES.get(match[2], match[2])))
        key = None if match is None else f"T_{match[1]}_{match[2]}"
        pos, rot = (sigma.get(f"{key}_position_mm"), sigma.get(f"{key}_rotation_deg"))
        used_sigma |= {f"{key}_position_mm", f"{key}_rotation_deg"}
        v = xyzabc
        rows.append(_row(f"position of {b} in {a} (X, Y, Z)", _numbers(v[:3], "mm"),
                         "not available" if pos is None else _numbers(pos, "mm"), "mm"))
        rows.append(_row(f"orientation of {b} in {a} (A, B, C; R = Rz(A) Ry(B) Rx(C))",
                         _numbers(v[3:], "deg"), "not available" if rot is None else
                         f"{_numbers(rot, 'deg')} (about X, Y, Z of {a})", "deg"))
        used |= {"matrix", "tcp_mm"}  # the TCP is the position of this pose
    for field, (name, unit) in _QUANTITIES.items():
        if field not in result or field in used:
            continue
        value = result[field]
        if field == "axis" and isinstance(value, str):
            name, unit = "axis of the track frame L along the rail", ""
        angle = result.get(field.removesuffix("_mm").removesuffix("_deg") + "_sigma_deg")
        if field in sigma:
            err = _numbers(sigma[field], unit)
            if angle is not None:
                err += f" (direction: {_numbers(angle, 'deg')} deg)"
        elif angle is not None:
            err = f"{_numbers(angle, 'deg')} deg (direction)"
        else:
            err = ""
        used |= {field, f"{field}_sigma_deg", field.removesuffix("_mm") + "_sigma_deg"}
        used_sigma.add(field)
        rows.append(_row(name, _numbers(value, unit), err, unit))
    return "".join(rows), used, used_sigma


def _sigma_bases(result: dict[str, Any]) -> str:
    """A list: per quantity what its 1-sigma is relative to and made of
    (:func:`~robotcell.calibration.sigmaparts.sigma_basis`), with its parts when it inherits
    errors (``sigma_relative_to`` and ``sigma_parts`` of the JSON)."""
    frames = result.get("sigma_relative_to")
    given = result.get("sigma_parts")
    every = given if isinstance(given, dict) else {}
    items = []
    for key, frame in (frames.items() if isinstance(frames, dict) else ()):
        parts = every.get(key) if isinstance(every.get(key), dict) else {}
        present = [p for p in PARTS if p in parts]
        try:
            lines = part_lines(parts) if set(present) - {"own"} else []
        except (TypeError, ValueError, KeyError):  # a hand-edited file: the total alone
            lines = []
        text = f"{key}: 1-sigma {sigma_basis(str(frame), present)}"
        sub = "".join(f"<li>{html.escape(line)}</li>" for line in lines[1:])
        items.append(f"<li>{html.escape(text + ('; ' + lines[0] if lines else ''))}"
                     + (f"<ul>{sub}</ul>" if sub else "") + "</li>")
    return f"<ul class=\"basis\">{''.join(items)}</ul>" if items else ""


def _quality_rows(result: dict[str, Any]) -> str:
    rows = [_row("touches", str(len(result["residuals_mm"])), "", "")]
    rows += [_row(name, _numbers(result[k], unit), "", unit)
             for k, (name, unit) in _QUALITY.items() if result.get(k) is not None]
    return "".join(rows)


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
    resid = _figure_residuals(result)
    grade, reasons = verdict(result)
    proc = html.escape(str(result["procedure"]))

    def head(key: str) -> str:
        units = [u for suffix, u in _UNITS.items() if key.endswith(suffix)]
        return html.escape(key) + "".join(f"<br><small>{html.escape(u)}</small>" for u in units)

    quantities, used, used_sigma = _result_rows(result)
    internals = {k: v for k, v in result.items()
                 if k not in _SKIP and k not in used and k not in _QUALITY}
    internals.update({f"sigma.{k}": v for k, v in (result.get("sigma") or {}).items()
                      if k not in used_sigma})
    given = result.get("verdict")
    internals.update({f"verdict.{k}": v for k, v in (given if isinstance(given, dict) else {})
                      .items() if k not in ("level", "reasons")})
    appendix = "".join(f"<tr><th>{head(k)}</th><td>{fmt(v)}</td></tr>"
                       for k, v in internals.items())
    labels = result.get("labels") or [str(i + 1) for i in range(len(result["residuals_mm"]))]
    xyz = result.get("residuals_xyz_mm") or [[float("nan")] * 3] * len(labels)
    touches = "".join(
        f"<tr><td>{html.escape(str(lab))}</td><td>{r:.4f}</td><td>{fmt(list(v))}</td></tr>"
        for lab, r, v in zip(labels, result["residuals_mm"], xyz))
    def items(key: str) -> str:
        vals = result.get(key) or []
        return "<ul>" + "".join(f"<li>{html.escape(str(v))}</li>" for v in vals) + "</ul>" if vals else "<p>none</p>"

    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>robotcell report: {proc}</title>
<style>{CSS}</style><script>{SCRIPT}</script></head>
<body>
<h1>Calibration report: {proc}</h1>
<div class="verdict {grade}"><b>{grade.upper()}</b>: {html.escape('; '.join(reasons))}</div>
<h2>Next step</h2><p>{html.escape(str(result.get('next_step') or ''))}</p>
<h2>Result</h2>
<table class="result"><tr><th>quantity</th><th>value</th><th>1-sigma</th><th>unit</th></tr>
{quantities or '<tr><td colspan="4">no calibrated quantity</td></tr>'}</table>
{_sigma_bases(result)}
<h2>Fit quality</h2>
<table class="result"><tr><th>quantity</th><th>value</th><th></th><th>unit</th></tr>
{_quality_rows(result)}</table>
<h2>Not determined by the measurements</h2>{items('undetermined')}
<h2>Warnings</h2>{items('warnings')}
<h2>Figures</h2>
{SCENE_SLOT}
<figure><img src="{resid}" alt="residual per touch"></figure>
<h2>Residuals per touch</h2>
<table><tr><th>touch</th><th>|residual| (mm)</th><th>x, y, z (mm)</th></tr>{touches}</table>
<h2>Appendix: fit internals</h2>
<p>For checking the computation (redundancy, noise estimate, covariance, matrices); the result
above is all that is needed to use the calibration.</p>
<table>{appendix}</table>
</body></html>
"""
    room = MAX_PAGE_BYTES - len(page.encode())
    atomic_write(out, page.replace(SCENE_SLOT, _scene(result, room), 1))
    return [out]
