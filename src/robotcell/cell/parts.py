"""The parts of a robot cell, in SI units: track, turntable or positioner, tools, frames, the
provenance of each calibrated value, and an identified arm beside its nominal.

External axes that carry the work are a :class:`Turntable` (one axis, the lecture's ``R_T_B
Rz(theta)``) or a :class:`Positioner`: a chain of 1-3 revolute axes written as a DH
:class:`~robotcell.robot.robot.Robot` whose ``base`` is the root pose, the form an identified chain
takes. Both offer the same kinematic interface (:attr:`Turntable.chain`, ``T_root_P``,
``axis_values``, ``within_limits``), which is all coupled kinematics and the exports use.

The cell that holds them is :class:`robotcell.cell.model.Cell`; the cell file reads and writes
them (:mod:`robotcell.cell.schema`).
"""

from __future__ import annotations

import datetime as _dt
import math
import re
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import axischain, kinematics
from robotcell.cell.kinematics import RESERVED_FRAMES
from robotcell.errors import InputError
from robotcell.kinematics.bounds import within
from robotcell.kinematics.transforms import finite_array, validate_pose
from robotcell.robot.robot import Joint, Robot

__all__ = ["DEFAULT_ROBOT", "IDENTIFIED_MAX_ANGLE", "IDENTIFIED_MAX_OFFSET", "NAME_RE", "CellRobot",
           "Frame", "IdentifiedArm", "Positioner", "Provenance", "Tool", "Track", "Turntable",
           "check_identified", "check_name", "single_pose", "unique_numbers"]

#: Names of tools and frames: a letter, then letters, digits or underscores, at most 24 in all
#: (KUKA keeps 24 characters of a tool or base name; RAPID identifiers allow 32).
NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,23}$")


# -- provenance -----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Provenance:
    """Where a calibrated value comes from, and how uncertain it is.

    Attributes
    ----------
    source : str
        ``"nominal"`` (design value), ``"manual"`` (typed in) or the calibration procedure that
        produced the value (``"tcp"``, ``"frame"``, ``"track"``, ``"turntable"``,
        ``"workpiece"``, ...).
    time : str or None
        When it was produced, ISO 8601 (``2025-03-14T09:30:00+01:00``).
    rms_mm : float or None
        Residual RMS of the calibration (mm).
    note : str
        Free text (operator, number of points, instrument).
    id : str or None
        Name of this calibration as an error source: the values calibrated later with this one
        (a turntable touched with this tool) carry its share under this name.
    measurements : str or None
        The touch file the calibration read (a path; written relative to the cell file).
    sha256 : str or None
        SHA-256 of that file's bytes when it was read, to tell a changed file.
    options : dict
        The calibration's options, to repeat it (``robotcell calibrate cell``): units of the
        command line (mm, deg), e.g. ``{"tool": "pointer", "sigma_mm": 0.1}``.
    inputs : tuple of str
        The items of the cell the calibration used (``tools.pointer``, ``track``,
        ``turntable``), in the order of their parameters.
    sources : dict of str to ndarray
        Error sources of the value (see :class:`robotcell.calibration.uncertainty.Sources`):
        per source a factor over the value's parameters (SI: origin m, rotation vector rad
        about the parent's axes, then the scale of a track). Empty: no uncertainty recorded.
    """

    source: str = "nominal"
    time: str | None = None
    rms_mm: float | None = None
    note: str = ""
    id: str | None = None
    measurements: str | None = None
    sha256: str | None = None
    options: dict[str, Any] = field(default_factory=dict)
    inputs: tuple[str, ...] = ()
    sources: dict[str, NDArray[np.float64]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.source, str) or not self.source.strip():
            raise InputError("provenance source must be a non-empty string")
        if self.time is not None:
            _iso_time(self.time, "provenance time")
        if self.rms_mm is not None and not (math.isfinite(self.rms_mm) and self.rms_mm >= 0):
            raise InputError(f"provenance rms_mm must be a finite number >= 0, got {self.rms_mm}")
        sizes = {np.shape(f)[0] for f in self.sources.values()}
        if len(sizes) > 1 or any(np.ndim(f) != 2 or not np.all(np.isfinite(f))
                                 for f in self.sources.values()):
            raise InputError("provenance sources must be finite matrices with one row per "
                             "parameter of the value")

    @classmethod
    def now(cls, source: str, rms_mm: float | None = None, note: str = "",
            **fields: Any) -> Provenance:
        """Provenance stamped with the current local time (ISO 8601, seconds, with UTC offset)."""
        stamp = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
        return cls(source=source, time=stamp, rms_mm=rms_mm, note=note, **fields)


def _iso_time(value: str, where: str) -> str:
    try:
        _dt.datetime.fromisoformat(value)
    except (TypeError, ValueError):
        raise InputError(f"{where} must be an ISO 8601 time like 2025-03-14T09:30:00+01:00, "
                         f"got {value!r}") from None
    return value


# -- components -----------------------------------------------------------------------------------
def single_pose(T: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = validate_pose(T, name)
    if arr.shape != (4, 4):
        raise InputError(f"{name} must be a single pose of shape (4, 4), got {arr.shape}")
    return arr.copy()


def _limits(lower: float, upper: float, what: str) -> None:
    if not (isinstance(lower, (int, float)) and isinstance(upper, (int, float))):
        raise InputError(f"{what} limits must be numbers")
    if not lower < upper:
        raise InputError(f"{what}: lower limit {lower} must be below upper limit {upper}")


@dataclass
class Track:
    """A linear track carrying the robot.

    ``T_L_R(e) = T_L_R0`` with its translation moved by ``e * scale * axis``: the lecture's
    ``p = x + L_Q_R f`` with ``x = e * scale * axis`` and ``L_Q_R`` the rotation of ``T_L_R0``.

    Attributes
    ----------
    T_world_L : ndarray, shape (4, 4)
        Pose of the track frame L in the world (metres).
    T_L_R0 : ndarray, shape (4, 4)
        Pose of the robot base R in L at track position 0 (metres); its rotation is the
        lecture's alignment error ``L_Q_R``, its translation the mounting offset.
    axis : {"x", "y", "z"}
        Axis of L the robot moves along (``x`` in the lecture; KUKA's linear units use ``z``).
    scale : float
        Displacement per unit of the controller's track value (1 for a true encoder).
    lower, upper : float
        Limits of the controller's track value (metres).
    name : str
        Name of the mechanical unit (used by controller exports, e.g. ABB ``TRACK_1``).
    provenance : Provenance
    """

    T_world_L: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    T_L_R0: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    axis: Literal["x", "y", "z"] = "x"
    scale: float = 1.0
    lower: float = -math.inf
    upper: float = math.inf
    name: str = "track"
    provenance: Provenance = field(default_factory=Provenance)

    def __post_init__(self) -> None:
        self.T_world_L = single_pose(self.T_world_L, "track T_world_L")
        self.T_L_R0 = single_pose(self.T_L_R0, "track T_L_R0")
        if self.axis not in ("x", "y", "z"):
            raise InputError(f"track axis must be 'x', 'y' or 'z', got {self.axis!r}")
        if not (math.isfinite(self.scale) and self.scale > 0):
            raise InputError(f"track scale must be a finite number > 0, got {self.scale}")
        _limits(self.lower, self.upper, "track")

    @property
    def direction(self) -> NDArray[np.float64]:
        """Unit vector of the motion in L, shape ``(3,)``."""
        return np.eye(3)["xyz".index(self.axis)]

    def T_L_R(self, e: ArrayLike) -> NDArray[np.float64]:
        """Pose of the robot base in L at track positions ``e`` (shape ``(...)``, metres)."""
        return kinematics.track_pose(self.T_L_R0, self.direction * self.scale, e)

    def within_limits(self, e: ArrayLike) -> NDArray[np.bool_]:
        """Whether track positions ``e`` (shape ``(...)``, metres) are within the limits (up to
        rounding, :data:`robotcell.kinematics.bounds.LIMIT_TOL`)."""
        return within(e, self.lower, self.upper)


@dataclass
class Turntable:
    """A one-axis turntable (rotary positioner).

    ``T_parent_W(theta) = T_parent_B Rz(theta) T_B_W`` for a frame W carried by the table: the
    lecture's ``R_T_W(theta) = R_T_B Rz(theta) B_T_W``. Positive table values turn about +Z_B.

    Attributes
    ----------
    T_parent_B : ndarray, shape (4, 4)
        Pose of the table root frame B (origin on the axis, Z along it) in its parent (metres).
    parent : {"world", "robot"}
        ``world``: fixed in the cell; ``robot``: fixed to the robot base R (moves with a track).
    lower, upper : float
        Limits of the table angle (radians).
    name : str
        Name of the mechanical unit (KUKA ``MACHINE_DEF`` name, ABB ``ufmec``).
    provenance : Provenance
    """

    T_parent_B: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    parent: Literal["world", "robot"] = "world"
    lower: float = -math.inf
    upper: float = math.inf
    name: str = "turntable"
    provenance: Provenance = field(default_factory=Provenance)

    def __post_init__(self) -> None:
        self.T_parent_B = single_pose(self.T_parent_B, "turntable T_parent_B")
        if self.parent not in ("world", "robot"):
            raise InputError(f"turntable parent must be 'world' or 'robot', got {self.parent!r}")
        _limits(self.lower, self.upper, "turntable")

    def within_limits(self, theta: ArrayLike) -> NDArray[np.bool_]:
        """Whether table angles ``theta`` (shape ``(...)``, radians) are within the limits (up to
        rounding, :data:`robotcell.kinematics.bounds.LIMIT_TOL`)."""
        return within(theta, self.lower, self.upper)

    # -- the interface shared with Positioner ----------------------------------------------------
    n_axes = 1

    @property
    def T_parent_root(self) -> NDArray[np.float64]:
        """Pose of the root frame B in the parent (metres): ``T_parent_B``."""
        return self.T_parent_B

    @property
    def chain(self) -> Robot:
        """The table as a 1-axis DH chain: base ``T_parent_B``, one revolute joint about Z_B."""
        return Robot(self.name, (Joint("revolute", lower=self.lower, upper=self.upper,
                                       name=f"{self.name}_axis"),), base=self.T_parent_B)

    def axis_values(self, theta: ArrayLike) -> NDArray[np.float64]:
        """Table angles as an array of shape ``(...)`` (radians), refusing NaN and infinity."""
        return finite_array(theta, "table angle")

    def batch_shape(self, theta: NDArray[np.float64]) -> tuple[int, ...]:
        """Batch shape of table angles: their shape."""
        return theta.shape

    def T_root_P(self, theta: ArrayLike) -> NDArray[np.float64]:
        """The table's turn ``Rz(theta)``, shape ``(..., 4, 4)``: frames on the table move with it."""
        return kinematics.table_pose(theta)


@dataclass
class Positioner:
    """A positioner: a chain of 1-3 revolute axes carrying the work (tilt-rotate, L, drop-centre).

    ``T_parent_P(v) = chain.fk(v)`` with the chain's ``base`` the root pose ``T_parent_0`` and its
    ``flange`` the plate frame P on the last axis, which carries the frames with parent
    ``turntable``. Axis values ``v`` have shape ``(..., n)``, radians, as the controller counts
    them (``sign`` and offsets of the DH table apply). A turntable is the 1-axis case with
    ``a = alpha = d = theta = 0``.

    Attributes
    ----------
    chain : Robot
        The axes as a DH chain (standard or modified), base = root pose in the parent (metres),
        limits on each axis (radians); e.g. the result of a kinematic identification.
    parent : {"world", "robot"}
        ``world``: fixed in the cell; ``robot``: fixed to the robot base R (moves with a track).
    name : str
        Name of the mechanical unit (KUKA ``MACHINE_DEF`` name, ABB mechanical unit).
    provenance : Provenance
    """

    chain: Robot
    parent: Literal["world", "robot"] = "world"
    name: str = "positioner"
    provenance: Provenance = field(default_factory=Provenance)

    def __post_init__(self) -> None:
        if not isinstance(self.chain, Robot):
            raise InputError("positioner chain must be a robotcell.Robot (a DH chain)")
        if not 1 <= self.chain.n_joints <= 3 or np.any(self.chain.prismatic):
            raise InputError(f"a positioner is a chain of 1 to 3 revolute axes, got "
                             f"{self.chain.n_joints} axes "
                             f"({', '.join(j.type for j in self.chain.joints)})")
        if self.parent not in ("world", "robot"):
            raise InputError(f"positioner parent must be 'world' or 'robot', got {self.parent!r}")
        self._axes = self.chain.with_base(np.eye(4))

    @property
    def n_axes(self) -> int:
        """Number of axes (1 to 3)."""
        return self.chain.n_joints

    @property
    def T_parent_root(self) -> NDArray[np.float64]:
        """Pose of the root frame (frame 0 of the chain) in the parent (metres)."""
        return self.chain.base

    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower axis limits, shape ``(n,)`` (radians)."""
        return self.chain.lower

    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper axis limits, shape ``(n,)`` (radians)."""
        return self.chain.upper

    def axis_values(self, values: ArrayLike) -> NDArray[np.float64]:
        """Axis values as an array of shape ``(..., n)`` (radians).

        A single number is every axis of a 1-axis positioner; of a longer chain only 0 (every
        axis at 0, the default of the kinematic functions) is taken, any other is refused.
        """
        v = finite_array(values, "positioner axis value")
        if v.ndim == 0:
            if self.n_axes > 1 and v != 0:
                raise InputError(f"positioner {self.name!r} has {self.n_axes} axes: give one "
                                 f"value per axis, shape (..., {self.n_axes}), not the single "
                                 f"value {float(v):g} rad")
            return np.broadcast_to(v, (self.n_axes,))
        if v.shape[-1] != self.n_axes:
            raise InputError(f"positioner {self.name!r} has {self.n_axes} axes: give its axis "
                             f"values with shape (..., {self.n_axes}), got {v.shape}")
        return v

    def batch_shape(self, values: NDArray[np.float64]) -> tuple[int, ...]:
        """Batch shape of axis values ``(..., n)``: ``(...)``."""
        return values.shape[:-1]

    def T_root_P(self, values: ArrayLike) -> NDArray[np.float64]:
        """Pose of the plate P in the root at axis values ``(..., n)``, shape ``(..., 4, 4)``."""
        return self._axes.fk(self.axis_values(values), np.eye(4))

    def within_limits(self, values: ArrayLike) -> NDArray[np.bool_]:
        """Whether axis values ``(..., n)`` are all within their limits (up to rounding,
        :data:`robotcell.kinematics.bounds.LIMIT_TOL`), shape ``(...)``."""
        return np.all(within(self.axis_values(values), self.lower, self.upper), axis=-1)

    def normal_up(self, normal: ArrayLike, T_world_parent: ArrayLike | None = None
                  ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Axis values of a 2-axis positioner that turn a plate direction straight up.

        Parameters
        ----------
        normal : array_like, shape (..., 3)
            Direction in the plate frame P (e.g. a weld's surface normal).
        T_world_parent : array_like, shape (..., 4, 4), optional
            Pose of the positioner's parent in the world (the robot base for ``parent="robot"``);
            default the world itself.

        Returns
        -------
        values : ndarray, shape (..., 2, 2)
            Up to two solutions (v_1, v_2), radians (NaN where none).
        valid : ndarray of bool, shape (..., 2)
            Solution exists and lies within the axis limits.
        """
        T = np.eye(4) if T_world_parent is None else np.asarray(T_world_parent, dtype=float)
        R = T[..., :3, :3] @ self.chain.base[:3, :3]
        return axischain.normal_up(self.chain, R, normal)


@dataclass
class Tool:
    """A tool on the robot flange.

    Attributes
    ----------
    T_F_TCP : ndarray, shape (4, 4)
        Pose of the TCP in the flange frame F of the cell's robot model (metres).
    number : int or None
        Controller slot (KUKA ``TOOL_DATA[n]``, Fanuc ``UTOOL[n]``); None: numbered in file order.
    mass : float or None
        Mass of the tool (kg), for controllers that need load data (ABB ``tload``).
    cog : ndarray, shape (3,), or None
        Centre of gravity in the flange frame (metres).
    provenance : Provenance
    """

    T_F_TCP: NDArray[np.float64]
    number: int | None = None
    mass: float | None = None
    cog: NDArray[np.float64] | None = None
    provenance: Provenance = field(default_factory=Provenance)

    def __post_init__(self) -> None:
        self.T_F_TCP = single_pose(self.T_F_TCP, "tool T_F_TCP")
        _check_number(self.number, "tool number")
        if self.mass is not None and not (math.isfinite(self.mass) and self.mass > 0):
            raise InputError(f"tool mass must be a finite number > 0 (kg), got {self.mass}")
        if self.cog is not None:
            cog = np.asarray(self.cog, dtype=float)
            if cog.shape != (3,) or not np.all(np.isfinite(cog)):
                raise InputError(f"tool cog must be 3 finite numbers, got {self.cog!r}")
            self.cog = cog


@dataclass
class Frame:
    """A named frame of the cell: a fixture, a base, a workpiece.

    Attributes
    ----------
    pose : ndarray, shape (4, 4)
        Pose of the frame in its parent (metres): ``T_world_X``, ``T_R_X`` or ``T_B_X`` (for a
        frame on the turntable, at table angle 0).
    parent : str
        What carries the frame: ``world`` (nothing: fixed in the world), ``robot`` (the robot
        base of a one-robot cell: moves with the track), ``turntable`` (turns with it), or, in a
        cell of several robots, the name of the robot whose base carries it.
    number : int or None
        Controller slot (KUKA ``BASE_DATA[n]``, Fanuc ``UFRAME[n]``); None: numbered in order.
    provenance : Provenance
    """

    pose: NDArray[np.float64]
    parent: str = "world"
    number: int | None = None
    provenance: Provenance = field(default_factory=Provenance)

    def __post_init__(self) -> None:
        self.pose = single_pose(self.pose, "frame pose")
        if self.parent not in ("world", "robot", "turntable") and not (
                isinstance(self.parent, str) and NAME_RE.match(self.parent)):
            raise InputError(f"frame parent must be 'world', 'robot', 'turntable' or the name of "
                             f"a robot of the cell, got {self.parent!r}")
        _check_number(self.number, "frame number")


def _check_number(n: Any, what: str) -> None:
    if n is not None and (isinstance(n, bool) or not isinstance(n, int) or n < 1):
        raise InputError(f"{what} must be an integer >= 1, got {n!r}")


#: Largest distance (m) and angle (rad) between the flange of an identified arm and its nominal's
#: at any configuration: a real arm is a few mm and tenths of a degree off its drawing, so a larger
#: difference is a model of another robot (or in other joint conventions).
IDENTIFIED_MAX_OFFSET = 0.05
IDENTIFIED_MAX_ANGLE = math.radians(5.0)


@dataclass
class IdentifiedArm:
    """The arm as an identification found it, beside the model its controller computes with.

    Attributes
    ----------
    nominal : Robot
        The controller's model (``robot.model`` of the cell file): it turns joint values into the
        Cartesian points a program is told.
    model : str
        The identified model file (absolute, or relative to the working directory).
    provenance : Provenance
        Where the identification comes from (``identify``, its time, RMS, held-out error).
    """

    nominal: Robot
    model: str
    provenance: Provenance = field(default_factory=lambda: Provenance("manual"))


def check_identified(nominal: Robot, identified: Robot) -> None:
    """Refuse an identified model that is not an identification of ``nominal``.

    Parameters
    ----------
    nominal, identified : Robot

    Raises
    ------
    InputError
        Another number or type of joints, another joint coupling (a J2/J3 factor; a scale of an
        axis may differ by up to 1 %), or a flange more than 50 mm or 5 deg from the nominal's
        at a configuration within the limits (the name says which).
    """
    who = f"the identified model {identified.name!r} is not an identification of {nominal.name!r}"
    if identified.n_joints != nominal.n_joints or len(identified.joints) != len(nominal.joints):
        raise InputError(f"{who}: it has {identified.n_joints} axes, {nominal.name} has "
                         f"{nominal.n_joints}")
    kinds = [(j.type, j.passive) for j in nominal.joints]
    if [(j.type, j.passive) for j in identified.joints] != kinds:
        raise InputError(f"{who}: its joint types differ "
                         f"({', '.join(j.type for j in identified.joints)})")
    eye = np.eye(len(nominal.joints), nominal.n_joints)
    C0 = eye if nominal.coupling is None else nominal.coupling.matrix
    C1 = eye if identified.coupling is None else identified.coupling.matrix
    if np.abs(C1 - C0).max() > 0.01:
        i, j = np.unravel_index(np.argmax(np.abs(C1 - C0)), C0.shape)
        raise InputError(f"{who}: its joint coupling differs (q_model = C q: C[{i + 1}, {j + 1}] is "
                         f"{C1[i, j]:g}, the nominal's {C0[i, j]:g}; a J2/J3 factor?)")
    lo = np.where(np.isfinite(nominal.lower), nominal.lower, -math.pi)
    hi = np.where(np.isfinite(nominal.upper), nominal.upper, math.pi)
    q = np.vstack([np.clip(np.zeros(nominal.n_joints), lo, hi),
                   lo + (hi - lo) * np.random.default_rng(0).random((24, nominal.n_joints))])
    T0, T1 = nominal.fk(q, tool=np.eye(4)), identified.fk(q, tool=np.eye(4))
    dp = np.linalg.norm(T1[:, :3, 3] - T0[:, :3, 3], axis=-1)
    cos = (np.trace(np.swapaxes(T0[:, :3, :3], -1, -2) @ T1[:, :3, :3], axis1=-2, axis2=-1) - 1) / 2
    da = np.arccos(np.clip(cos, -1.0, 1.0))
    k = int(np.argmax(np.maximum(dp / IDENTIFIED_MAX_OFFSET, da / IDENTIFIED_MAX_ANGLE)))
    if dp[k] > IDENTIFIED_MAX_OFFSET or da[k] > IDENTIFIED_MAX_ANGLE:
        raise InputError(f"{who}: its flange is {dp[k] * 1e3:.1f} mm and {math.degrees(da[k]):.2f} "
                         f"deg from the nominal's at joints "
                         f"{np.round(np.degrees(q[k]), 1).tolist()} deg (a real arm is a few mm "
                         f"off; at most {IDENTIFIED_MAX_OFFSET * 1e3:g} mm and "
                         f"{math.degrees(IDENTIFIED_MAX_ANGLE):g} deg are taken)")


def check_name(name: Any, what: str) -> None:
    """Refuse a tool or frame name that is not :data:`NAME_RE`, or a reserved frame name.

    Parameters
    ----------
    name : str
    what : {"tool", "frame", "robot"}
        What the name is of, for the message (frames and robots may not take the names of
        :data:`~robotcell.cell.kinematics.RESERVED_FRAMES`).

    Raises
    ------
    InputError
    """
    if not isinstance(name, str) or not NAME_RE.match(name):
        raise InputError(f"{what} name {name!r} is invalid: use a letter, then letters, digits "
                         "or '_', at most 24 characters")
    if what in ("frame", "robot") and name in RESERVED_FRAMES:
        raise InputError(f"{what} name {name!r} is reserved (reserved: "
                         f"{', '.join(sorted(RESERVED_FRAMES))})")


def unique_numbers(numbers: dict[str, int | None], what: str) -> None:
    """Refuse two items with the same controller number.

    Parameters
    ----------
    numbers : dict of str to int or None
        Controller number of each named item (None: numbered in order).
    what : str
        What the items are (``tool``, ``frame``), for the message.

    Raises
    ------
    InputError
        Naming the two items and their number.
    """
    seen: dict[int, str] = {}
    for name, n in numbers.items():
        if n is None:
            continue
        if n in seen:
            raise InputError(f"{what}s {seen[n]!r} and {name!r} have the same number {n}")
        seen[n] = name


#: The name of the robot of a one-robot cell (a cell file with ``robot:``, not ``robots:``).
DEFAULT_ROBOT = "robot"


@dataclass
class CellRobot:
    """One robot of a cell: its arm, where it stands (a track or a fixed base), its tools.

    A cell holds one or several (:attr:`robotcell.cell.Cell.robots`); each has its own
    controller, so tool numbers are unique per robot.

    Attributes
    ----------
    robot : Robot
        The arm. Its default tool applies when FK gets no tool.
    model : str
        How the cell file names the arm: a library name, or a model file path.
    T_world_R : ndarray, shape (4, 4)
        Pose of the robot base in the world for a robot without track (metres).
    track : Track or None
        The linear track carrying this robot (it then places the robot).
    tools : dict of str to Tool
        This robot's tools (``T_F_TCP`` in its flange frame).
    identified : IdentifiedArm or None
        Set when ``robot`` is an identified arm (see :class:`robotcell.cell.Cell`).
    base_provenance : Provenance
        Where ``T_world_R`` comes from (``nominal``, or e.g. a robot-to-robot calibration).
    """

    robot: Robot
    model: str
    T_world_R: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    track: Track | None = None
    tools: dict[str, Tool] = field(default_factory=dict)
    identified: IdentifiedArm | None = None
    base_provenance: Provenance = field(default_factory=Provenance)

    def __post_init__(self) -> None:
        self.T_world_R = single_pose(self.T_world_R, "robot T_world_R")
        if self.identified is not None:
            check_identified(self.identified.nominal, self.robot)
            if not np.array_equal(self.robot.tool, self.identified.nominal.tool):
                self.robot = self.robot.with_tool(self.identified.nominal.tool)
            if self.robot.ik_seed is None:  # a model from another tool: the nominal seeds its IK
                self.robot = replace(self.robot, ik_seed=self.identified.nominal)
        if self.track is not None and not np.allclose(self.T_world_R, np.eye(4), atol=0):
            raise InputError("a robot on a track is placed by the track (track frame and "
                             "robot_at_zero); do not give the robot a frame as well")
        for name in self.tools:
            check_name(name, "tool")
        unique_numbers({k: t.number for k, t in self.tools.items()}, "tool")

    @property
    def nominal_robot(self) -> Robot:
        """The model the controller computes with: the nominal of an identified arm, else ``robot``."""
        return self.robot if self.identified is None else self.identified.nominal

    def controller(self) -> CellRobot:
        """This robot as its controller computes it: with the nominal arm."""
        if self.identified is None:
            return self
        return replace(self, robot=self.identified.nominal, identified=None)

    def T_world_R0(self) -> NDArray[np.float64]:
        """Pose of the robot base in the world at track position 0 (metres), shape ``(4, 4)``."""
        if self.track is None:
            return self.T_world_R
        return self.track.T_world_L @ self.track.T_L_R0
