"""The kinematic model of a serial arm described by Denavit-Hartenberg parameters.

``T_R_TCP(q) = T_R_0 · T_0_1(q_1) ··· T_{n-1,n}(q_n) · T_n_F · T_F_TCP`` with the base transform
``T_R_0``, the DH chain, the flange transform ``T_n_F`` and the tool ``T_F_TCP``. Joint values are
controller axis values (see ``docs/conventions.md``): the DH variable is ``sign * q + offset``.
A robot with a :class:`~robotcell.kinematics.coupling.Coupling` (parallel linkage, passive joints) maps its
controller values to the chain's joint values first, ``q_model = C q + offset``; every method
takes and returns controller values.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.kinematics.bounds import LIMIT_TOL, within
from robotcell.kinematics.coupling import Coupling
from robotcell.kinematics.covariance import ParameterCovariance, is_base_parameter
from robotcell.kinematics.dh import CHAIN, JACOBIAN, NO_SHIFT, Chain, Convention
from robotcell.kinematics.transforms import validate_pose, validate_single_pose

__all__ = ["Arm", "Joint"]


@dataclass(frozen=True)
class Joint:
    """One joint of a DH chain, in SI units.

    Attributes
    ----------
    type : {"revolute", "prismatic"}
    a : float
        Link length (m); Craig's ``a_{i-1}`` in the modified convention.
    alpha : float
        Link twist (rad); Craig's ``alpha_{i-1}`` in the modified convention.
    d : float
        Joint distance (m); for a prismatic joint the constant added to ``sign * q``.
    theta : float
        Joint angle (rad); for a revolute joint the constant added to ``sign * q``.
    sign : float
        +1 or -1, direction of the controller axis relative to the DH variable.
    lower, upper : float
        Limits of the controller axis value ``q`` (rad or m); infinite when unlimited.
    name : str
        Axis name as the controller shows it (``A1``, ``J1``, ...).
    passive : bool
        A joint without a controller axis, moved by a linkage (a palletizer's parallelogram);
        its value comes from the robot's coupling and its limits are not used.
    mass : float
        Mass of the link this joint moves (kg); 0 when not stated. Used only for gravity
        compliance in identification.
    com : tuple of 3 float
        Centre of mass of that link in its DH frame (m).
    beta : float
        Hayati's rotation about the link's y axis after the twist (rad; 0 for plain DH): standard
        ``Tz(d) Rz(theta) Tx(a) Rx(alpha) Ry(beta)``, modified ``Rx(alpha) Ry(beta) Tx(a) Rz(theta)
        Tz(d)``. An identified arm has it where two axes are nearly parallel (docs/models.md).
    """

    type: Literal["revolute", "prismatic"]
    a: float = 0.0
    alpha: float = 0.0
    d: float = 0.0
    theta: float = 0.0
    sign: float = 1.0
    lower: float = -math.inf
    upper: float = math.inf
    name: str = ""
    passive: bool = False
    mass: float = 0.0
    com: tuple[float, float, float] = (0.0, 0.0, 0.0)
    beta: float = 0.0

    @property
    def prismatic(self) -> bool:
        """True for a prismatic (sliding) joint."""
        return self.type == "prismatic"


@dataclass(frozen=True, eq=False)
class Arm:
    """A serial arm: DH joints, base, flange and tool transforms, provenance.

    The model the inverse kinematics solvers (:mod:`robotcell.ik`) work on; users build a
    :class:`~robotcell.robot.robot.Robot`, the same model with its inverse kinematics
    (:func:`robotcell.load_robot`, a library name or model file, or directly).

    Attributes
    ----------
    name : str
    joints : tuple of Joint
    convention : {"standard", "modified"}
    base : ndarray, shape (4, 4)
        ``T_R_0``, pose of DH frame 0 in the robot base frame R (metres).
    flange : ndarray, shape (4, 4)
        ``T_n_F``, pose of the flange frame in the last DH frame (metres).
    tool : ndarray, shape (4, 4)
        ``T_F_TCP``, the default tool: pose of the TCP in the flange frame (metres).
    home : ndarray, shape (n,) or None
        A typical home configuration (rad, m).
    title, source, verification : str
        Human name, citation of the parameters, and how they were checked.
    verified : bool
        True when the model was checked against an independent published value.
    coupling : Coupling or None
        Linear map from controller axis values to the chain's joint values (one row per joint,
        one column per non-passive joint); None when every joint is its own controller axis.
    ik_seed : Arm or None
        A nearby model with a closed-form IK (an identified arm's nominal model): when this model
        has none, ``Robot.ik`` refines the seed's analytic branches numerically (docs/ik.md).
    covariance : ParameterCovariance or None
        An identified model's: the covariance of the constants the identification moved
        (docs/accuracy.md).
    repeatability : float or None
        Pose repeatability RP that the robot's datasheet states (m; the "±" value), with its
        citation ``repeatability_source``; the default limit of an ISO 9283 test
        (docs/iso9283.md). None when no public datasheet gives it.
    repeatability_source : str
        Where ``repeatability`` is stated (document and address).
    link_radius : float or None
        Radius of the capsules around the arm's links for clearance checks (m), e.g. from the
        datasheet's drawing; None: :func:`robotcell.clearance.skeleton.default_radius` of the
        arm's size (docs/clearance.md).
    """

    name: str
    joints: tuple[Joint, ...]
    convention: Convention = "standard"
    base: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    flange: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    tool: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    home: NDArray[np.float64] | None = None
    title: str = ""
    source: str = ""
    verified: bool = False
    verification: str = ""
    coupling: Coupling | None = None
    ik_seed: Arm | None = None
    covariance: ParameterCovariance | None = None
    repeatability: float | None = None
    repeatability_source: str = ""
    link_radius: float | None = None

    def __post_init__(self) -> None:
        if self.convention not in ("standard", "modified"):
            raise InputError(f"convention must be 'standard' or 'modified', got {self.convention!r}")
        if not self.joints:
            raise InputError("a robot needs at least one joint")
        for i, j in enumerate(self.joints, start=1):
            if j.type not in ("revolute", "prismatic"):
                raise InputError(f"joint {i}: type must be 'revolute' or 'prismatic', got {j.type!r}")
            if j.sign not in (1.0, -1.0):
                raise InputError(f"joint {i}: sign must be +1 or -1, got {j.sign}")
            if not j.lower < j.upper:
                raise InputError(f"joint {i}: lower limit {j.lower} is not below upper limit {j.upper}")
        axes = tuple(j for j in self.joints if not j.passive)
        if self.coupling is None and len(axes) != len(self.joints):
            raise InputError("passive joints need a coupling that says how they move")
        if self.coupling is not None and self.coupling.matrix.shape != (len(self.joints), len(axes)):
            raise InputError(
                f"the coupling matrix must have one row per joint and one column per controller "
                f"(non-passive) axis, shape ({len(self.joints)}, {len(axes)}); got "
                f"{self.coupling.matrix.shape}"
            )
        if self.covariance is not None:
            known = {j.name or f"A{i}" for i, j in enumerate(self.joints, start=1)}
            bad = [n for n in self.covariance.names
                   if n != "j23_factor" and not is_base_parameter(n)
                   and n.rpartition(".")[0] not in known]
            if bad:
                raise InputError(f"covariance: parameter(s) {', '.join(bad)} of no joint of this "
                                 f"robot (joints {', '.join(sorted(known))})")
        object.__setattr__(self, "_axes", axes)
        for key in ("base", "flange", "tool"):
            object.__setattr__(self, key, validate_pose(getattr(self, key), key).copy())
        if self.home is not None:
            object.__setattr__(self, "home", self._joints(self.home, "home"))
        js = self.joints
        chain = Chain(self.convention, [j.a for j in js], [j.alpha for j in js], [j.d for j in js],
                      [j.theta for j in js], [j.prismatic for j in js], [j.sign for j in js],
                      [j.beta for j in js])
        object.__setattr__(self, "_chain", chain)
        object.__setattr__(self, "_tail", self.flange @ self.tool)
        object.__setattr__(self, "_sign", np.array([j.sign for j in js]))
        object.__setattr__(self, "_prismatic", np.array([j.prismatic for j in js]))

    # -- properties -----------------------------------------------------------------------------
    @property
    def n_joints(self) -> int:
        """Number of controller axes ``n`` (the chain's joints minus the passive ones)."""
        return len(self._axes)

    @property
    def axes(self) -> tuple[Joint, ...]:
        """The joints that are controller axes (all but the passive ones), in order."""
        return self._axes

    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower limits of the controller axes, shape ``(n,)`` (rad or m)."""
        return np.array([j.lower for j in self._axes])

    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper limits of the controller axes, shape ``(n,)`` (rad or m)."""
        return np.array([j.upper for j in self._axes])

    @property
    def prismatic(self) -> NDArray[np.bool_]:
        """Mask of prismatic controller axes, shape ``(n,)``."""
        return np.array([j.prismatic for j in self._axes])

    def uncoupled(self) -> Arm:
        """The kinematic model alone: the same chain whose joint values are the model's.

        For a robot without coupling this is the robot itself. Otherwise a robot with every joint
        of the chain as an axis (passive ones included), no coupling and no joint limits (limits
        are stated for controller values); ``uncoupled().fk(coupling.to_model(q)) == fk(q)``.
        """
        if self.coupling is None:
            return self
        model = self.__dict__.get("_uncoupled")
        if model is None:
            joints = tuple(replace(j, lower=-math.inf, upper=math.inf, passive=False) for j in self.joints)
            home = None if self.home is None else self.coupling.to_model(self.home)
            model = type(self)(f"{self.name}_model", joints, self.convention, self.base, self.flange,
                          self.tool, home, f"{self.title or self.name} (model joint values)",
                          self.source)
            object.__setattr__(self, "_uncoupled", model)
        return model

    def with_tool(self, tool: ArrayLike) -> Arm:
        """Return a copy whose default tool is ``tool`` (``T_F_TCP``, shape (4, 4), metres)."""
        return replace(self, tool=np.asarray(tool, dtype=float))

    def with_base(self, base: ArrayLike) -> Arm:
        """Return a copy whose base transform is ``base`` (``T_R_0``, shape (4, 4), metres).

        An ``ik_seed`` moves with the chain (its frame 0 keeps its place relative to this one's).
        """
        new = validate_pose(base, "base")
        seed = self.ik_seed
        if seed is not None:
            seed = seed.with_base(new @ np.linalg.inv(self.base) @ seed.base)
        return replace(self, base=new, ik_seed=seed)

    # -- validation -----------------------------------------------------------------------------
    def _tail_for(self, tool: ArrayLike | None) -> NDArray[np.float64]:
        """``T_n_TCP = T_n_F @ T_F_TCP`` for ``tool`` (the default tool when None), metres; the
        last tool's is kept, for a loop of single poses with one tool."""
        if tool is None:
            return self._tail
        arr = np.asarray(tool, dtype=float)
        key = arr.tobytes()
        last = self.__dict__.get("_last_tail")
        if last is None or last[0] != key:
            last = (key, self.flange @ validate_single_pose(arr, "tool"))
            object.__setattr__(self, "_last_tail", last)
        return last[1]

    def _one(self, q: ArrayLike) -> NDArray[np.float64] | None:
        """The chain's joint values of one configuration ``(m,)`` (a C-contiguous float array),
        or None when ``q`` is a batch. Not checked for NaN (the kernels do that)."""
        if type(q) is np.ndarray:
            if q.ndim != 1:
                return None
            arr = np.ascontiguousarray(q, dtype=float)
        elif isinstance(q, (list, tuple)):
            try:
                arr = np.array(q, dtype=float)
            except (TypeError, ValueError):
                arr = self._joints(q)  # raises the error
            if arr.ndim != 1:
                return None
        else:
            return None
        if arr.shape[0] != len(self._axes):
            self._joints(arr)  # raises the error
        if self.coupling is not None:
            arr = np.array(self.coupling.to_model_list(arr.tolist()))
        return arr

    def _joints(self, q: ArrayLike, name: str = "q") -> NDArray[np.float64]:
        try:
            arr = np.asarray(q, dtype=float)
        except (TypeError, ValueError) as exc:
            raise InputError(f"{name} must be numeric: {exc}") from None
        if arr.ndim == 0 or arr.shape[-1] != self.n_joints:
            raise InputError(
                f"{self.name} has {self.n_joints} joints; {name} must have shape (..., "
                f"{self.n_joints}), got {arr.shape}"
            )
        if not np.all(np.isfinite(arr)):
            raise InputError(f"{name} contains NaN or infinite values")
        return arr

    def within_limits(self, q: ArrayLike, tol: float = LIMIT_TOL) -> NDArray[np.bool_]:
        """Whether controller values respect the joint limits and the coupling's interaction limits.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Controller axis values (rad, m).
        tol : float
            Allowed excess beyond a limit (rad or m); default the rounding tolerance
            :data:`robotcell.kinematics.bounds.LIMIT_TOL`, so that a value at a limit is inside.

        Returns
        -------
        ndarray of bool, shape (...)
        """
        return self._inside(self._joints(q), tol)

    def _inside(self, q: NDArray[np.float64], tol: float = LIMIT_TOL) -> NDArray[np.bool_]:
        """:meth:`within_limits` of unchecked values ``(..., n)``: NaN values are outside."""
        ok = np.all(within(q, self.lower, self.upper, tol), axis=-1)
        if self.coupling is not None:
            ok &= self.coupling.within_interaction(q, tol)
        return ok

    def model_values(self, q: ArrayLike) -> NDArray[np.float64]:
        """Joint values of the chain for controller values ``q``.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Controller axis values (rad, m).

        Returns
        -------
        ndarray, shape (..., m)
            ``C q + offset`` with the robot's coupling (a copy of ``q`` without one).
        """
        arr = self._joints(q)
        return arr.copy() if self.coupling is None else self.coupling.to_model(arr)

    def dh_variables(self, q: ArrayLike) -> NDArray[np.float64]:
        """DH variables ``sign * q_model + offset`` (theta or d) of every joint, ``(..., m)``."""
        arr = self.model_values(q)
        sign = np.array([j.sign for j in self.joints])
        off = np.array([j.d if j.prismatic else j.theta for j in self.joints])
        return sign * arr + off

    # -- kinematics -----------------------------------------------------------------------------
    def fk(self, q: ArrayLike, tool: ArrayLike | None = None) -> NDArray[np.float64]:
        """Forward kinematics: the arm matrix ``T_R_TCP``.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Joint values (controller axis values; rad for revolute, m for prismatic joints).
        tool : array_like, shape (4, 4), optional
            ``T_F_TCP`` to use instead of the robot's default tool (metres).

        Returns
        -------
        ndarray, shape (..., 4, 4)
            Pose of the TCP in the robot base frame (metres).
        """
        return self.fk_from(self.base, q, tool)

    def fk_from(self, T_X_0: NDArray[np.float64], q: ArrayLike, tool: ArrayLike | None = None,
                shift: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """Forward kinematics from a given pose of DH frame 0: ``T_X_TCP``.

        The chain starts at ``T_X_0`` (``fk`` is ``fk_from(base, q)``): a cell places the robot's
        frame 0 in the world, on a track, without one more product of poses.

        Parameters
        ----------
        T_X_0 : ndarray, shape (4, 4)
            Pose of DH frame 0 in a frame X (metres), a valid rigid transform (not checked).
        q : array_like, shape (..., n)
            Joint values (rad, m).
        tool : array_like, shape (4, 4), optional
            ``T_F_TCP`` to use instead of the robot's default tool (metres).
        shift : ndarray, shape (3,), optional
            Added to the translation of ``T_X_0`` (metres, in X): a linear track's motion.

        Returns
        -------
        ndarray, shape (..., 4, 4)
            Pose of the TCP in X (metres).
        """
        tail = self._tail if tool is None else self._tail_for(tool)
        one = self._one(q)
        if one is not None:
            out = np.empty((4, 4))
            if not CHAIN.call(self._chain.program, one, T_X_0, NO_SHIFT if shift is None else shift,
                              tail, out, None, None):
                self._joints(q)  # raises: NaN or infinite values
            return out
        arr = self.model_values(q)
        batch = arr.shape[:-1]
        T = self._chain.apply(T_X_0, arr.reshape(-1, len(self.joints)), tail=tail, shift=shift)
        return T.reshape(batch + (4, 4))

    def frames(self, q: ArrayLike) -> NDArray[np.float64]:
        """Every DH frame in the robot base frame: ``T_R_i`` for ``i = 0..m``.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Controller axis values (rad, m).

        Returns
        -------
        ndarray, shape (..., m + 1, 4, 4)
            ``frames[..., 0]`` is the base transform ``T_R_0``; ``frames[..., i]`` is ``T_R_i``
            (``m`` joints in the chain, ``m = n`` without passive joints). The flange is
            ``frames[..., m] @ robot.flange``.
        """
        m = len(self.joints)
        one = self._one(q)
        if one is not None:
            F = np.empty((m + 1, 4, 4))
            if not self._chain.one(one, self.base, self._tail, F, frames=True):
                self._joints(q)  # raises: NaN or infinite values
            return F
        arr = self.model_values(q)
        batch = arr.shape[:-1]
        F = self._chain.apply(self.base, arr.reshape(-1, m), frames=True)
        return F.reshape(batch + (m + 1, 4, 4))

    def jacobian(self, q: ArrayLike, tool: ArrayLike | None = None) -> NDArray[np.float64]:
        """Geometric Jacobian in the robot base frame, for the TCP.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Joint values (rad, m).
        tool : array_like, shape (4, 4), optional
            ``T_F_TCP`` to use instead of the default tool (metres).

        Returns
        -------
        ndarray, shape (..., 6, n)
            Rows ``(vx, vy, vz, wx, wy, wz)``: the TCP's linear velocity (m/s) and the angular
            velocity (rad/s) per unit velocity of each controller axis (rad/s or m/s); with a
            coupling ``J_model @ C`` (chain rule).
        """
        tail = self._tail_for(tool)
        first = 0 if self.convention == "standard" else 1
        m = len(self.joints)
        one = self._one(q)
        if one is not None:
            F = np.empty((m + 1, 4, 4))
            if not self._chain.one(one, self.base, tail, F, frames=True):
                self._joints(q)  # raises: NaN or infinite values
            J = np.empty((6, m))
            JACOBIAN.call(F, tail, first, self._sign, self._prismatic, J)
        else:
            arr = self.model_values(q)
            J = self._chain.jacobian(self.base, arr.reshape(-1, m), tail, first, self._sign,
                                     self._prismatic).reshape(arr.shape[:-1] + (6, m))
        return J if self.coupling is None else self.coupling.jacobian(J)
