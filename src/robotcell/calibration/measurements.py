"""Measurement tables (CSV columns, vendor units) to SI arrays for the calibration procedures.

The CSV contract (see ``docs/calibration.md``): a header line; lengths in millimetres, angles in
degrees. Column names are case-insensitive.

- TCP positions in the robot base frame: ``x, y, z`` (mm), or joint values ``a1..an`` (deg; mm
  for prismatic joints) together with a robot model and the tool that was active.
- Flange poses (tool calibration): ``x, y, z, a, b, c`` (KUKA: ``R = Rz(A) Ry(B) Rx(C)``) or
  ``a1..an`` with a robot model (the flange pose is computed with no tool).
- ``e1``: external axis value, mm for a linear track, deg for a turntable.
- ``track``: track position of the robot at each touch (mm), for procedures whose touches are
  mapped through a cell file (``--cell``); the track calibration itself uses ``e1``.
- ``point``: the role of a touch in a 3-point frame (``origin``, ``x``, ``xy``).
- ``nominal_x, nominal_y, nominal_z``: known coordinates of a touched point in the frame being
  calibrated (mm), for N-point frames.

Columns come from :func:`robotcell.io.tables.read_csv` (lower-cased names; numeric columns as
float arrays, others as lists of strings).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.io.tables import outside_limits
from robotcell.robot.robot import Robot

__all__ = [
    "MM_LOOKS_LIKE_M",
    "check_count",
        "external_axis",
    "flange_poses",
    "joint_columns",
    "nominal_points",
    "point_roles",
    "repeated_rows",
    "tcp_positions",
    "track_column",
]

#: When every length in a column set stays below this many millimetres, the file is taken to be
#: in metres by mistake: a robot workspace written in mm spans hundreds of millimetres.
MM_LOOKS_LIKE_M = 5.0

Columns = Mapping[str, Any]


def _numeric(cols: Columns, names: Sequence[str], source: str) -> NDArray[np.float64]:
    missing = [n for n in names if n not in cols]
    if missing:
        raise InputError(f"{source}: missing column(s) {', '.join(missing)} "
                         f"(have: {', '.join(cols) or 'none'})")
    out = []
    for n in names:
        v = cols[n]
        if not isinstance(v, np.ndarray):
            bad = next((c for c in v if not _is_number(c)), v[0] if v else "")
            raise InputError(f"{source}: column '{n}' must be numeric, found {bad!r}")
        if not np.all(np.isfinite(v)):
            raise InputError(f"{source}: column '{n}' contains NaN or infinite values; "
                             "re-record or delete that touch")
        out.append(np.asarray(v, dtype=float))
    return np.stack(out, axis=1)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _check_mm(values: NDArray[np.float64], what: str, source: str) -> None:
    if values.size and np.max(np.abs(values)) < MM_LOOKS_LIKE_M:
        raise InputError(
            f"{source}: every {what} value is below {MM_LOOKS_LIKE_M:g} in magnitude, which looks "
            "like metres; the CSV must be in millimetres (multiply by 1000)"
        )


def check_count(n: int, minimum: int, what: str, source: str) -> None:
    """Refuse fewer than ``minimum`` measurements.

    Parameters
    ----------
    n : int
        Number of measurements given.
    minimum : int
        Smallest number the procedure can use.
    what : str
        What the measurements are, plural, for the message (e.g. ``"touches of the reference
        point"``); the message reads ``"<source>: <what>: <n> given, at least <minimum> needed"``.
    source : str
        File name or description, prefixed to the message.
    """
    if n < minimum:
        raise InputError(f"{source}: {what}: {n} given, at least {minimum} needed "
                         f"(more than {minimum} give a redundancy check and uncertainties)")


def repeated_rows(rows: NDArray[np.float64], source: str,
                  labels: Sequence[str] | None = None) -> list[str]:
    """Notes on identical measurement rows: repeated touches are data, averaged by the fit.

    Parameters
    ----------
    rows : ndarray, shape (N, k)
        The raw values of each measurement (vendor units).
    source : str
        File name or description.
    labels : sequence of str, optional
        Name of each row for the message; defaults to CSV line numbers (header is line 1).

    Returns
    -------
    list of str
        One note per group of identical rows (empty when every row differs).
    """
    names = labels if labels is not None else [f"line {i + 2}" for i in range(len(rows))]
    groups: dict[bytes, list[int]] = {}
    for i, r in enumerate(np.asarray(rows, dtype=float)):
        groups.setdefault((np.round(r, 9) + 0.0).tobytes(), []).append(i)
    return [f"{source}: {', '.join(names[i] for i in g)} are identical; each is used as a "
            "measurement of its own (if one is a copied line, delete it)"
            for g in groups.values() if len(g) > 1]


def joint_columns(cols: Columns, robot: Robot, source: str) -> NDArray[np.float64]:
    """Joint values from columns ``a1..an`` in controller units, converted to SI.

    Parameters
    ----------
    cols : mapping
        CSV columns.
    robot : Robot
        Model whose ``n_joints``, joint types and limits set the columns, units and ranges.
    source : str

    Returns
    -------
    ndarray, shape (N, n)
        Radians for revolute joints, metres for prismatic joints.

    Raises
    ------
    InputError
        A value outside the robot's joint limits (no touch can be recorded there), naming its
        line and column.
    """
    names = [f"a{i + 1}" for i in range(robot.n_joints)]
    q = _numeric(cols, names, source)
    scale = np.where(robot.prismatic, 1e3, 180.0 / np.pi)
    units = ["mm" if p else "deg" for p in robot.prismatic]
    bad = outside_limits(q, names, robot.lower * scale, robot.upper * scale, units)
    if bad is not None:
        raise InputError(f"{source}: joint values outside the limits of {robot.name}: {bad}. A "
                         "touch is recorded within the limits: correct the value (a typing or "
                         "unit error?), or give the robot that touched")
    return np.where(robot.prismatic, q * 1e-3, np.radians(q))


def tcp_positions(cols: Columns, source: str, robot: Robot | None = None,
                  tool: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """TCP positions in the robot base frame from ``x,y,z`` or from ``a1..an`` through FK.

    Parameters
    ----------
    cols : mapping
        CSV columns.
    source : str
        File name, for messages.
    robot : Robot, optional
        Needed for joint-value input.
    tool : ndarray, shape (4, 4), optional
        ``T_F_TCP`` of the tool that touched (metres); the robot's own tool when omitted.

    Returns
    -------
    ndarray, shape (N, 3)
        Positions in metres.
    """
    if "x" in cols or "a1" not in cols and ("y" in cols or "z" in cols):
        p = _numeric(cols, ("x", "y", "z"), source)
        _check_mm(p, "x, y, z", source)
        return p * 1e-3
    if "a1" in cols:
        if robot is None:
            raise InputError(f"{source}: joint values a1..a6 need a robot model "
                             "(--robot NAME_OR_FILE) and the tool that was used (--tool X,Y,Z,A,B,C)")
        q = joint_columns(cols, robot, source)
        return robot.fk(q, tool)[:, :3, 3]
    raise InputError(f"{source}: needs TCP positions as columns x, y, z (mm) or joint values "
                     f"a1..a6 (deg) (have: {', '.join(cols) or 'none'})")


def flange_poses(cols: Columns, source: str, robot: Robot | None = None) -> NDArray[np.float64]:
    """Flange poses ``T_R_F`` from ``x,y,z,a,b,c`` (KUKA) or from ``a1..an`` through FK.

    Parameters
    ----------
    cols : mapping
        CSV columns.
    source : str
    robot : Robot, optional
        Needed for joint-value input; FK is evaluated with no tool.

    Returns
    -------
    ndarray, shape (N, 4, 4)
        Flange poses in the robot base frame (metres).
    """
    if "x" in cols or "a1" not in cols and any(k in cols for k in "yzabc"):
        v = _numeric(cols, ("x", "y", "z", "a", "b", "c"), source)
        _check_mm(v[:, :3], "flange x, y, z", source)
        return pose_from_vendor(v, "kuka")
    if "a1" in cols:
        if robot is None:
            raise InputError(f"{source}: joint values a1..a6 need a robot model (--robot NAME_OR_FILE)")
        return robot.fk(joint_columns(cols, robot, source), np.eye(4))
    raise InputError(f"{source}: needs flange poses as columns x, y, z, a, b, c (KUKA, mm and deg) "
                     f"or joint values a1..a6 (deg) (have: {', '.join(cols) or 'none'})")


def external_axis(cols: Columns, source: str, kind: str) -> NDArray[np.float64]:
    """External axis values from column ``e1``.

    Parameters
    ----------
    cols : mapping
    source : str
    kind : {"track", "table", "workpiece"}
        ``"track"``: millimetres (a track position in metres by mistake shows as a scale of
        about 1000, which the track calibration refuses). ``"table"``: degrees, refused when every
        value lies within +-2 pi (+-6.28): radians by mistake (in degrees such touches would span
        less than 6.28 deg, far below the 90 deg a table axis needs). ``"workpiece"``: degrees,
        refused likewise when every value lies within +-6.28 and one is not 0 (all touches at
        table angle 0 are a valid workpiece calibration).

    Returns
    -------
    ndarray, shape (N,)
        Metres (track) or radians (table, workpiece).
    """
    e = _numeric(cols, ("e1",), source)[:, 0]
    if kind == "track":
        return e * 1e-3
    if kind in ("table", "workpiece"):
        small = e.size and np.max(np.abs(e)) <= 2 * np.pi
        if small and (kind == "table" or np.any(e != 0)):
            tail = (f". In degrees these touches would span only {np.ptp(e):.2f} deg of table "
                    "rotation; spread them over 90 degrees or more" if kind == "table" else "")
            raise InputError(
                f"{source}: every e1 (table angle) value is within +-6.28, which looks like radians; "
                f"the CSV must be in degrees (multiply radians by 57.2958){tail}")
        return np.radians(e)
    raise InputError(f"external axis kind must be 'track', 'table' or 'workpiece', got {kind!r}")


def point_roles(cols: Columns, source: str) -> list[str]:
    """Roles of the touches of a 3-point frame from column ``point``.

    Parameters
    ----------
    cols : mapping
    source : str

    Returns
    -------
    list of str
        One of ``"origin"``, ``"x"``, ``"xy"`` per row (lower case). Each role must occur at least
        once; repeated roles are averaged by the procedure.
    """
    if "point" not in cols:
        raise InputError(f"{source}: missing column 'point' (origin, x or xy for each touch)")
    roles = [str(v).strip().lower() for v in cols["point"]]
    bad = sorted({r for r in roles if r not in ("origin", "x", "xy")})
    if bad:
        raise InputError(f"{source}: column 'point' must hold origin, x or xy; found {', '.join(bad)}")
    missing = [r for r in ("origin", "x", "xy") if r not in roles]
    if missing:
        raise InputError(f"{source}: no touch of point(s) {', '.join(missing)}; a 3-point frame needs "
                         "the origin, a point on +X and a point in the XY plane with positive Y")
    return roles


def nominal_points(cols: Columns, source: str) -> NDArray[np.float64]:
    """Known coordinates of the touched points in the frame being calibrated.

    Parameters
    ----------
    cols : mapping
        Columns ``nominal_x, nominal_y, nominal_z`` (mm).
    source : str

    Returns
    -------
    ndarray, shape (N, 3)
        Metres.
    """
    return _numeric(cols, ("nominal_x", "nominal_y", "nominal_z"), source) * 1e-3


def track_column(cols: Columns, source: str) -> NDArray[np.float64] | None:
    """Track position of the robot at each touch from the optional column ``track``.

    Parameters
    ----------
    cols : mapping
        CSV columns; ``track`` in millimetres.
    source : str

    Returns
    -------
    ndarray, shape (N,), or None
        Metres; None when the column is absent. Refused when every non-zero value is below
        :data:`MM_LOOKS_LIKE_M` (metres by mistake); all zeros is a valid column.
    """
    if "track" not in cols:
        return None
    e = _numeric(cols, ("track",), source)[:, 0]
    _check_mm(e[e != 0], "track (track position)", source)
    return e * 1e-3
