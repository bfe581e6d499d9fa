"""Measurement tables (columns in the table's units, mm and deg) to SI, once per procedure.

A table is a mapping of lower-case column name to one value per touch: numbers (a float array)
or text (a list of str), as :func:`robotcell.io.tables.read_csv` returns a CSV file with a header
(see ``docs/calibration.md``). What a procedure reads from it, the roles and units of its columns
and its fewest touches, is its :class:`~robotcell.calibration.spec.TableSpec`
(:data:`~robotcell.calibration.spec.SPECS`); :func:`read_touch_table` reads a table by it, once,
into :class:`TouchTable` (SI): the touches (TCP positions, flange poses or joint values), the
external axis values, the robot's track positions, the touched points and their known
coordinates. The column readers below (:func:`tcp_positions`, :func:`external_axis`, ...) are
its pieces, each refusing what its column cannot hold (metres or radians by mistake, values
outside the joint limits, unknown point names).

- TCP positions in the robot base frame: ``x, y, z`` (mm), or joint values ``a1..an`` (deg; mm
  for prismatic joints) together with a robot model and the tool that was active.
- Flange poses (tool calibration): ``x, y, z, a, b, c`` (KUKA: ``R = Rz(A) Ry(B) Rx(C)``) or
  ``a1..an`` with a robot model (the flange pose is computed with no tool).
- ``e1``: external axis value, mm for a linear track, deg for a turntable.
- ``track``: track position of the robot at each touch (mm), for procedures whose touches are
  mapped through a cell; the track calibration itself uses ``e1``.
- ``point``: the role of a touch in a 3-point frame (``origin``, ``x``, ``xy``).
- ``nominal_x, nominal_y, nominal_z``: known coordinates of a touched point in the frame being
  calibrated (mm), for N-point frames.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.spec import JOINT_COLUMNS, SPECS, Column, TableSpec
from robotcell.errors import InputError, term
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.io.tables import (
    empty_rows,
    outside_limits,
    refuse_empty,
    spreadsheet_number,
    unknown_columns_warning,
)
from robotcell.robot.robot import Robot

__all__ = [
    "MM_LOOKS_LIKE_M",
    "TouchTable",
    "check_count",
    "columns_of",
    "external_axis",
    "flange_poses",
    "joint_columns",
    "line_labels",
    "nominal_points",
    "point_roles",
    "read_touch_table",
    "repeated_rows",
    "tcp_positions",
    "track_column",
]

#: When every length in a column set stays below this many millimetres, the file is taken to be
#: in metres by mistake: a robot workspace written in mm spans hundreds of millimetres.
MM_LOOKS_LIKE_M = 5.0

#: Decimals of the joint values (deg, mm) in a written table.
JOINT_DECIMALS = 6

Columns = Mapping[str, Any]


@dataclass(frozen=True, eq=False)
class TouchTable:
    """The touches of one procedure, read from a measurement table, in SI units.

    Exactly one of ``points``, ``poses`` and ``joints`` holds the touches.

    Attributes
    ----------
    procedure : TableSpec
        What the table was read by (:data:`~robotcell.calibration.spec.SPECS`).
    source : str
        Name of the table in messages (its file), and of each touch by its line.
    points : ndarray, shape (N, 3), or None
        TCP positions in the robot base (m), from ``x, y, z``.
    poses : ndarray, shape (N, 4, 4), or None
        Flange poses ``T_R_F`` (m), from ``x, y, z, a, b, c`` (tool procedure).
    joints : ndarray, shape (N, n), or None
        Joint values ``a1..an`` (rad; m for prismatic joints), of ``robot``.
    robot : Robot or None
        The arm whose joint values ``joints`` are.
    axes : ndarray, shape (N, k), or None
        External axis values ``e1..ek`` (m for a track, rad for a table).
    track : ndarray, shape (N,), or None
        Track position of the robot at each touch (m), column ``track``.
    point : tuple of str, or None
        What each touch touched (column ``point`` in lower case, or the procedure's default).
    reference : ndarray, shape (N,), or None
        Number of the reference point of each touch (the track's column ``point``, 1-based).
    nominal : ndarray, shape (N, 3), or None
        Known coordinates of each touched point in the frame being calibrated (m).
    notes : tuple of str
        Remarks made while reading (columns not used, identical rows).
    """

    procedure: TableSpec
    source: str
    points: NDArray[np.float64] | None = None
    poses: NDArray[np.float64] | None = None
    joints: NDArray[np.float64] | None = None
    robot: Robot | None = None
    axes: NDArray[np.float64] | None = None
    track: NDArray[np.float64] | None = None
    point: tuple[str, ...] | None = None
    reference: NDArray[np.float64] | None = None
    nominal: NDArray[np.float64] | None = None
    notes: tuple[str, ...] = ()

    @property
    def n(self) -> int:
        """Number of touches."""
        touches = next(v for v in (self.points, self.poses, self.joints) if v is not None)
        return len(touches)

    def tcp(self, tool: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """TCP positions in the robot base (m), shape (N, 3).

        Parameters
        ----------
        tool : ndarray, shape (4, 4), optional
            ``T_F_TCP`` of the tool that touched (m), for joint values; default the robot
            model's tool. Positions ``x, y, z`` were recorded with the controller's tool.
        """
        if self.points is not None:
            return self.points
        if self.poses is not None:
            return self.poses[:, :3, 3]
        return self.robot.fk(self.joints, tool)[:, :3, 3]

    def flange(self) -> NDArray[np.float64]:
        """Flange poses ``T_R_F`` (m), shape (N, 4, 4): as given, or from the joint values."""
        if self.poses is not None:
            return self.poses
        if self.joints is None:
            raise InputError(f"{self.source}: the touches are TCP positions x, y, z, not flange "
                             "poses")
        return self.robot.fk(self.joints, np.eye(4))

    def labels(self, points: bool = False) -> list[str]:
        """Names of the touches as lines of the table (``line 2``; ``line 3 (x)`` with the
        touched points)."""
        return line_labels(self.n, self.point if points else None)

    def count(self) -> int:
        """Touches that count towards the procedure's minimum."""
        want = self.procedure.counted_point
        return self.n if want is None or self.point is None else self.point.count(want)

    def check_count(self) -> None:
        """Refuse fewer touches than the procedure's minimum (:func:`check_count`)."""
        spec = self.procedure
        check_count(self.count(), spec.minimum, spec.counted, self.source)

    def check_points(self) -> None:
        """Refuse a column ``point`` that is missing where the procedure needs it, holds names
        it does not know, or leaves out a point it needs (the origin, x and xy of a 3-point
        frame)."""
        _check_points(self.procedure, self.point, self.source)

    def table(self) -> dict[str, Any]:
        """The measurement table (mm, deg), its columns in the order of the procedure.

        Returns
        -------
        dict
            Column name to a float array (text: a list of str), as :func:`read_touch_table`
            reads it back.
        """
        out: dict[str, Any] = {}
        if self.joints is not None:
            prismatic = (np.zeros(self.joints.shape[1], dtype=bool) if self.robot is None
                         else self.robot.prismatic)
            q = np.where(prismatic, self.joints * 1e3, np.degrees(self.joints))
            out.update({f"a{i + 1}": q[:, i] for i in range(q.shape[1])})
        elif self.poses is not None:
            out.update(zip("xyzabc", pose_to_vendor(self.poses, "kuka").T))
        else:
            out.update(zip("xyz", self.points.T * 1e3))
        axes = iter(() if self.axes is None else self.axes.T)
        for c in self.procedure.columns:
            value = {"track": None if self.track is None else self.track * 1e3,
                     "point": None if self.point is None else list(self.point),
                     "reference": self.reference}.get(c.role)
            if c.role == "axis" and self.axes is not None:
                value = next(axes)
                value = value * 1e3 if c.unit == "mm" else np.degrees(value)
            elif c.role == "nominal" and self.nominal is not None:
                value = self.nominal[:, "xyz".index(c.name[-1])] * 1e3
            if value is not None:
                out[c.name] = value
        return out

    def text(self) -> tuple[list[str], list[list[str]]]:
        """The table as text: header and rows, numbers with the decimals of their column."""
        decimals = {c.name: c.decimals for c in self.procedure.columns}
        table = self.table()
        columns = []
        for name, values in table.items():
            d = JOINT_DECIMALS if name in JOINT_COLUMNS else decimals.get(name, 3)
            columns.append([str(v) for v in values] if isinstance(values, list)
                           else [f"{v:.{d}f}" for v in values])
        return list(table), [list(r) for r in zip(*columns)]


def columns_of(table: Any, source: str) -> dict[str, Any]:
    """The columns of a measurement table given in Python, checked as a CSV file is.

    Parameters
    ----------
    table : mapping
        Column name to a sequence of values, one per touch: numbers (mm, deg) or text.
    source : str
        Name of the table in messages.

    Returns
    -------
    dict
        Lower-case names; numeric columns as float arrays of equal length N, text as lists of
        str.
    """
    if not isinstance(table, Mapping) or not table:
        raise InputError(f"{source}: measurements must be a non-empty mapping of column name to "
                         "values (mm, deg), or the path of a CSV file")
    cols: dict[str, Any] = {}
    for name, values in table.items():
        if isinstance(values, str) or np.ndim(values) != 1:
            raise InputError(f"{source}: column {name!r} must be a sequence, one value per touch")
        values = list(values)
        try:
            arr = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            cols[str(name).strip().lower()] = [str(v) for v in values]
            continue
        if arr.ndim != 1 or not np.all(np.isfinite(arr)):
            raise InputError(f"{source}: column {name!r} must be one finite number per touch")
        cols[str(name).strip().lower()] = arr
    lengths = {len(v) for v in cols.values()}
    if len(lengths) != 1:
        raise InputError(f"{source}: the columns have different lengths {sorted(lengths)}")
    return cols


def read_touch_table(procedure: TableSpec | str, cols: Columns, source: str,
                      robot: Robot | None = None,
                      on_note: Callable[[str], None] | None = None) -> TouchTable:
    """Read a measurement table by a procedure's specification, into SI units.

    Parameters
    ----------
    procedure : TableSpec or str
        The procedure (or its name in :data:`~robotcell.calibration.spec.SPECS`).
    cols : mapping
        The table: lower-case column names to float arrays or lists of str, of one length (as
        :func:`robotcell.io.tables.read_csv` or :func:`columns_of` give it).
    source : str
        Name of the table in messages.
    robot : Robot, optional
        The arm, for joint values ``a1..an`` (their number, units and limits).
    on_note : callable, optional
        Receives each note as it arises: a ``warning:`` naming the columns the procedure does
        not use (a misspelt name is otherwise ignored silently), and a ``note:`` per group of
        identical rows.

    Returns
    -------
    TouchTable

    Raises
    ------
    InputError
        A column the procedure refuses (:attr:`TableSpec.unused`), missing or non-numeric pose
        or axis columns, values in metres or radians by mistake, joint values without a robot
        or outside its limits, point names the procedure does not know or points not touched.
    """
    spec = SPECS[procedure] if isinstance(procedure, str) else procedure
    notes: list[str] = []

    def note(text: str) -> None:
        notes.append(text)
        if on_note is not None:
            on_note(text)

    unused = unknown_columns_warning(source, cols, spec.known,
                                     term("procedure", f"the {spec.name} calibration"))
    if unused:
        note(unused)
    for name, why in spec.unused.items():
        if name in cols and len(empty_rows(cols[name])) < len(cols[name]):  # a value given
            procedure = term(f"procedure:{spec.name}", f"the {spec.name} calibration")
            raise InputError(f"{source}: column '{name}' {why.format(procedure=procedure)}")
    touches = _touches(cols, source, spec.pose, robot)
    n = len(next(v for v in touches.values() if v is not None))
    axes = spec.role("axis")
    values = np.stack([_axis(cols, source, c) for c in axes], axis=1) if axes else None
    nominal = None
    if spec.role("nominal") and "nominal_x" in cols:
        nominal = nominal_points(cols, source)
    point = _points(spec, cols, n, source) if spec.points else None
    reference = None
    if spec.role("reference") and "point" in cols:
        reference = _numeric(cols, ("point",), source, optional=True)[:, 0]
    track = track_column(cols, source) if spec.role("track") else None
    for text in repeated_rows(raw_rows(cols, spec.names), source):
        note(f"note: {text}")
    return TouchTable(spec, source, **touches, robot=robot, axes=values, track=track,
                        point=point, reference=reference, nominal=nominal, notes=tuple(notes))


def _touches(cols: Columns, source: str, pose: str, robot: Robot | None
             ) -> dict[str, NDArray[np.float64] | None]:
    """The touches of a table: ``points`` (x, y, z), ``poses`` (x..c) or ``joints`` (SI)."""
    out: dict[str, NDArray[np.float64] | None] = {"points": None, "poses": None, "joints": None}
    filled = {k for k, v in cols.items() if len(empty_rows(v)) < len(v)}
    if "a1" in filled:  # pose columns left empty beside the joint values are not given
        cols = {k: v for k, v in cols.items() if k in filled or k not in tuple("xyzabc")}
    if pose == "tcp" and ("x" in cols or "a1" not in cols and ("y" in cols or "z" in cols)):
        p = _numeric(cols, ("x", "y", "z"), source)
        _check_mm(p, "x, y, z", source)
        out["points"] = p * 1e-3
    elif pose == "flange" and ("x" in cols or "a1" not in cols
                               and any(k in cols for k in "yzabc")):
        v = _numeric(cols, ("x", "y", "z", "a", "b", "c"), source)
        _check_mm(v[:, :3], "flange x, y, z", source)
        out["poses"] = pose_from_vendor(v, "kuka")
    elif "a1" in cols:
        if robot is None:
            tool = (" and the tool that was used "
                    f"({term('tool=X,Y,Z,A,B,C', 'tool')})" if pose == "tcp" else "")
            raise InputError(f"{source}: joint values a1..a6 need a robot model "
                             f"({term('robot=NAME_OR_FILE', 'robot')}){tool}")
        out["joints"] = joint_columns(cols, robot, source)
    elif pose == "tcp":
        raise InputError(f"{source}: needs TCP positions as columns x, y, z (mm) or joint values "
                         f"a1..a6 (deg) (have: {', '.join(cols) or 'none'})")
    else:
        raise InputError(f"{source}: needs flange poses as columns x, y, z, a, b, c (KUKA, mm and "
                         f"deg) or joint values a1..a6 (deg) (have: {', '.join(cols) or 'none'})")
    return out


def _axis(cols: Columns, source: str, column: Column) -> NDArray[np.float64]:
    """One external axis column in SI: mm to m, deg to rad (checked as ``column.check`` says)."""
    if column.unit == "mm":
        return _numeric(cols, (column.name,), source)[:, 0] * 1e-3
    if column.check is not None:
        return external_axis(cols, source, column.check, column.name)
    return np.radians(_numeric(cols, (column.name,), source)[:, 0])


def _points(spec: TableSpec, cols: Columns, n: int, source: str) -> tuple[str, ...] | None:
    """Column ``point`` in lower case, the procedure's default point (also for a line that
    leaves the cell empty), or None; checked by :func:`_check_points`. A procedure without a
    default point refuses an empty cell."""
    if "point" not in cols:
        return None if spec.default_point is None else (spec.default_point,) * n
    if spec.default_point is None:
        refuse_empty(cols, ("point",), source)
    names = ["" if isinstance(v, float) and np.isnan(v) else str(v).strip().lower()
             for v in cols["point"]]
    return tuple(name or str(spec.default_point) for name in names)


def _check_points(spec: TableSpec, roles: Sequence[str] | None, source: str) -> None:
    """Refuse a column ``point`` that is missing, holds names the procedure does not know, or
    leaves out a point the procedure needs (the origin, x and xy of a 3-point frame)."""
    if roles is None:
        if spec.required_points:
            raise InputError(f"{source}: missing column 'point' ({spec.point_text()} for each "
                             "touch)")
        return
    bad = sorted({r for r in roles if r not in spec.points})
    if bad:
        raise InputError(f"{source}: column 'point' must hold {spec.point_text()}; found "
                         f"{', '.join(bad)}")
    missing = [r for r in spec.required_points if r not in roles]
    if missing:
        raise InputError(f"{source}: no touch of point(s) {', '.join(missing)}; a 3-point frame "
                         "needs the origin, a point on +X and a point in the XY plane with "
                         "positive Y")


def line_labels(n: int, roles: Sequence[str] | None = None) -> list[str]:
    """Names of the touches as lines of the CSV (``line 2``, ``line 3 (x)``, ...)."""
    if roles is None:
        return [f"line {i + 2}" for i in range(n)]
    return [f"line {i + 2} ({r})" for i, r in enumerate(roles)]


def raw_rows(cols: Columns, names: Sequence[str]) -> NDArray[np.float64]:
    """The numeric columns among ``names`` as an (N, k) array, for the repeated-row note; no
    rows when none of them is there."""
    use = [n for n in names if n in cols and isinstance(cols[n], np.ndarray)]
    return np.stack([cols[n] for n in use], axis=1) if use else np.zeros((0, 0))


def _numeric(cols: Columns, names: Sequence[str], source: str, optional: bool = False
             ) -> NDArray[np.float64]:
    """Columns ``names`` as an (N, k) float array, refused when one is missing, empty on a
    line (``optional``: a column that may be left out as a whole), or not numeric."""
    missing = [n for n in names if n not in cols]
    if missing:
        raise InputError(f"{source}: missing column(s) {', '.join(missing)} "
                         f"(have: {', '.join(cols) or 'none'})")
    refuse_empty(cols, names, source, optional)
    out = []
    for n in names:
        v = cols[n]
        if not isinstance(v, np.ndarray):
            bad = next((i for i, c in enumerate(v) if spreadsheet_number(str(c)) is None), 0)
            raise InputError(f"{source}: line {bad + 2}: column '{n}' must be numeric, found "
                             f"{v[bad] if v else ''!r}")
        if not np.all(np.isfinite(v)):
            raise InputError(f"{source}: column '{n}' contains NaN or infinite values; "
                             "re-record or delete that touch")
        out.append(np.asarray(v, dtype=float))
    return np.stack(out, axis=1)


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
    names = labels if labels is not None else line_labels(len(rows))
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
    touches = _touches(cols, source, "tcp", robot)
    if touches["points"] is not None:
        return touches["points"]
    return robot.fk(touches["joints"], tool)[:, :3, 3]


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
    touches = _touches(cols, source, "flange", robot)
    if touches["poses"] is not None:
        return touches["poses"]
    return robot.fk(touches["joints"], np.eye(4))


def external_axis(cols: Columns, source: str, kind: str, column: str = "e1"
                  ) -> NDArray[np.float64]:
    """External axis values from column ``e1`` (or ``column``).

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
    column : str
        The column.

    Returns
    -------
    ndarray, shape (N,)
        Metres (track) or radians (table, workpiece).
    """
    e = _numeric(cols, (column,), source)[:, 0]
    if kind == "track":
        return e * 1e-3
    if kind in ("table", "workpiece"):
        small = e.size and np.max(np.abs(e)) <= 2 * np.pi
        if small and (kind == "table" or np.any(e != 0)):
            tail = (f". In degrees these touches would span only {np.ptp(e):.2f} deg of table "
                    "rotation; spread them over 90 degrees or more" if kind == "table" else "")
            raise InputError(
                f"{source}: every {column} (table angle) value is within +-6.28, which looks like "
                "radians; "
                f"the CSV must be in degrees (multiply radians by 57.2958){tail}")
        return np.radians(e)
    raise InputError(f"external axis kind must be 'track', 'table' or 'workpiece', got {kind!r}")


def point_roles(cols: Columns, source: str) -> list[str]:
    """Roles of the touches of a 3-point frame from column ``point`` (as a frame reads it).

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
    spec = SPECS["frame"]
    roles = _points(spec, cols, len(cols.get("point", ())), source)
    _check_points(spec, roles, source)
    return list(roles)


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
    return _numeric(cols, ("nominal_x", "nominal_y", "nominal_z"), source, optional=True) * 1e-3


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
    e = _numeric(cols, ("track",), source, optional=True)[:, 0]
    _check_mm(e[e != 0], "track (track position)", source)
    return e * 1e-3
