"""The parameterised chain the identification fits: elementary motions with named constants.

A measured point is modelled, in the measuring device's frame D, as::

    p_D = T_D_R(base) · T_R_0 · L_1(q) ··· L_n(q) · T_n_F · T_F_T(tool) · r_k

with ``T_D_R`` the unknown pose of the robot base in the device frame, ``T_R_0`` and ``T_n_F`` the
nominal base and flange transforms (constants), ``L_i`` the links, ``T_F_T`` the measured target's
frame on the flange (pose measurements only) and ``r_k`` the unknown position of reflector ``k``
on the last link. Each of ``T_D_R``, ``L_i`` and ``T_F_T`` is a product of elementary motions
(rotations about and translations along the current frame's x, y or z axis); every constant of
those motions is a candidate unknown, named after its joint (``A2.alpha``).

Links follow the nominal model's convention (``docs/conventions.md``)::

    standard:  L_i = Tz(d_i) Rz(theta_i) Tx(a_i) Rx(alpha_i) [Ry(beta_i)]
    modified:  L_i = Rx(alpha_{i-1}) [Ry(beta_i)] Tx(a_{i-1}) Rz(theta_i) Tz(d_i)

The rotation ``Ry(beta_i)`` (Hayati and Mirmirani, "Improving the absolute positioning accuracy of
robot manipulators", J. Robotic Systems 2(4), 1985) is added where the two axes the link joins are
nominally parallel (or where the nominal model has one: a model identified before). There plain DH is discontinuous (a tilt of 0.01 deg moves the common normal
metres away), while with ``beta`` every small tilt is a small change of parameters. The joint
variable enters as ``theta_i = sign_i * qm_i + theta_i`` (revolute) or ``d_i = sign_i * qm_i + d_i``
(prismatic) with the model joint value ``qm_i = (1 + scale_i) q_i``, plus ``k * q_2`` on joint 3 for
a J2/J3 coupling ``q3_model = J3 + k * J2`` (the ROS-Industrial FANUC driver's ``J23_factor``),
plus ``sign_i * compliance_i * tau_i(q)`` on joints 2 and 3: their turn under the gravity torque
``tau_i`` of the nominal link masses (:mod:`robotcell.identification.gravity`), so that the DH
variable changes by ``compliance_i * tau_i`` (rad per N m times N m).

The derivative of ``p_D`` with respect to the constant of a rotation about unit axis ``u``
through ``o`` (both in D, at the current row) is ``u × (p_D - o)``, and ``u`` for a translation:
the Jacobian is analytic and costs one pass over the chain.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotcell.identification.gravity import gravity_torques
from robotcell.kinematics.transforms import make_pose, rot_x, rot_y, rot_z
from robotcell.robot.robot import Robot

__all__ = ["COMPLIANT_JOINTS", "PARALLEL_TOL", "Chain", "Op"]

#: Joints (0-based) with a gravity compliance parameter: axes 2 and 3.
COMPLIANT_JOINTS = (1, 2)

#: Consecutive nominal axes closer than this to parallel (radians) get a Hayati ``beta``.
PARALLEL_TOL = math.radians(1.0)


@dataclass(frozen=True)
class Op:
    """One elementary motion ``T <- T @ op``.

    Attributes
    ----------
    kind : {"tx", "ty", "tz", "rx", "ry", "rz"}
    param : int
        Index of its constant in the parameter vector.
    joint : int
        Joint whose value it adds (``-1`` for a constant motion).
    sign : float
        +1 or -1: the joint's direction.
    """

    kind: str
    param: int
    joint: int = -1
    sign: float = 1.0


@dataclass
class Evaluation:
    """Frames along the chain for a batch of rows (device frame D, metres)."""

    R: NDArray[np.float64]  # (N, 3, 3) last frame (target frame)
    p: NDArray[np.float64]  # (N, 3) its origin
    axes: list[NDArray[np.float64]]  # per op: (N, 3) unit axis in D
    origins: list[NDArray[np.float64]]  # per op: (N, 3) frame origin before the motion


class Chain:
    """Elementary-motion model of a serial chain with named parameters (SI units).

    Parameters
    ----------
    robot : Robot
        Nominal model: convention, DH constants, signs, base and flange, joint names.
    n_targets : int
        Number of reflectors on the last link (point measurements).
    pose_target : bool
        True when orientations are measured: adds the 6 constants of ``T_F_T``.
    base_start, tool_start : ndarray, shape (4, 4)
        ``T_D_R`` and ``T_F_T`` the base and tool motions start from (their constants start at 0).

    Attributes
    ----------
    names : list of str
        Parameter names; ``values`` the nominal parameter vector (m, rad).
    groups : list of str
        Per parameter: ``base``, ``target``, ``link``, ``scale``, ``coupling`` or ``compliance``.
    """

    def __init__(self, robot: Robot, n_targets: int, pose_target: bool,
                 base_start: NDArray[np.float64], tool_start: NDArray[np.float64]) -> None:
        self.robot = robot
        self.n = robot.n_joints
        self.n_targets = n_targets
        self.pose_target = pose_target
        self.base_start = np.asarray(base_start, dtype=float)
        self.tool_start = np.asarray(tool_start, dtype=float)
        names: list[str] = []
        values: list[float] = []
        groups: list[str] = []
        ops: list[Op] = []

        def add(name: str, value: float, group: str) -> int:
            names.append(name)
            values.append(float(value))
            groups.append(group)
            return len(names) - 1

        def op(kind: str, name: str, value: float, group: str, joint: int = -1, sign: float = 1.0):
            ops.append(Op(kind, add(name, value, group), joint, sign))

        for k, label in zip(("tx", "ty", "tz", "rx", "ry", "rz"), ("x", "y", "z", "rx", "ry", "rz")):
            op(k, f"base.{label}", 0.0, "base")
        self.joint_names = [j.name or f"A{i}" for i, j in enumerate(robot.joints, start=1)]
        z = _nominal_axes(robot)
        self.beta_joints: list[int] = []
        for i, j in enumerate(robot.joints):
            nm = self.joint_names[i]
            jz = (i, j.sign) if j.prismatic else (-1, 1.0)
            jr = (i, j.sign) if not j.prismatic else (-1, 1.0)
            if robot.convention == "standard":
                parallel = i + 1 < self.n and _parallel(z[i], z[i + 1])
                op("tz", f"{nm}.d", j.d, "link", *jz)
                op("rz", f"{nm}.theta", j.theta, "link", *jr)
                op("tx", f"{nm}.a", j.a, "link")
                op("rx", f"{nm}.alpha", j.alpha, "link")
                if parallel or j.beta:
                    op("ry", f"{nm}.beta", j.beta, "link")
            else:
                parallel = i > 0 and _parallel(z[i - 1], z[i])
                op("rx", f"{nm}.alpha", j.alpha, "link")
                if parallel or j.beta:
                    op("ry", f"{nm}.beta", j.beta, "link")
                op("tx", f"{nm}.a", j.a, "link")
                op("rz", f"{nm}.theta", j.theta, "link", *jr)
                op("tz", f"{nm}.d", j.d, "link", *jz)
            if parallel or j.beta:
                self.beta_joints.append(i)
        self.n_chain_ops = len(ops)
        if pose_target:
            for k, label in zip(("tx", "ty", "tz", "rx", "ry", "rz"), ("x", "y", "z", "rx", "ry", "rz")):
                op(k, f"target.{label}", 0.0, "target")
        self.ops = ops
        self.target_params = []
        for t in range(n_targets):
            tag = "target" if n_targets == 1 else f"target{t + 1}"
            self.target_params.append([add(f"{tag}.{c}", 0.0, "target") for c in "xyz"])
        self.scale_params = [add(f"{nm}.scale", 0.0, "scale") for nm in self.joint_names]
        self.coupling_param = add("j23_factor", 0.0, "coupling") if self.n >= 3 else -1
        self.compliance_params = ([add(f"{self.joint_names[j]}.compliance", 0.0, "compliance")
                                   for j in COMPLIANT_JOINTS] if self.n >= 3 else [])
        self._masses = any(j.mass > 0 for j in robot.joints)
        self._tau_cache: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        self.names = names
        self.values = np.array(values)
        self.groups = groups

    def index(self, name: str) -> int:
        """Index of the parameter called ``name``."""
        return self.names.index(name)

    # -- evaluation -----------------------------------------------------------------------------
    def torques(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """Gravity torques on axes 2 and 3 of the nominal model at ``q`` (N m), shape (N, 2)."""
        if not (self._masses and self.compliance_params):
            return np.zeros((q.shape[0], len(self.compliance_params)))
        hit = self._tau_cache
        if hit is None or hit[0].shape != q.shape or not np.array_equal(hit[0], q):
            hit = (q.copy(), gravity_torques(self.robot, q, COMPLIANT_JOINTS))
            self._tau_cache = hit
        return hit[1]

    def model_joints(self, x: NDArray[np.float64], q: NDArray[np.float64],
                     gravity: bool = True) -> NDArray[np.float64]:
        """Model joint values ``(1 + scale) q`` plus ``k q_2`` on joint 3, shape (N, n).

        With ``gravity``, plus ``sign * compliance * tau`` on axes 2 and 3 (the deflection).
        """
        qm = q * (1.0 + x[self.scale_params])
        if self.coupling_param >= 0:
            qm[:, 2] += x[self.coupling_param] * q[:, 1] * (1.0 + x[self.scale_params[2]])
        if gravity and self._masses and self.compliance_params:
            c = x[self.compliance_params]
            if np.any(c):
                tau = self.torques(q)
                for col, j in enumerate(COMPLIANT_JOINTS):
                    qm[:, j] += self.robot.joints[j].sign * c[col] * tau[:, col]
        return qm

    def evaluate(self, x: NDArray[np.float64], q: NDArray[np.float64], jac: bool = True,
                 base: bool = True, gravity: bool = True) -> Evaluation:
        """Walk the chain for every row.

        Parameters
        ----------
        x : ndarray, shape (P,)
            Full parameter vector (m, rad).
        q : ndarray, shape (N, n)
            Controller joint values (rad, m).
        jac : bool
            Record the axis and origin of every motion (for the Jacobian).
        base : bool
            Include ``T_D_R`` (False: frames in the robot base frame R).
        gravity : bool
            Include the gravity deflection of axes 2 and 3.

        Returns
        -------
        Evaluation
        """
        N = q.shape[0]
        qm = self.model_joints(x, q, gravity)
        start = self.base_start if base else np.eye(4)
        cols = [np.broadcast_to(start[:3, k], (N, 3)) for k in range(4)]
        axes: list[NDArray[np.float64]] = []
        origins: list[NDArray[np.float64]] = []

        def const(T: NDArray[np.float64]) -> None:
            new = [sum(T[m, k] * cols[m] for m in range(3)) for k in range(3)]
            new.append(cols[3] + sum(T[m, 3] * cols[m] for m in range(3)))
            cols[:] = new

        for idx, o in enumerate(self.ops):
            if idx == 6:
                const(self.robot.base)
            if idx == self.n_chain_ops:
                const(self.robot.flange @ self.tool_start)
            if not base and idx < 6:
                axes.append(np.zeros((N, 3)))
                origins.append(np.zeros((N, 3)))
                continue
            v = x[o.param]
            if o.joint >= 0:
                v = o.sign * qm[:, o.joint] + v
            kind = o.kind
            m = "xyz".index(kind[1])
            if jac:
                axes.append(cols[m])
                origins.append(cols[3])
            if kind[0] == "t":
                cols[3] = cols[3] + (v[:, None] if np.ndim(v) else v) * cols[m]
                continue
            i, j = {"rx": (1, 2), "ry": (2, 0), "rz": (0, 1)}[kind]
            c, s = np.cos(v), np.sin(v)
            if np.ndim(v):
                c, s = c[:, None], s[:, None]
            ci, cj = cols[i], cols[j]
            cols[i] = c * ci + s * cj
            cols[j] = c * cj - s * ci
        if len(self.ops) == self.n_chain_ops:
            const(self.robot.flange @ self.tool_start)
        R = np.stack(cols[:3], axis=-1)
        return Evaluation(R=R, p=np.array(cols[3]), axes=axes, origins=origins)

    def targets(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """Reflector positions in the last frame, shape (K, 3) (m)."""
        return x[np.array(self.target_params, dtype=int).reshape(-1, 3)] if self.n_targets else np.zeros((0, 3))

    def predict(self, x: NDArray[np.float64], q: NDArray[np.float64]):
        """Predicted points ``(N, K, 3)`` and target rotations ``(N, 3, 3)`` in D (m)."""
        ev = self.evaluate(x, q, jac=False)
        r = np.zeros((1, 3)) if self.pose_target else self.targets(x)
        pts = ev.p[:, None, :] + np.einsum("nij,kj->nki", ev.R, r)
        return pts, ev.R

    def point_jacobian(self, x: NDArray[np.float64], q: NDArray[np.float64], ev: Evaluation,
                       pts: NDArray[np.float64]) -> NDArray[np.float64]:
        """``d pts / d x``: shape (N, K, 3, P) (m per m or rad)."""
        N, K = pts.shape[:2]
        J = np.zeros((N, K, 3, len(self.names)))
        for o, u, org in zip(self.ops, ev.axes, ev.origins):
            col = u[:, None, :] if o.kind[0] == "t" else np.cross(u[:, None, :], pts - org[:, None, :])
            J[..., o.param] += np.broadcast_to(col, (N, K, 3))
            if o.joint >= 0:
                self._joint_terms(J, col, o, q, x)
        for k, idx in enumerate(self.target_params):
            J[:, k, :, idx] = np.moveaxis(ev.R, -1, 0)
        return J

    def rotation_jacobian(self, x: NDArray[np.float64], q: NDArray[np.float64],
                          ev: Evaluation) -> NDArray[np.float64]:
        """Angular velocity of the target frame per parameter: shape (N, 3, P) (rad per m or rad)."""
        N = q.shape[0]
        W = np.zeros((N, 3, len(self.names)))
        for o, u in zip(self.ops, ev.axes):
            if o.kind[0] == "t":
                continue
            W[..., o.param] += u
            if o.joint >= 0:
                self._joint_terms(W, u, o, q, x)
        return W

    def _joint_terms(self, J, col, o: Op, q, x) -> None:
        """Add the scale and coupling columns of a joint motion whose parameter column is ``col``."""
        extra = (slice(None),) + (None,) * (col.ndim - 1)
        j = o.joint
        base_q = q[:, j] if j != 2 or self.coupling_param < 0 else q[:, 2] + x[self.coupling_param] * q[:, 1]
        J[..., self.scale_params[j]] += o.sign * base_q[extra] * col
        if j in COMPLIANT_JOINTS and self.compliance_params and self._masses:
            # d(DH variable)/d(compliance) = sign * sign * tau = tau.
            J[..., self.compliance_params[COMPLIANT_JOINTS.index(j)]] += (
                self.torques(q)[:, COMPLIANT_JOINTS.index(j)][extra] * col)
        if j == 2 and self.coupling_param >= 0:
            J[..., self.coupling_param] += (o.sign * (1.0 + x[self.scale_params[2]]) * q[:, 1])[extra] * col

    # -- geometry of the result -----------------------------------------------------------------
    def base_pose(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """``T_D_R``: the robot base in the device frame (m)."""
        return self.base_start @ _motion(x[:6])

    def tool_pose(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """``T_F_T``: the measured target frame on the flange (m); ``tool_start`` for points."""
        if not self.pose_target:
            return self.tool_start.copy()
        first = self.ops[self.n_chain_ops].param
        return self.tool_start @ _motion(x[first:first + 6])

    def axis_lines(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                                           NDArray[np.float64]]:
        """Joint axes of the model at ``q = 0`` in the robot base frame R.

        Returns
        -------
        points : ndarray, shape (n, 3)
            A point on each axis (m).
        directions : ndarray, shape (n, 3)
            Unit direction in which a positive controller value turns or moves.
        flange : ndarray, shape (4, 4)
            ``T_R_F`` at ``q = 0`` (m).
        """
        ev = self.evaluate(x, np.zeros((1, self.n)), jac=True, base=False, gravity=False)
        pts, dirs = np.zeros((self.n, 3)), np.zeros((self.n, 3))
        for o, u, org in zip(self.ops, ev.axes, ev.origins):
            if o.joint >= 0:
                dirs[o.joint] = o.sign * u[0]
                pts[o.joint] = org[0]
        T_R_T = make_pose(ev.R[0], ev.p[0])
        return pts, dirs, T_R_T @ np.linalg.inv(self.tool_pose(x))


def _motion(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """``Tx Ty Tz Rx Ry Rz`` for the six constants ``v`` (m, rad)."""
    T = np.eye(4)
    T[:3, 3] = v[:3]
    T[:3, :3] = rot_x(v[3]) @ rot_y(v[4]) @ rot_z(v[5])
    return T


def _nominal_axes(robot: Robot) -> NDArray[np.float64]:
    F = robot.frames(np.zeros(robot.n_joints))
    axes = F[:-1] if robot.convention == "standard" else F[1:]
    return axes[:, :3, 2]


def _parallel(z1: NDArray[np.float64], z2: NDArray[np.float64]) -> bool:
    return float(np.linalg.norm(np.cross(z1, z2))) < math.sin(PARALLEL_TOL)
