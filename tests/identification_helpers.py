"""Synthetic truth for the identification tests: a perturbed arm measured by a simulated tracker."""

import math
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from robotcell.identification import TargetMeasurements
from robotcell.identification.chain import Chain
from robotcell.kinematics.transforms import make_pose
from robotcell.robot.robot import Robot

#: Pose of the robot base in the tracker frame used by every synthetic test (m).
T_D_R = make_pose(Rotation.from_euler("zyx", [30.0, 2.0, -1.0], degrees=True).as_matrix(),
                  [2.0, -1.0, 0.3])
REFLECTORS = np.array([[0.05, 0.10, 0.08], [-0.07, 0.0, 0.10], [0.0, -0.10, 0.06]])


def perturbed(nominal: Robot, rng: np.random.Generator) -> Robot:
    """Every DH constant moved by 0.1-1 mm or 0.02-0.2 deg, random sign."""
    def mm():
        return rng.uniform(0.1e-3, 1e-3) * rng.choice([-1.0, 1.0])

    def deg():
        return math.radians(rng.uniform(0.02, 0.2)) * rng.choice([-1.0, 1.0])

    joints = tuple(replace(j, a=j.a + mm(), d=j.d + mm(), alpha=j.alpha + deg(), theta=j.theta + deg())
                   for j in nominal.joints)
    return replace(nominal, joints=joints)


def truth_chain(truth: Robot, n_targets: int, pose: bool, rng: np.random.Generator,
                coupling: float | None = None, scale=None):
    """A chain in the tracker frame with Hayati tilts at the parallel axes; returns (chain, x).

    ``coupling``: the J2/J3 factor; default the model's own (``coupling: {j23_factor: k}``).
    """
    if coupling is None:
        coupling = truth.coupling.j23_factor if truth.coupling is not None else 0.0
    tool = make_pose(Rotation.from_euler("xyz", [10.0, -20.0, 95.0], degrees=True).as_matrix(),
                     [0.02, -0.03, 0.12]) if pose else np.eye(4)
    ch = Chain(truth, 0 if pose else n_targets, pose, T_D_R, tool)
    x = ch.values.copy()
    for b in ch.beta_joints:
        x[ch.index(f"{ch.joint_names[b]}.beta")] = math.radians(rng.uniform(0.02, 0.2))
    for k in range(ch.n_targets):
        x[ch.target_params[k]] = REFLECTORS[k]
    if ch.coupling_param >= 0:
        x[ch.coupling_param] = coupling
    if scale is not None:
        x[ch.scale_params] = scale
    return ch, x


def configurations(robot: Robot, n: int, rng: np.random.Generator) -> np.ndarray:
    """Random joint values within 80 % of the limits (rad, m)."""
    lo = np.where(np.isfinite(robot.lower), robot.lower, -math.pi)
    hi = np.where(np.isfinite(robot.upper), robot.upper, math.pi)
    mid, half = (lo + hi) / 2, (hi - lo) / 2 * 0.8
    return rng.uniform(mid - half, mid + half, (n, robot.n_joints))


def measure(ch: Chain, x: np.ndarray, q: np.ndarray, rng: np.random.Generator, noise: float,
            angle_noise: float = 0.0) -> TargetMeasurements:
    """Simulated measurements with Gaussian noise (m per coordinate, rad per axis)."""
    pts, R = ch.predict(x, q)
    pts = pts + rng.normal(0.0, noise, pts.shape)
    rot = None
    if ch.pose_target:
        rot = Rotation.from_rotvec(rng.normal(0.0, angle_noise, (len(q), 3))).as_matrix() @ R
    return TargetMeasurements(q, pts, rot)


def write_csv(path, meas: TargetMeasurements, prismatic=None) -> None:
    """Write measurements as the CLI's CSV (deg / mm)."""
    n, K = meas.q.shape[1], meas.n_targets
    pris = np.zeros(n, dtype=bool) if prismatic is None else np.asarray(prismatic)
    q = np.where(pris, meas.q * 1e3, np.degrees(meas.q))
    head = [f"a{i}" for i in range(1, n + 1)]
    head += ["x", "y", "z"] if K == 1 else [f"{c}{k}" for k in range(1, K + 1) for c in "xyz"]
    cols = [q, meas.points.reshape(len(q), -1) * 1e3]
    if meas.rotations is not None:
        head += ["qw", "qx", "qy", "qz"]
        xyzw = Rotation.from_matrix(meas.rotations).as_quat()
        cols.append(xyzw[:, [3, 0, 1, 2]])
    rows = np.concatenate(cols, axis=1)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(",".join(head) + "\n")
        fh.writelines(",".join(f"{v:.9f}" for v in r) + "\n" for r in rows)


def target_tool(data: dict) -> np.ndarray:
    """``T_F_T`` (m) from the JSON of ``identify``: the target frame, else the first reflector."""
    T = np.array(data["target"], dtype=float) if "target" in data else np.eye(4)
    if "target" not in data:
        T[:3, 3] = data["targets"][0]
    T[:3, 3] /= 1e3
    return T


def one_joint_rows(robot: Robot, per_joint: int = 7, span_deg: float = 60.0) -> np.ndarray:
    """Rows moving each joint alone about zero (rad)."""
    rows = []
    for j in range(robot.n_joints):
        for v in np.linspace(-np.radians(span_deg), np.radians(span_deg), per_joint):
            q = np.zeros(robot.n_joints)
            q[j] = v
            rows.append(q)
    return np.array(rows)
