"""A six-axis arm on a linear track: forward and inverse kinematics with 7 axes.

The lecture's model (track/turntable calibration, "Usage of the linear track calibration matrix"):
the track frame L is fixed, the robot base R slides along a unit direction ``u`` of L, and at track
value ``x`` the base pose is ``T_L_R(x) = [Q, t0 + x u]`` with the mounting ``T_L_R0 = [Q, t0]``
(``Q`` is the lecture's ``L_Q_R``). Then

    p = x u + t0 + Q f,      Q_TCP = Q R_Q_TCP,

and for a target ``T_L_TCP`` and a chosen ``x`` the arm must reach
``T_R_TCP = T_L_R(x)^-1 T_L_TCP`` (the lecture's ``f = Q^-1 (p - x)``, ``R_Q_TCP = Q^-1 L_Q_TCP``):
for every track value within reach the arm has its 8 solutions. The track default is +X of L as in
the lecture; KUKA external axes move along their Z.

:meth:`TrackRobot.as_robot` writes the same system as one 7-joint DH chain whose first, prismatic
joint slides along ``u`` (a DH frame placed at the track), for numeric IK or anything that takes a
:class:`~robotcell.robot.robot.Robot`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.ik.analytic import solve
from robotcell.ik.result import IKSolutions
from robotcell.kinematics.arm import Arm, Joint
from robotcell.kinematics.bounds import within
from robotcell.kinematics.transforms import invert, make_pose, rot_x, rot_y, validate_pose

__all__ = ["TrackChoice", "TrackRobot"]


@dataclass(frozen=True)
class TrackChoice:
    """Solutions at a track value chosen by :meth:`TrackRobot.ik`.

    Attributes
    ----------
    solutions : IKSolutions
        ``q`` of shape ``(..., 8, 7)``: track value (m) then the six arm axes (rad).
    track : ndarray, shape (...)
        Chosen track value (m).
    manipulability : ndarray, shape (...)
        ``|det J|`` of the arm at the best valid branch there (0 where nothing is reachable).
    """

    solutions: IKSolutions
    track: NDArray[np.float64]
    manipulability: NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class TrackRobot:
    """A robot arm on a linear track.

    Attributes
    ----------
    arm : Arm
        The six-axis arm; its base frame R is the frame that slides.
    T_L_R0 : ndarray, shape (4, 4)
        Pose of the arm's base frame R in the track frame L at track value 0 (m).
    direction : ndarray, shape (3,)
        Direction of motion in L (normalised on construction); default +X of L.
    lower, upper : float
        Track limits (m).
    name : str
    """

    arm: Arm
    T_L_R0: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    direction: NDArray[np.float64] = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    lower: float = -math.inf
    upper: float = math.inf
    name: str = "track"

    def __post_init__(self) -> None:
        object.__setattr__(self, "T_L_R0", validate_pose(self.T_L_R0, "T_L_R0").copy())
        u = np.asarray(self.direction, dtype=float)
        if u.shape != (3,) or not np.all(np.isfinite(u)) or np.linalg.norm(u) < 1e-12:
            raise InputError(f"track direction must be a non-zero 3-vector, got {self.direction!r}")
        object.__setattr__(self, "direction", u / np.linalg.norm(u))
        if not self.lower < self.upper:
            raise InputError(f"track lower limit {self.lower} is not below upper limit {self.upper}")

    # -- kinematics ------------------------------------------------------------------------------
    def _track(self, x: ArrayLike) -> NDArray[np.float64]:
        arr = np.asarray(x, dtype=float)
        if not np.all(np.isfinite(arr)):
            raise InputError("track value contains NaN or infinite values")
        return arr

    def base_pose(self, x: ArrayLike) -> NDArray[np.float64]:
        """``T_L_R(x)``: pose of the arm's base at track values ``x`` (shape (...), m); (..., 4, 4)."""
        arr = self._track(x)
        T = np.broadcast_to(self.T_L_R0, arr.shape + (4, 4)).copy()
        T[..., :3, 3] += arr[..., None] * self.direction
        return T

    def fk(self, q: ArrayLike, tool: ArrayLike | None = None) -> NDArray[np.float64]:
        """``T_L_TCP`` for ``q = (x, q1, ..., q6)`` of shape (..., 7) (m, rad); returns (..., 4, 4)."""
        arr = np.asarray(q, dtype=float)
        if arr.ndim == 0 or arr.shape[-1] != self.arm.n_joints + 1:
            raise InputError(f"a track robot has {self.arm.n_joints + 1} axes; q must have shape "
                             f"(..., {self.arm.n_joints + 1}), got {arr.shape}")
        return self.base_pose(arr[..., 0]) @ self.arm.fk(arr[..., 1:], tool=tool)

    def ik_at(self, T: ArrayLike, x: ArrayLike, tool: ArrayLike | None = None) -> IKSolutions:
        """All arm solutions for targets in L at given track values.

        Parameters
        ----------
        T : array_like, shape (..., 4, 4)
            ``T_L_TCP`` (m).
        x : array_like, shape broadcastable to (...)
            Track values (m).
        tool : array_like, shape (4, 4), optional
            ``T_F_TCP`` instead of the arm's default tool (m).

        Returns
        -------
        IKSolutions
            ``q`` of shape ``(..., 8, 7)`` with the track value first; branches are invalid when
            ``x`` is outside the track limits.
        """
        arr = validate_pose(T, "target pose")
        xs = np.broadcast_to(self._track(x), arr.shape[:-2])
        sol = solve(self.arm, invert(self.base_pose(xs)) @ arr, tool)
        xcol = np.broadcast_to(xs[..., None, None], sol.q.shape[:-1] + (1,))
        xin = within(xs, self.lower, self.upper)
        return IKSolutions(np.concatenate([xcol, sol.q], axis=-1), sol.valid & xin[..., None],
                           sol.reachable, sol.method, sol.reach_error)

    def ik(self, T: ArrayLike, samples: int = 65, tool: ArrayLike | None = None) -> TrackChoice:
        """Choose the track value, then return the 8 arm solutions there.

        The criterion: the track value within the limits where the arm reaches the target with the
        largest manipulability ``|det J|`` (Yoshikawa 1985) over its valid branches. This keeps the
        wrist centre away from the boundary of the arm's reach (stretched or folded elbow, both
        ``det J = 0``), from axis 1 and from the wrist singularity, i.e. near the middle of the
        reach. It is searched on ``samples`` evenly spaced track values, then refined on as many
        values between the neighbours of the best one.

        Parameters
        ----------
        T : array_like, shape (..., 4, 4)
            ``T_L_TCP`` (m).
        samples : int
            Track values per search stage (>= 3).
        tool : array_like, shape (4, 4), optional
            ``T_F_TCP`` instead of the arm's default tool (m).

        Returns
        -------
        TrackChoice
        """
        self.check_choice(samples)
        arr = validate_pose(T, "target pose")
        batch = arr.shape[:-2]
        flat = arr.reshape(-1, 1, 4, 4)
        grid = np.broadcast_to(np.linspace(self.lower, self.upper, samples), (flat.shape[0], samples))
        x, score = self._best(flat, grid, tool)
        step = (self.upper - self.lower) / (samples - 1)
        fine = np.clip(x[:, None] + np.linspace(-step, step, samples), self.lower, self.upper)
        x, score = self._best(flat, fine, tool)
        sol = self.ik_at(arr, x.reshape(batch), tool)
        return TrackChoice(sol, x.reshape(batch), score.reshape(batch))

    def check_choice(self, samples: int) -> None:
        """Refuse to choose the track value without finite limits or with fewer than 3 samples."""
        if not (math.isfinite(self.lower) and math.isfinite(self.upper)):
            raise InputError("choosing the track value needs finite track limits (lower, upper)")
        if self.arm.n_joints != 6:
            raise InputError(f"choosing the track value needs a six-axis arm; {self.arm.name} has "
                             f"{self.arm.n_joints} axes: give the track value (ik_at)")
        if samples < 3:
            raise InputError(f"samples must be at least 3, got {samples}")

    def _best(self, T: NDArray[np.float64], grid: NDArray[np.float64],
              tool: ArrayLike | None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Best track value per target among ``grid`` (N, K); returns (N,) values and scores."""
        sol = solve(self.arm, invert(self.base_pose(grid)) @ T, tool)  # (N, K, 8, 6)
        q = np.where(sol.valid[..., None], sol.q, 0.0)
        w = np.abs(np.linalg.det(self.arm.jacobian(q)))
        score = np.where(sol.valid, w, 0.0).max(axis=-1)  # (N, K)
        k = np.argmax(score, axis=1)
        rows = np.arange(grid.shape[0])
        return grid[rows, k], score[rows, k]

    # -- the same system as one DH chain ----------------------------------------------------------
    def as_robot(self) -> Arm:
        """The arm and its track as one 7-joint DH robot (frame R of the result is L).

        Joint 1 is prismatic along ``direction``; DH frame 0 sits at the arm's first joint frame at
        track value 0 with ``z_0`` along the motion (for the arm mounted without rotation on a +X
        track that is L itself, turned so that z points along X_L). Its first DH row absorbs the
        angle between the motion and axis 1; the arm's first row absorbs the rotation about axis 1.

        Returns
        -------
        Arm
            Of the arm's class (a :class:`~robotcell.robot.robot.Robot` for a robot); joint
            values ``(x, q1, ..., q6)`` as in :meth:`fk` (controller values; an arm's
            coupling is carried over, extended by the uncoupled track axis); limits ``lower``,
            ``upper`` on x.
        """
        arm = self.arm
        j1 = arm.joints[0]
        C = self.T_L_R0 @ arm.base  # arm DH frame 0 (standard) in L
        if arm.convention == "modified":  # the constant part of row 1: Rx(alpha) Ry(beta) Tx(a)
            R1 = rot_x(j1.alpha) @ rot_y(j1.beta)
            C = C @ make_pose(R1, R1 @ [j1.a, 0.0, 0.0])
        u, zc, xc = self.direction, C[:3, 2], C[:3, 0]
        n = np.cross(u, zc)
        s = float(np.linalg.norm(n))
        if s < 1e-12:
            x0 = xc - u * float(xc @ u)
            x0 /= np.linalg.norm(x0)
        else:
            x0 = n / s
        alpha = math.atan2(float(np.cross(u, zc) @ x0), float(u @ zc))
        gamma = math.atan2(float(np.cross(x0, xc) @ zc), float(x0 @ xc))
        base = np.eye(4)
        base[:3, 0], base[:3, 1], base[:3, 2], base[:3, 3] = x0, np.cross(u, x0), u, C[:3, 3]
        if arm.convention == "standard":
            track = Joint("prismatic", 0.0, alpha, 0.0, 0.0, 1.0, self.lower, self.upper, "track")
            first = replace(j1, theta=j1.theta + gamma)
        else:
            track = Joint("prismatic", 0.0, 0.0, 0.0, 0.0, 1.0, self.lower, self.upper, "track")
            first = replace(j1, a=0.0, alpha=alpha, beta=0.0, theta=j1.theta + gamma)
        home = None
        if arm.home is not None:
            mid = 0.5 * (self.lower + self.upper) if math.isfinite(self.lower + self.upper) else 0.0
            home = np.concatenate([[mid], arm.home])
        coupling = None if arm.coupling is None else arm.coupling.extended(1)
        # The arm's own class (a Robot stays a Robot), without the arm's verification and seed.
        return replace(arm, name=f"{arm.name}_on_{self.name}", joints=(track, first) + arm.joints[1:],
                       base=base, home=home, title=f"{arm.title or arm.name} on a linear track",
                       verified=False, verification="", coupling=coupling, ik_seed=None)
