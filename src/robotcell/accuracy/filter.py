"""Filtering poses: what to tell a controller with a nominal model so that the real arm goes there.

A controller computes joint values from a Cartesian pose with its nominal model. The real arm,
the identified one, puts the TCP elsewhere by the nominal model's error (0.5-3 mm on an
industrial arm). Filtering turns this around, as calibration products do (RoboDK's
``FilterTarget``; KUKA's absolutely accurate robot, ABB's Absolute Accuracy inside the
controller): for each desired pose,

1. the configuration is the one the nominal arm would use for it: the one with the given flags
   (KUKA S/T, ABB confdata, FANUC CONFIG, or the solver's own shoulder, elbow, wrist of
   :mod:`robotcell.ik.config`, which every arm type has: a Universal Robots controller has no
   flags), else its solution nearest to given reference joints (URScript's ``qnear``), else to
   the robot's home;
2. the identified arm's IK in that configuration gives the joint values that put the real TCP on
   the desired pose (the identified arm's branches are refined from the nominal's, so the branch
   is the same);
3. the nominal FK of those joints is the pose to command: the controller's own IK of it, in that
   configuration, gives those joints back.

A correction above ``max_correction`` (default 5 mm) is refused: no real arm is that far off its
drawing, the identified model is wrong (another robot, a unit error). Besides the commanded pose
:func:`filter_poses` predicts, per pose, the TCP error without filtering (the identified arm at
the joints the controller computes for the desired pose) and, for a model that carries the
identification's covariance, the 3D RMS of the filtered position's error (base, constants and
model error: :func:`robotcell.identification.uncertainty.position_sigma`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.calibration.sigmaparts import sigma_basis
from robotcell.cell import Cell
from robotcell.cell.ik import CellIKSolutions
from robotcell.cell.kinematics import robot_pose, tool_pose
from robotcell.controllers.model import Config
from robotcell.errors import InputError, RobotcellError
from robotcell.identification.uncertainty import position_error
from robotcell.ik.config import ARM_FLAGS, branch_of_flags, flags_of_branch
from robotcell.ik.select import nearest
from robotcell.kinematics.transforms import invert, validate_pose
from robotcell.programs.config import config_text, select
from robotcell.robot.robot import Robot

__all__ = ["MAX_CORRECTION", "MAX_ROTATION", "SIGMA_RELATIVE_TO", "FilterRefused", "FilteredPoses",
           "filter_poses", "identified_joints", "refuse", "sigma_text", "too_large"]

#: Largest position correction taken (m): beyond it the identified model is wrong.
MAX_CORRECTION = 5e-3
#: Largest orientation correction taken (rad).
MAX_ROTATION = math.radians(1.0)
#: What the predicted error of a filtered point is relative to (JSON ``sigma_relative_to``):
#: the measuring device's frame the identification located the arm in.
SIGMA_RELATIVE_TO = "device"


def sigma_text() -> str:
    """What the predicted 1-sigma of a filtered point is relative to and made of, as printed:
    the arm's identification alone (docs/accuracy.md, "How good it will be")."""
    return (sigma_basis(SIGMA_RELATIVE_TO, own="the arm's identification")
            + ", not the tool's and frames' calibrations")


class FilterRefused(RobotcellError):
    """Poses or points that cannot be filtered; ``points`` name each and say why.

    Attributes
    ----------
    points : list of (str, str)
        ``("pose 3", why)``, or the point's name in a program (``"XP7 (line 12)"``).
    """

    def __init__(self, message: str, points: list[tuple[str, str]]) -> None:
        super().__init__(message)
        self.points = points


@dataclass
class FilteredPoses:
    """The result of :func:`filter_poses` (SI units).

    Attributes
    ----------
    T : ndarray, shape (N, 4, 4)
        Poses to command, in the frame of the desired poses (m).
    q : ndarray, shape (N, n)
        The joint values the controller computes for them, which put the real TCP on the
        desired poses (rad, m).
    track : ndarray, shape (N,)
        Track positions (m; 0 without a track).
    table : ndarray, shape (N,) or (N, k)
        Table angle or positioner axis values (rad).
    dpos, drot : ndarray, shape (N,)
        Size of the correction: distance (m) and angle (rad) from the desired to the commanded pose.
    error, error_rot : ndarray, shape (N,)
        Predicted TCP error without filtering: where the identified arm takes the joints the
        controller computes for the desired pose, against it (m, rad).
    sigma : ndarray, shape (N,)
        3D RMS of the filtered TCP position's error (the RMS length of the error the
        identification's covariance and model error predict, m); NaN when the identified
        model carries no covariance.
    branch : ndarray of int, shape (N,)
        The IK branch (configuration) used.
    flags : ndarray of int, shape (N, 3)
        Its shoulder, elbow, wrist flags (:func:`robotcell.ik.config.flags_of_branch`).
    sigma_axes : ndarray, shape (N, 3)
        1-sigma of the filtered TCP position's error along the robot base's x, y, z (m); NaN
        without a covariance.
    radius95 : ndarray, shape (N,)
        Radius that holds the filtered TCP position's error with 95 % probability (m); NaN
        without a covariance.
    """

    T: NDArray[np.float64]
    q: NDArray[np.float64]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    dpos: NDArray[np.float64]
    drot: NDArray[np.float64]
    error: NDArray[np.float64]
    error_rot: NDArray[np.float64]
    sigma: NDArray[np.float64]
    branch: NDArray[np.int_]
    flags: NDArray[np.int_]
    sigma_axes: NDArray[np.float64] | None = None
    radius95: NDArray[np.float64] | None = None


def _angles(A: NDArray[np.float64], B: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation angle from ``A`` to ``B`` per pose, shape (N,) (rad)."""
    return Rotation.from_matrix(np.swapaxes(A[:, :3, :3], -1, -2) @ B[:, :3, :3]).magnitude()


def too_large(dpos: NDArray[np.float64], drot: NDArray[np.float64], done: NDArray[np.bool_],
              max_correction: float, max_rotation: float) -> list[tuple[int, str]]:
    """``(index, why)`` of the corrections above the limits (m, rad) among ``done``."""
    return [(int(i), (f"the correction is {dpos[i] * 1e3:.3f} mm, {math.degrees(drot[i]):.4f} "
                      f"deg, above the {max_correction * 1e3:g} mm, "
                      f"{math.degrees(max_rotation):g} deg a real arm can be off its nominal model: "
                      "the identified model is wrong (another robot, another unit?)"))
            for i in np.flatnonzero(done & ((dpos > max_correction) | (drot > max_rotation)))]


def refuse(refused: list[tuple[int, str]], what: str, names: list[str] | None = None) -> None:
    """Raise :class:`FilterRefused` naming each refused item (``what`` 1-based, or by ``names``)."""
    if not refused:
        return
    labelled = [(names[i] if names is not None else f"{what} {i + 1}", why)
                for i, why in sorted(refused)]
    text = "; ".join(f"{label}: {why}" for label, why in labelled[:10])
    more = f" (and {len(labelled) - 10} more)" if len(labelled) > 10 else ""
    raise FilterRefused(f"{len(labelled)} {what}(s) cannot be filtered: {text}{more}", labelled)


def _flags_text(flags: NDArray[np.int_]) -> str:
    """``shoulder 1, elbow 0, wrist 1``."""
    return ", ".join(f"{name} {int(v)}" for name, v in zip(ARM_FLAGS, flags))


def _nominal_branch(ctrl: Cell, sol: CellIKSolutions, config: list[Config] | ArrayLike | None,
                    near: NDArray[np.float64] | None
                    ) -> tuple[NDArray[np.float64], NDArray[np.int_]]:
    """The nominal arm's solution per pose and its branch: the given flags (a vendor's, or the
    solver's shoulder, elbow, wrist), on the equivalent nearest ``near`` (else home)."""
    robot = ctrl.robot
    home = robot.home if robot.home is not None else np.zeros(robot.n_joints)
    ref = np.broadcast_to(home, sol.q.shape[:-2] + home.shape) if near is None else near
    if config is None:
        q, _, branch = nearest(robot, sol, ref)
        return q, branch
    if isinstance(config, list) and all(isinstance(c, Config) for c in config):
        vendors = {c.vendor for c in config}
        if len(vendors) != 1:
            raise InputError(f"config: the flags of one vendor, got {sorted(vendors)}")
        wanted = np.array([c.values for c in config])
        q, found, _ = select(robot, sol.q, sol.reachable, wanted, vendors.pop(), near)
        _, _, branch = nearest(robot, sol, np.where(found[:, None], q, 0.0))
        return q, np.where(found, branch, -1)
    k = branch_of_flags(sol.method, config)
    mine = np.arange(sol.valid.shape[-1]) == k[:, None]
    q, _, branch = nearest(robot, replace(sol, valid=sol.valid & mine), ref)
    return q, branch


def _polish(robot: Robot, q: NDArray[np.float64], T: NDArray[np.float64], steps: int = 2
            ) -> NDArray[np.float64]:
    """Newton steps of ``robot`` from ``q`` onto the flange poses ``T`` (robot base frame).

    The seeded IK stops within 1e-9 m and rad; two steps bring that to rounding, so that the
    commanded poses take the real arm onto the desired ones to 1e-12 m. Directions of the
    Jacobian weaker than 1e-6 of its strongest (a singular wrist) get no step: a residual of
    1e-9 there must not turn an axis.
    """
    eye = np.eye(4)
    for _ in range(steps):
        T_cur = robot.fk(q, tool=eye)
        dp = T[:, :3, 3] - T_cur[:, :3, 3]
        dw = Rotation.from_matrix(T[:, :3, :3] @ np.swapaxes(T_cur[:, :3, :3], -1, -2)).as_rotvec()
        J = robot.jacobian(q, tool=eye)
        step = np.linalg.pinv(J, rcond=1e-6)
        q = q + np.einsum("nij,nj->ni", step, np.concatenate([dp, dw], axis=-1))
    return q


def identified_joints(cell: Cell, T_R_F: ArrayLike, q_nominal: ArrayLike
                      ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.int_]]:
    """The identified arm's joints for flange poses, in the nominal joints' configuration.

    Parameters
    ----------
    cell : Cell
        A cell with an identified arm.
    T_R_F : array_like, shape (N, 4, 4)
        Desired flange poses in the robot base frame (m).
    q_nominal : array_like, shape (N, n)
        The nominal arm's joints for them (rad, m): their IK branch is the configuration kept.

    Returns
    -------
    q : ndarray, shape (N, n)
        The identified arm's solution on the same branch nearest to ``q_nominal``, refined to
        rounding (rad, m; 0 where none).
    found : ndarray of bool, shape (N,)
        The identified arm reaches the pose on that branch within the limits.
    branch : ndarray of int, shape (N,)
        That branch (-1 where the nominal joints are on none).
    """
    T = np.asarray(T_R_F, dtype=float)
    q_nom = np.nan_to_num(np.asarray(q_nominal, dtype=float))
    eye = np.eye(4)
    nominal = cell.nominal_robot
    _, known, branch = nearest(nominal, nominal.ik(T, tool=eye), q_nom)
    ident = cell.robot.ik(T, tool=eye)
    same = ident.valid & (np.arange(ident.valid.shape[-1]) == branch[:, None])
    q, found, _ = nearest(cell.robot, replace(ident, valid=same), q_nom)
    found &= known
    return _polish(cell.robot, np.where(found[:, None], q, 0.0), T), found, branch


def _reference(near: ArrayLike | None, n: int, n_joints: int) -> NDArray[np.float64] | None:
    """Reference joints per pose as an ``(n, n_joints)`` array, or None."""
    if near is None:
        return None
    ref = np.asarray(near, dtype=float)
    if ref.shape != (n, n_joints) or not np.isfinite(ref).all():
        raise InputError(f"near must give {n_joints} finite joint values per pose, shape "
                         f"({n}, {n_joints}), got {ref.shape}")
    return ref


def _unreached(config: list[Config] | NDArray[np.int_] | None, i: int) -> str:
    """Why pose ``i`` has no nominal solution: the flags asked for, or the limits."""
    if config is None:
        return "the nominal arm does not reach it within the axis limits"
    text = (config_text(config[i]) if isinstance(config[i], Config)
            else _flags_text(np.asarray(config[i])))
    return f"the nominal arm does not reach it with the flags given ({text})"


def filter_poses(cell: Cell, T: ArrayLike, frame: str = "world", tool: str | ArrayLike | None = None,
                 track: ArrayLike | None = None, table: ArrayLike = 0.0,
                 config: list[Config] | ArrayLike | None = None, near: ArrayLike | None = None,
                 max_correction: float = MAX_CORRECTION,
                 max_rotation: float = MAX_ROTATION) -> FilteredPoses:
    """The poses to command so that the real (identified) arm reaches the desired ones.

    Parameters
    ----------
    cell : Cell
        A cell with an identified arm (``cell.identified``; its ``robot`` is the real arm, its
        nominal the controller's model).
    T : array_like, shape (N, 4, 4)
        Desired TCP poses ``T_X_TCP`` in frame ``frame`` (m).
    frame : str
        ``world`` or a frame of the cell.
    tool : str or array_like of shape (4, 4), optional
        A tool of the cell, or ``T_F_TCP`` (m); default the robot model's tool.
    track : array_like, shape (N,), optional
        Track positions (m); default chosen per pose by the nominal arm (a cell with a track).
    table : array_like, shape (N,) or (N, k)
        Table angles or positioner axis values (rad).
    config : list of Config, or array_like of int with shape (N, 3), optional
        The configuration per pose: a controller's flags
        (:class:`robotcell.controllers.model.Config`, one vendor), or the solver's shoulder,
        elbow, wrist flags, 0 or 1 (:mod:`robotcell.ik.config`; every arm type, a UR arm too).
        Default: the nominal arm's solution nearest to ``near``.
    near : array_like, shape (N, n), optional
        Reference joints per pose (rad, m; URScript's ``qnear``): the solution nearest to them
        (among those with the flags ``config`` gives), each axis on its 2*pi-equivalent nearest
        them. Default the robot's home.
    max_correction, max_rotation : float
        Largest correction taken (m, rad; default 5 mm and 1 deg).

    Returns
    -------
    FilteredPoses

    Raises
    ------
    InputError
        A cell without an identified arm, bad poses, flags or reference joints, an unknown tool
        or frame.
    FilterRefused
        A pose the nominal arm does not reach in its configuration, one the identified arm
        cannot reach in that configuration, or a correction above the limits; each is named.
    """
    if cell.identified is None:
        raise InputError("the cell has no identified arm (robot.identified): filtering needs "
                         "the arm as it is beside the controller's nominal model")
    Tq = validate_pose(T, "desired poses")
    if Tq.ndim != 3:
        raise InputError(f"desired poses must have shape (N, 4, 4), got {Tq.shape}")
    n = Tq.shape[0]
    if config is not None and len(config) != n:
        raise InputError(f"config must give the flags of each pose ({n}), got {len(config)}")
    ctrl = cell.controller()
    ref = _reference(near, n, ctrl.robot.n_joints)
    T_tool = tool_pose(cell, tool)
    T_F_TCP = cell.robot.tool if T_tool is None else T_tool
    nom = ctrl.ik(Tq, frame, track, table, T_tool)
    q_nom, branch = _nominal_branch(ctrl, nom, config, ref)
    track_, table_ = nom.track, nom.table
    T_R_F = (invert(robot_pose(cell, track_)) @ cell.frame_pose(frame, track_, table_) @ Tq
             @ invert(T_F_TCP))
    q, found, _ = identified_joints(cell, T_R_F, q_nom)
    refused = [(int(i), _unreached(config, i)) for i in np.flatnonzero(branch < 0)]
    refused += [(int(i), ("the identified arm cannot reach it in the configuration the nominal "
                          "arm uses (within the axis limits)"))
                for i in np.flatnonzero((branch >= 0) & ~found)]
    T_cmd = ctrl.fk(q, track_, table_, tool=T_tool, frame=frame)
    dpos = np.linalg.norm(T_cmd[:, :3, 3] - Tq[:, :3, 3], axis=-1)
    drot = _angles(Tq, T_cmd)
    refused += too_large(dpos, drot, found, max_correction, max_rotation)
    refuse(refused, "pose")
    T_real = cell.fk(np.nan_to_num(q_nom), track_, table_, tool=T_tool, frame=frame)
    error = np.linalg.norm(T_real[:, :3, 3] - Tq[:, :3, 3], axis=-1)
    error_rot = _angles(Tq, T_real)
    if cell.robot.covariance is None:
        sigma, axes, r95 = np.full(n, np.nan), np.full((n, 3), np.nan), np.full(n, np.nan)
    else:
        predicted = position_error(cell.robot, q, T_F_TCP)
        sigma, axes, r95 = predicted.rms, predicted.per_axis, predicted.radius(0.95)
    return FilteredPoses(T_cmd, q, np.asarray(track_, dtype=float), np.asarray(table_, dtype=float),
                         dpos, drot, error, error_rot, sigma, branch,
                         flags_of_branch(nom.method, branch), axes, r95)
