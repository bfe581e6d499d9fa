"""Checks of a calibration result given as JSON (mm, deg), before it is read back.

What :meth:`robotcell.calibration.result.CalibrationResult.from_json` refuses: a field missing
(:data:`REQUIRED`) or of the wrong type, an unknown ``procedure`` (one no procedure of
:data:`~robotcell.calibration.spec.SPECS` writes), a number that is not finite
(anywhere), a length (a key ending in ``_mm``, the translation of a pose) beyond
:data:`~robotcell.io.tables.MAX_ABS_VALUE` mm, a pose (:data:`POSES`; a track's ``rotation``)
that is not a rigid transform (a proper rotation), or a quantity the report draws
(:data:`GEOMETRY`) that is not a finite number or 3 of them."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robotcell.calibration.spec import result_procedures
from robotcell.io.tables import MAX_ABS_VALUE
from robotcell.kinematics.transforms import check_pose

__all__ = ["GEOMETRY", "POSES", "REQUIRED", "TOUCH_LISTS", "UNIT_VECTORS", "is_points", "malformed"]

#: Fields of a result that name touches (by their labels).
TOUCH_LISTS = ("excluded", "unchecked", "outliers", "disagreeing", "gross_outliers")

#: Fields that hold a pose (4x4, translation in mm): the result's own, and a workpiece's turntable.
POSES = ("matrix", "turntable_matrix")

#: Fields that give the geometry a result draws (the report's 3D scene), each a finite number
#: (1) or 3 of them (3) wherever it is written.
GEOMETRY = {**dict.fromkeys(["radius_mm", "height_mm", "spread_deg", "tilt_deg", "scale",
                             "normal_length_mm", "axis_angle_deg", "tilt_zero_deg",
                             "rotate_zero_deg"], 1),
            **dict.fromkeys(["tcp_mm", "offset_mm", "axis", "direction", "tilt_point_mm",
                             "tilt_axis", "rotate_point_mm", "rotate_axis"], 3)}

#: Fields of :data:`GEOMETRY` that are directions (unit vectors).
UNIT_VECTORS = ("axis", "direction", "tilt_axis", "rotate_axis")

#: Fields every result as JSON has.
REQUIRED = ("procedure", "residuals_mm", "rms_mm", "max_mm", "warnings")


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


def _is_sigma(v: Any) -> bool:
    """A finite number, or None (a 1-sigma the touches do not determine, written as null)."""
    return v is None or _is_number(v)


def is_points(v: Any, n: int | None) -> bool:
    """A list of ``n`` (any number when None) lists of 3 finite numbers."""
    return (isinstance(v, list) and (n is None or len(v) == n)
            and all(isinstance(p, list) and len(p) == 3 and all(map(_is_number, p)) for p in v))


def malformed(data: dict[str, Any]) -> str | None:
    """What is wrong with the fields of a result that the report uses, or None; a field that
    is not there is not checked (:data:`REQUIRED` says which must be)."""
    if not isinstance(data["procedure"], str):
        return "'procedure' must be a text"
    known = result_procedures()
    if data["procedure"] not in known:
        return (f"'procedure' {data['procedure']!r} is none robotcell calibrates "
                f"({', '.join(known)})")
    where = _not_finite(data, "")
    if where is not None:
        return f"{where.lstrip('.')!r} is not a finite number"
    for key, value in data.items():
        if key.endswith("_mm") and any(abs(v) > MAX_ABS_VALUE for v in _lengths(value)):
            return (f"{key!r} holds a length beyond {MAX_ABS_VALUE:.0e} mm, which no "
                    "calibration measures")
    res = data.get("residuals_mm", [])
    if not isinstance(res, list) or not all(map(_is_number, res)):
        return "'residuals_mm' must be a list of numbers"
    n = len(res) if "residuals_mm" in data else None
    for key in ("rms_mm", "max_mm"):
        if key in data and not _is_number(data[key]):
            return f"{key!r} must be a number"
    for key in ("warnings", "undetermined"):
        v = data.get(key, [])
        if (v is not None or key == "warnings") and (
                not isinstance(v, list) or not all(isinstance(w, str) for w in v)):
            return f"{key!r} must be a list of texts"
    checks = {
        "condition": lambda v: _is_number(v),
        "labels": lambda v: isinstance(v, list) and (n is None or len(v) == n)
        and all(isinstance(x, (str, int)) for x in v),
        "residuals_xyz_mm": lambda v: is_points(v, n),
        "points_mm": lambda v: is_points(v, None),
        "pivot_mm": lambda v: is_points([v], 1),
        "sigma": lambda v: isinstance(v, dict) and all(
            _is_sigma(x) or (isinstance(x, list) and all(map(_is_sigma, x))) for x in v.values()),
        **dict.fromkeys(POSES, lambda v: isinstance(v, list) and len(v) == 4 and all(
            isinstance(r, list) and len(r) == 4 and all(map(_is_number, r)) for r in v)),
        "rotation": lambda v: is_points(v, 3),
        "dof": lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0,
        **dict.fromkeys(["noise_sigma_mm", "touch_sigma_mm", "residual_sigma_mm", "chi2"],
                        _is_number),
        **dict.fromkeys(["noise_source", "accuracy_source", "next_step"],
                        lambda v: isinstance(v, str)),
        **dict.fromkeys(TOUCH_LISTS, lambda v: isinstance(v, list) and all(
            isinstance(x, (str, int)) and not isinstance(x, bool) for x in v)),
    }
    if "matrix" in data and data["matrix"] is None:
        return "'matrix' must be a 4x4 list of numbers"
    for key, ok in checks.items():
        if data.get(key) is not None and not ok(data[key]):
            return f"{key!r} has the wrong type or size"
    for key, size in GEOMETRY.items():
        if key in data and not (_is_number(data[key]) if size == 1 else is_points([data[key]], 1)):
            return (f"{key!r} must be a number" if size == 1 else
                    f"{key!r} must be a list of 3 numbers")
    for key in (k for k in UNIT_VECTORS if k in data):
        if abs(math.hypot(*data[key]) - 1.0) > 1e-6:
            return f"{key!r} must be a unit vector (a direction), its length is not 1"
    for key in (k for k in POSES if data.get(k) is not None):
        T = np.array(data[key], dtype=float)
        if np.abs(T[:3, 3]).max() > MAX_ABS_VALUE:
            return f"{key!r} holds a translation beyond {MAX_ABS_VALUE:.0e} mm"
        T[:3, 3] *= 1e-3
        ok, reasons = check_pose(T)
        if not ok:
            return f"{key!r} is not a rigid transform (R orthonormal, det R = 1): {reasons[0]}"
    if data.get("rotation") is not None:  # the track's L_Q_R
        T = np.eye(4)
        T[:3, :3] = data["rotation"]
        ok, reasons = check_pose(T)
        if not ok:
            return f"'rotation' is not a proper rotation (orthonormal, det = 1): {reasons[0]}"
    return None
