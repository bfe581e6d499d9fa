"""What each calibration procedure reads from a measurement table: columns, roles, units, counts.

One :class:`TableSpec` per procedure (:data:`SPECS`) says which columns its measurement table
has, the role of each (what it is), its unit in the table (the vendor boundary: mm, deg), which
values column ``point`` takes, and the fewest touches the procedure can use. Everything that
reads, writes or counts touches takes them from here: the reader of measurement tables
(:func:`robotcell.calibration.measurements.read_touch_table`, and with it the warning about
columns a procedure does not use), the tables :mod:`robotcell.studies.simulate` writes, and the
estimators' and the simulation's smallest counts. A column added to a procedure here is read,
known and written by all of them.

Roles (:data:`ROLES`): ``pose`` (the touch itself: TCP positions ``x, y, z`` or flange poses
``x, y, z, a, b, c``, or the arm's joint values ``a1..an``), ``axis`` (the value of the external
axis the procedure calibrates, ``e1..en``), ``track`` (the robot's track position at each
touch, mapped through a cell), ``point`` (what each touch touched, by name), ``reference``
(which of the given reference points each touch touched, by number), ``nominal`` (known
coordinates of the touched point).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Literal

from robotcell.errors import InputError

__all__ = ["JOINT_COLUMNS", "POSE_COLUMNS", "ROLES", "SPECS", "Column", "TableSpec", "add",
           "remove", "result_procedures"]

#: The roles of the columns of a measurement table.
ROLES = ("pose", "axis", "track", "point", "reference", "nominal")

#: Joint value columns of a touch (deg; mm for a prismatic joint), for arms of up to 9 axes.
JOINT_COLUMNS = tuple(f"a{i}" for i in range(1, 10))

#: Columns that make a touch: a flange or TCP pose (mm, deg) or the arm's joint values.
POSE_COLUMNS = ("x", "y", "z", "a", "b", "c") + JOINT_COLUMNS


@dataclass(frozen=True)
class Column:
    """One column of a measurement table.

    Attributes
    ----------
    name : str
        Lower-case name in the table's header.
    role : {"axis", "track", "point", "reference", "nominal"}
        What it holds (:data:`ROLES`; the pose columns are :attr:`TableSpec.pose`).
    unit : {"mm", "deg", ""}
        Its unit in the table; ``""`` for text.
    meaning : str
        What it holds, for documentation and messages.
    decimals : int
        Decimals when a table is written (:mod:`robotcell.studies.simulate`); 0 for text.
    check : {"table", "workpiece"}, optional
        How values in the wrong unit show (see
        :func:`robotcell.calibration.measurements.external_axis`): ``"table"``, every angle
        within +-2 pi (radians); ``"workpiece"``, the same unless every angle is 0.
    """

    name: str
    role: Literal["axis", "track", "point", "reference", "nominal"]
    unit: Literal["mm", "deg", ""]
    meaning: str
    decimals: int = 3
    check: Literal["table", "workpiece"] | None = None


@dataclass(frozen=True)
class TableSpec:
    """The measurement table of one calibration procedure.

    Attributes
    ----------
    name : str
        As :mod:`robotcell.cell.calibrate` and the command line name it (``"turntable"``).
    pose : {"tcp", "flange"}
        What the pose columns of a touch give: the TCP position ``x, y, z`` (mm, robot base)
        or the flange pose ``x, y, z, a, b, c`` (KUKA, mm and deg, no tool active); or either
        through the joint values ``a1..an``.
    columns : tuple of Column
        The other columns, in the order a written table has them.
    points : tuple of str
        The values column ``point`` takes; empty when it holds numbers (the track's reference
        points ``1..K``) or is not a column.
    default_point : str, optional
        The point of every touch of a table without column ``point``; None: the column is
        required (unless nominal coordinates replace it).
    required_points : tuple of str
        Points each of which must be touched at least once.
    minimum : int
        Fewest touches the procedure can use (of :attr:`counted_point`, when given).
    counted : str
        What :attr:`minimum` counts, plural, for messages.
    counted_point : str, optional
        Only touches of this point count.
    unused : mapping of str to str
        Columns the procedure refuses rather than ignores, each with the rest of the message
        after ``column 'NAME'`` (what it is and why it is refused; ``{procedure}`` stands for
        the procedure as the caller names it).
    results : tuple of str
        The ``procedure`` its estimators write into a result
        (:attr:`~robotcell.calibration.result.CalibrationResult.procedure`), e.g.
        ``("frame-3point", "frame-npoint")``; default its :attr:`name`.
    """

    name: str
    pose: Literal["tcp", "flange"]
    columns: tuple[Column, ...] = ()
    points: tuple[str, ...] = ()
    default_point: str | None = None
    required_points: tuple[str, ...] = ()
    minimum: int = 3
    counted: str = "touches"
    counted_point: str | None = None
    unused: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    results: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not self.results:
            object.__setattr__(self, "results", (self.name,))

    def role(self, role: str) -> tuple[Column, ...]:
        """The columns of ``role``, in table order."""
        return tuple(c for c in self.columns if c.role == role)

    @property
    def names(self) -> tuple[str, ...]:
        """Every column the procedure reads: the pose columns, then :attr:`columns`."""
        return POSE_COLUMNS + tuple(c.name for c in self.columns)

    @property
    def known(self) -> tuple[str, ...]:
        """The columns a table of the procedure may hold without a warning: :attr:`names` and
        the refused :attr:`unused` ones (which get their own message)."""
        return self.names + tuple(self.unused)

    def with_axes(self, n: int) -> TableSpec:
        """The same procedure with ``n`` axis columns ``e1..en`` (as its first axis column):
        a workpiece on a positioner chain of ``n`` axes."""
        axes = self.role("axis")
        if not axes or len(axes) == n:
            return self
        first = axes[0]
        more = tuple(replace(first, name=f"e{i + 1}", meaning=f"value of axis {i + 1}",
                             check=None) for i in range(n))
        i = self.columns.index(first)
        rest = tuple(c for c in self.columns if c.role != "axis")
        return replace(self, columns=rest[:i] + more + rest[i:])

    def point_text(self) -> str:
        """The values of column ``point``, e.g. ``"origin, x or xy"``."""
        return (", ".join(self.points[:-1]) + " or " + self.points[-1] if len(self.points) > 1
                else "".join(self.points))


def _track_column() -> Column:
    return Column("track", "track", "mm", "track position of the robot at each touch")


def _point(meaning: str, role: Literal["point", "reference"] = "point") -> Column:
    return Column("point", role, "", meaning, decimals=0)


_E1_TABLE = "table angle at each touch"
_NOMINAL = tuple(Column(f"nominal_{a}", "nominal", "mm", f"known {a} of the touched point in "
                        "the frame being calibrated") for a in "xyz")

_SPECS = {
    "tcp": TableSpec(
        "tcp", "flange", (_track_column(), _point("tcp, -x, xy or world")),
        points=("tcp", "-x", "xy", "world"), default_point="tcp", counted_point="tcp",
        counted="touches of the reference point (point=tcp)"),
    "frame": TableSpec(
        "frame", "tcp", (_track_column(), _point("origin, x or xy"), *_NOMINAL),
        points=("origin", "x", "xy"), required_points=("origin", "x", "xy"), counted="points",
        results=("frame-3point", "frame-npoint")),
    "external-tcp": TableSpec(
        "external-tcp", "tcp", (_point("tcp, x or xy"),), points=("tcp", "x", "xy"),
        default_point="tcp", counted_point="tcp", counted="touches of the fixed TCP",
        unused=MappingProxyType({"track": (
            "(track position of each touch) is not used by {procedure}: touch the "
            "fixed tool with the track at one position and remove the column")})),
    "track": TableSpec(
        "track", "tcp", (Column("e1", "axis", "mm", "track position at each touch"),
                         _point("number 1..K of the reference point touched", "reference")),
        unused=MappingProxyType({"track": (
            "(track position of each touch) is not used by {procedure}: its track "
            "positions are column e1")})),
    "turntable": TableSpec(
        "turntable", "tcp", (Column("e1", "axis", "deg", _E1_TABLE, 4, "table"),
                             _track_column())),
    "workpiece": TableSpec(
        "workpiece", "tcp", (Column("e1", "axis", "deg", _E1_TABLE, 4, "workpiece"),
                             _track_column(), _point("origin, x or xy")),
        points=("origin", "x", "xy"), required_points=("origin", "x", "xy")),
    "positioner": TableSpec(
        "positioner", "tcp", (Column("e1", "axis", "deg", "tilt (axis 1) at each touch", 4),
                              Column("e2", "axis", "deg", "rotate (axis 2) at each touch", 4),
                              _track_column()),
        counted="touches that turn one axis alone", results=("positioner-2axis",)),
}

#: The procedures, by name (read-only; :func:`add` and :func:`remove` change it).
SPECS: Mapping[str, TableSpec] = MappingProxyType(_SPECS)


def add(spec: TableSpec) -> None:
    """Add the table of a procedure defined outside this module (a plug-in), so that its
    results are known (:func:`result_procedures`).

    The registry of procedures (:func:`robotcell.cell.calibrate.registry.register`) calls it;
    the specifications above are the built-in procedures'.

    Raises
    ------
    InputError
        A procedure of that name, or a result name, is known already.
    """
    if spec.name in _SPECS:
        raise InputError(f"a procedure named {spec.name!r} is known already")
    taken = set(spec.results) & set(result_procedures())
    if taken:
        raise InputError(f"procedure {spec.name!r}: results named {', '.join(sorted(taken))} "
                         "are written by another procedure already")
    _SPECS[spec.name] = spec


def remove(name: str) -> None:
    """Remove the table of a procedure that :func:`add` added (nothing when unknown)."""
    _SPECS.pop(name, None)


#: Results of calibrations between robots, each from two robots' touch files with a command of
#: its own (``calibrate robot-to-robot``), not a procedure of one touch file in :data:`SPECS`.
BETWEEN_ROBOTS = ("robot-to-robot",)


def result_procedures() -> tuple[str, ...]:
    """The ``procedure`` of every result robotcell's calibrations write, in the order of
    :data:`SPECS` (e.g. ``"frame-3point"`` of the frame procedure), then
    :data:`BETWEEN_ROBOTS`."""
    return (*(r for spec in _SPECS.values() for r in spec.results), *BETWEEN_ROBOTS)
