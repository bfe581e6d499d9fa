"""The evaluation of an ISO 9283 test: a measurement log against its plan (:func:`analyse`).

Per pose the position and orientation figures, between P1 and each other pose the distance
figures, per path the path figures (:mod:`robotcell.iso9283.figures`); the drift of AP and RP
when the log has time stamps; a verdict against the limits given. A log measured in the
tracker's own frame is first put into the plan's frame by the rigid transform that fits the
barycentres of P1..P5 onto their commands (``device_frame``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from robotcell.calibration.fitting import kabsch
from robotcell.errors import IllPosedError, InputError
from robotcell.io.poseformats import pose_to_vendor
from robotcell.iso9283.cube import POSE_NAMES
from robotcell.iso9283.cycles import MIN_CYCLES, PATH_CYCLES, POSE_CYCLES
from robotcell.iso9283.figures import (
    PathFigures,
    PoseFigures,
    crossings,
    distance_figures,
    nearest_samples,
    orientation_figures,
    path_figures,
    path_orientation_figures,
    pose_figures,
)
from robotcell.iso9283.log import Log, read_log
from robotcell.iso9283.planfile import read_plan
from robotcell.iso9283.testplan import TestPlan
from robotcell.iso9283.verdict import Limits, Verdict, datasheet_limits, judge
from robotcell.kinematics.arm import Arm

__all__ = ["DRIFT_CYCLES", "MAX_OFFSET", "DistanceResult", "Iso9283Result", "PathResult",
           "PoseResult", "analyse", "fit_device_frame"]

#: Largest distance of a measured pose or path sample from its command (m): a robot misses by
#: millimetres; farther is another frame (a tracker not aligned: ``device_frame``) or unit.
MAX_OFFSET = 0.050
#: Cycles at the start and at the end of a time-stamped log that the drift compares.
DRIFT_CYCLES = 10


@dataclass
class PoseResult:
    """The figures of one pose (m, rad).

    Attributes
    ----------
    pose : str
    command : ndarray, shape (3,)
        Commanded position in the plan's frame.
    p : ndarray, shape (n, 3)
        Measured positions of its n cycles, in the plan's frame.
    figures : PoseFigures
    AP_abc, RP_abc : ndarray, shape (3,), or None
        Orientation accuracy and repeatability about x, y, z (rad), when measured.
    drift : tuple of float, or None
        ``(dAP_p, dRP_l)`` from the first to the last :data:`DRIFT_CYCLES` cycles in time (m):
        the length of the change of the vector ``AP`` (how far the barycentre moved) and the
        change of ``RP_l``, when the log has time stamps and enough cycles.
    """

    pose: str
    command: NDArray[np.float64]
    p: NDArray[np.float64]
    figures: PoseFigures
    AP_abc: NDArray[np.float64] | None = None
    RP_abc: NDArray[np.float64] | None = None
    drift: tuple[float, float] | None = None


@dataclass
class DistanceResult:
    """Distance accuracy and repeatability between P1 and another pose (m)."""

    pose: str
    cycles: int
    D_c: float
    D_mean: float
    AD_p: float
    S_D: float
    RD_p: float


@dataclass
class PathResult:
    """The figures of one path: its command points and :class:`PathFigures` (m); ``AT_abc``
    the orientation path accuracy about x, y, z (rad), when the log has orientations."""

    path: str
    cycles: int
    names: list[str]
    command: NDArray[np.float64]
    figures: PathFigures
    AT_abc: NDArray[np.float64] | None = None


@dataclass
class Iso9283Result:
    """Everything :func:`analyse` finds; :meth:`to_json` in mm and deg.

    Attributes
    ----------
    plan : TestPlan
    poses : list of PoseResult
    distances : list of DistanceResult
    paths : list of PathResult
    T_X_device : ndarray, shape (4, 4), or None
        The tracker's frame in the plan's frame, when fitted (m).
    device_rms : float or None
        RMS distance of the barycentres from their commands after the fit (m).
    limits : Limits
    verdict : Verdict
    notes : list of str
    warnings : list of str
    source : str
        The log.
    """

    plan: TestPlan
    poses: list[PoseResult]
    distances: list[DistanceResult]
    paths: list[PathResult]
    T_X_device: NDArray[np.float64] | None
    device_rms: float | None
    limits: Limits
    verdict: Verdict
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    source: str = ""

    def to_json(self) -> dict[str, Any]:
        """The result as plain JSON values, lengths in mm and angles in deg (docs/iso9283.md)."""
        return {
            "log": self.source, "frame": self.plan.frame, "tool": self.plan.tool,
            "poses": [_pose_json(r) for r in self.poses],
            "distances": [{"from": "P1", "to": d.pose, "cycles": d.cycles,
                           "D_c_mm": d.D_c * 1e3, "D_mean_mm": d.D_mean * 1e3,
                           "AD_p_mm": d.AD_p * 1e3, "S_D_mm": d.S_D * 1e3,
                           "RD_p_mm": d.RD_p * 1e3} for d in self.distances],
            "paths": [_path_json(r) for r in self.paths],
            "device_frame": None if self.T_X_device is None else {
                **dict(zip(("x_mm", "y_mm", "z_mm", "a_deg", "b_deg", "c_deg"),
                           pose_to_vendor(self.T_X_device, "kuka").tolist())),
                "rms_mm": float(self.device_rms) * 1e3},
            "limits": self.limits.to_json(),
            "verdict": self.verdict.to_json(),
            "notes": list(self.notes),
        }


def _mm(v: NDArray[np.float64] | float) -> Any:
    return (np.asarray(v) * 1e3).tolist()


def _pose_json(r: PoseResult) -> dict[str, Any]:
    f = r.figures
    out: dict[str, Any] = {
        "pose": r.pose, "cycles": len(r.p), "command_mm": _mm(r.command),
        "barycentre_mm": _mm(f.barycentre), "AP_p_mm": f.AP_p * 1e3,
        "AP_x_mm": f.AP[0] * 1e3, "AP_y_mm": f.AP[1] * 1e3, "AP_z_mm": f.AP[2] * 1e3,
        "l_mean_mm": f.l_mean * 1e3, "S_l_mm": f.S_l * 1e3, "RP_l_mm": f.RP_l * 1e3,
    }
    for k, axis in enumerate("abc"):
        out[f"AP_{axis}_deg"] = None if r.AP_abc is None else float(np.degrees(r.AP_abc[k]))
        out[f"RP_{axis}_deg"] = None if r.RP_abc is None else float(np.degrees(r.RP_abc[k]))
    out["drift"] = None if r.drift is None else {
        "cycles": DRIFT_CYCLES, "dAP_p_mm": r.drift[0] * 1e3, "dRP_l_mm": r.drift[1] * 1e3}
    return out


def _path_json(r: PathResult) -> dict[str, Any]:
    f = r.figures
    out = {"path": r.path, "cycles": r.cycles, "points": len(r.names),
           "AT_p_mm": f.AT_p * 1e3, "AT_at": r.names[int(np.argmax(f.deviation))],
           "RT_p_mm": f.RT_p * 1e3, "RT_at": r.names[int(np.argmax(f.repeatability))]}
    for k, axis in enumerate("abc"):
        out[f"AT_{axis}_deg"] = None if r.AT_abc is None else float(np.degrees(r.AT_abc[k]))
    return out


def fit_device_frame(log: Log, plan: TestPlan) -> tuple[NDArray[np.float64], float]:
    """The tracker's frame in the plan's frame, from the barycentres of P1..P5.

    Parameters
    ----------
    log : Log
        Measured in the tracker's frame.
    plan : TestPlan

    Returns
    -------
    T_X_device : ndarray, shape (4, 4)
        Maps the log's coordinates into the plan's frame (m).
    rms : float
        RMS distance of the mapped barycentres from their commands (m).

    Raises
    ------
    IllPosedError
        The commanded poses do not fix a frame: all on one line (or one point).
    """
    cmd = plan.poses[:, :3, 3]
    bar = np.array([log.p[log.rows(name)].mean(axis=0) for name in POSE_NAMES])
    sv = np.linalg.svd(cmd - cmd.mean(axis=0), compute_uv=False)
    if sv[1] <= 1e-3 * sv[0] or sv[1] < 1e-4:
        raise IllPosedError("the device frame cannot be fitted: the plan's poses P1..P5 lie on "
                            "one line, which leaves the rotation about it free; measure a plan "
                            "whose poses span a plane, or align the tracker to the frame")
    T = kabsch(bar, cmd)
    res = (bar @ T[:3, :3].T + T[:3, 3]) - cmd
    return T, float(np.sqrt(np.mean(np.sum(res**2, axis=1))))


def _in_frame(log: Log, T: NDArray[np.float64]) -> Log:
    R = None if log.R is None else T[:3, :3] @ log.R
    return Log(log.cycle, log.name, log.p @ T[:3, :3].T + T[:3, 3], R, log.time, log.line,
               log.source)


def _check_offsets(log: Log, plan: TestPlan, fitted: bool) -> None:
    """Refuse a pose farther than :data:`MAX_OFFSET` from its command, or a path sample
    farther than that from the nearest point of its path (plus half the path's longest step
    between points)."""
    hint = ("the fit of the device frame leaves it there: a wrong pose or path name?" if fitted
            else "is the log in the plan's frame (else device_frame) and in mm?")
    for name, T in [*zip(POSE_NAMES, plan.poses[:, None]), *plan.paths.items()]:
        idx = log.rows(name)
        if idx.size == 0:
            continue
        c = T[:, :3, 3]
        d, _ = cKDTree(c).query(log.p[idx])
        step = np.linalg.norm(np.diff(c, axis=0), axis=1).max(initial=0.0) / 2
        k = int(np.argmax(d))
        if d[k] > MAX_OFFSET + step:
            raise InputError(f"{log.source}: line {log.line[idx[k]]}: {name} lies "
                             f"{d[k] * 1e3:.1f} mm from its command, more than "
                             f"{MAX_OFFSET * 1e3:g} mm; {hint}")


def _pose_results(log: Log, plan: TestPlan) -> list[PoseResult]:
    out = []
    for name, T in zip(POSE_NAMES, plan.poses):
        idx = log.rows(name)
        r = PoseResult(name, T[:3, 3], log.p[idx], pose_figures(log.p[idx], T[:3, 3]))
        if log.R is not None:
            r.AP_abc, r.RP_abc = orientation_figures(log.R[idx], T[:3, :3])
        if log.time is not None and len(idx) >= 2 * DRIFT_CYCLES:
            first = pose_figures(log.p[idx[:DRIFT_CYCLES]], T[:3, 3])
            last = pose_figures(log.p[idx[-DRIFT_CYCLES:]], T[:3, 3])
            r.drift = (float(np.linalg.norm(last.AP - first.AP)), abs(last.RP_l - first.RP_l))
        out.append(r)
    return out


def _distance_results(log: Log, plan: TestPlan) -> list[DistanceResult]:
    cmd = dict(zip(POSE_NAMES, plan.poses[:, :3, 3]))
    out = []
    first = {int(log.cycle[i]): i for i in log.rows("P1")}
    for name in POSE_NAMES[1:]:
        pairs = [(first[int(log.cycle[i])], i) for i in log.rows(name)
                 if int(log.cycle[i]) in first]
        if len(pairs) < MIN_CYCLES:
            continue
        a, b = np.array(pairs).T
        out.append(DistanceResult(name, len(pairs), *distance_figures(
            log.p[a], log.p[b], cmd["P1"], cmd[name])))
    return out


def _path_results(log: Log, plan: TestPlan) -> list[PathResult]:
    out = []
    for path, T in plan.paths.items():
        idx = log.rows(path)
        cycles = np.unique(log.cycle[idx])
        if cycles.size == 0:
            continue
        c = T[:, :3, 3]
        x, R = [], []
        for k in cycles:
            rows = idx[log.cycle[idx] == k]
            if len(rows) < 2:
                raise InputError(f"{log.source}: line {log.line[rows[0]]}: {path} of cycle {k} "
                                 "has one sample; a path needs its samples along it")
            x.append(crossings(log.p[rows], c))
            if log.R is not None:
                R.append(log.R[rows[nearest_samples(log.p[rows], x[-1])]])
        names = [f"{path}_{i + 1}" for i in range(len(c))]
        result = PathResult(path, int(cycles.size), names, c, path_figures(np.array(x), c))
        if R:
            result.AT_abc = path_orientation_figures(np.array(R), T[:, :3, :3])[1]
        out.append(result)
    return out


def analyse(measurements: str | Path | Log, plan: str | Path | TestPlan,
            device_frame: bool = False, limits: Limits | None = None,
            robot: Arm | None = None) -> Iso9283Result:
    """Evaluate an ISO 9283 test: the figures of every pose, distance and path, and a verdict.

    Parameters
    ----------
    measurements : str, Path or Log
        The measurement log (:mod:`robotcell.iso9283.log`), a file or read.
    plan : str, Path or TestPlan
        The plan it measured (:mod:`robotcell.iso9283.planfile`), a file or made.
    device_frame : bool
        The log is in the tracker's own frame: fit it onto the plan's frame first
        (:func:`fit_device_frame`).
    limits : Limits, optional
        Limits of AP, RP, AT, RT for the verdict (m); none: the verdict says so.
    robot : Arm, optional
        The arm tested: where ``limits`` has no RP and its model carries the datasheet's pose
        repeatability, that is the limit of RP (a note says so).

    Returns
    -------
    Iso9283Result

    Raises
    ------
    InputError
        A bad plan or log (the message names the file and line), or a pose or sample farther
        than :data:`MAX_OFFSET` from its command.
    IllPosedError
        ``device_frame`` with poses that do not fix a frame.
    """
    warnings: list[str] = []
    if not isinstance(plan, TestPlan):
        plan, w = read_plan(plan)
        warnings += w
    if isinstance(measurements, Log):
        log = measurements
    else:
        log, w = read_log(measurements, plan)
        warnings += w
    T_fit, rms = None, None
    if device_frame:
        T_fit, rms = fit_device_frame(log, plan)
        log = _in_frame(log, T_fit)
    _check_offsets(log, plan, device_frame)
    poses = _pose_results(log, plan)
    paths = _path_results(log, plan)
    limits, datasheet = datasheet_limits(limits or Limits(), robot)
    notes = _notes(poses, paths, log, device_frame) + ([datasheet] if datasheet else [])
    figures = {"AP": [(r.figures.AP_p, r.pose) for r in poses],
               "RP": [(r.figures.RP_l, r.pose) for r in poses],
               "AT": [(r.figures.AT_p, r.path) for r in paths],
               "RT": [(r.figures.RT_p, r.path) for r in paths]}
    return Iso9283Result(plan, poses, _distance_results(log, plan), paths, T_fit, rms, limits,
                         judge(figures, limits), notes, warnings, log.source)


def _notes(poses: list[PoseResult], paths: list[PathResult], log: Log, fitted: bool) -> list[str]:
    notes = []
    few = [r.pose for r in poses if len(r.p) < POSE_CYCLES]
    if few:
        notes.append(f"{', '.join(few)}: fewer than the {POSE_CYCLES} cycles ISO 9283 prescribes "
                     "for a pose")
    few = [r.path for r in paths if r.cycles < PATH_CYCLES]
    if few:
        notes.append(f"{', '.join(few)}: fewer than the {PATH_CYCLES} cycles ISO 9283 prescribes "
                     "for a path")
    if log.time is None:
        notes.append("no drift: the log has no time stamps")
    elif any(r.drift is None for r in poses):
        notes.append(f"no drift where a pose has fewer than {2 * DRIFT_CYCLES} cycles")
    if fitted:
        notes.append("device frame fitted to the barycentres of P1..P5: the part of the errors "
                     "that a rigid motion of the frame explains is not in AP")
    return notes
