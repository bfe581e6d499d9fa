"""Linear motions of a program as the controller runs them: what a straight line between two
points asks of the arm.

A controller moves the TCP of a linear motion on the straight line between the two points, in
the frame of the target (a frame carried by the turntable moves with it: KUKA ``EK``, ABB
coordinated work objects), turning the orientation about one axis at a constant rate (KUKA
``#VAR``, ABB's quaternion interpolation) while the external axes move in proportion; it keeps
the arm's configuration, and stops where the line cannot be followed. :func:`line_problems`
follows each line the same way, in batches: the segment is sampled, every sample solved by the
analytic IK, and the arm kept on the branch it starts on (the same shoulder, elbow and wrist
solution), each revolute axis unwrapped along the way. It names what a controller refuses or
what surprises an operator:

- the target is on another branch than the one the line arrives on: the shoulder, the elbow or
  the wrist would change sides, which a straight line cannot do without passing a singularity
  (a wrist flip, axis 5 changing sign; the elbow passing stretched; the wrist centre passing
  axis 1);
- the line arrives with an axis a whole turn away from the point's joints as the configuration
  written selects them (ABB ``ConfL \\On``, FANUC and YASKAWA turn flags);
- the line passes closer to a singularity than the point check's margins (``singular_margin``
  for the wrist and the elbow, ``shoulder_margin`` for the wrist centre and axis 1) between its
  ends: there the wrist axes turn fast, and a controller slows down or stops with an axis speed
  error. Where the samples come near one, the line is sampled finer around the nearest approach;
- the line leaves the arm's reach, or takes an axis outside its limits, between the ends.

No fixed angle between two points is a problem: a wrist turning 40 deg on a short linear motion
is what controllers run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from robotcell.cell import Cell
from robotcell.cell.kinematics import robot_pose
from robotcell.ik.limits import TWO_PI
from robotcell.kinematics.transforms import invert
from robotcell.programs.config import side_changes
from robotcell.programs.frames import Placement
from robotcell.programs.singular import outside_text, singular_distances
from robotcell.robot.robot import Robot

__all__ = ["LineData", "line_problems"]

#: The line is sampled at least every SAMPLE_LENGTH of the TCP's path (m), every SAMPLE_ANGLE of
#: its turn and of the largest axis change between the ends (rad).
SAMPLE_LENGTH = 0.01
SAMPLE_ANGLE = math.radians(5.0)
#: Fewest and most intervals a line is sampled in.
MIN_INTERVALS, MAX_INTERVALS = 2, 256
#: A line whose samples come within REFINE_BELOW times a margin of a singularity is sampled
#: REFINE_SAMPLES times more finely around its nearest approach, REFINE_ROUNDS times.
REFINE_BELOW, REFINE_SAMPLES, REFINE_ROUNDS = 4.0, 8, 4
#: Largest difference (rad) between the line's end and the point's joints that counts as none.
ARRIVAL_TOL = 1e-6

@dataclass
class LineData:
    """The points of a program as :func:`line_problems` needs them.

    Attributes
    ----------
    names : list of str
        As the program names the points.
    lines : ndarray of int, shape (L, 2)
        Start and end point (0-based) of each linear motion to check; both with joints.
    q : ndarray, shape (N, 6)
        Each point's joints as the controller uses them (rad).
    track : ndarray, shape (N,)
        Track values (m).
    table : ndarray, shape (N,) or (N, n)
        Table values (rad).
    tools : ndarray, shape (N, 4, 4)
        ``T_F_TCP`` of each point (m).
    frames : list of Placement
        The frame each point's line is straight in (the frame of its target).
    branches : ndarray, shape (N, 8, 6), optional
        Every IK branch of each point's pose, with its own tool and in its own frame, where the
        check solved them already (NaN rows elsewhere): the ends of the lines, not solved again.
    """

    names: list[str]
    lines: NDArray[np.int_]
    q: NDArray[np.float64]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    tools: NDArray[np.float64]
    frames: list[Placement]
    branches: NDArray[np.float64] | None = None


@dataclass(frozen=True)
class _Margins:
    wrist: float
    shoulder: float


def _wrap(d: NDArray[np.float64]) -> NDArray[np.float64]:
    return d - TWO_PI * np.round(d / TWO_PI)


def _unwrap(robot: Robot, q: NDArray[np.float64], anchor: NDArray[np.float64]
            ) -> NDArray[np.float64]:
    """``q`` (``(L, m, n)``) with whole turns added to each revolute axis so that it starts at
    ``anchor`` (``(L, n)``) and moves by less than half a turn from sample to sample."""
    rev = ~robot.prismatic
    steps = np.diff(q, axis=1)
    steps[..., rev] = _wrap(steps[..., rev])
    start = q[:, 0].copy()
    start[:, rev] = anchor[:, rev] + _wrap(start[:, rev] - anchor[:, rev])
    return np.concatenate([start[:, None], start[:, None] + np.cumsum(steps, axis=1)], axis=1)


class _Lines:
    """Lines straight in one frame, solved on the branch each starts on.

    Parameters
    ----------
    cell : Cell
        The controller's cell.
    frame : Placement
    T0, T1 : ndarray, shape (L, 4, 4)
        The TCP at the start and the end, in ``frame`` (m).
    track, table : ndarray, shape (L, 2) and (L, 2) or (L, 2, n)
        External axes at the ends.
    tools : ndarray, shape (L, 4, 4)
        ``T_F_TCP`` of each line.
    """

    def __init__(self, cell: Cell, frame: Placement, T0: NDArray, T1: NDArray, track: NDArray,
                 table: NDArray, tools: NDArray) -> None:
        self.cell, self.frame = cell, frame
        self.T0, self.dp = T0, T1[:, :3, 3] - T0[:, :3, 3]
        self.rotvec = Rotation.from_matrix(np.swapaxes(T0[:, :3, :3], -1, -2)
                                           @ T1[:, :3, :3]).as_rotvec()
        self.track, self.table, self.tool_inv = track, table, invert(tools)
        self.branch = np.zeros(len(T0), dtype=int)

    def subset(self, rows: NDArray[np.int_]) -> _Lines:
        """The lines ``rows`` alone, on their branches."""
        out = object.__new__(_Lines)
        out.cell, out.frame = self.cell, self.frame
        for k in ("T0", "dp", "rotvec", "track", "table", "tool_inv", "branch"):
            setattr(out, k, getattr(self, k)[rows])
        return out

    def solve(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        """Every IK branch at path parameters ``s`` (``(L, m)``, 0 at the start, 1 at the end):
        shape ``(L, m, 8, 6)``, NaN where a branch does not reach."""
        L, m = s.shape
        rot = Rotation.from_rotvec((s[..., None] * self.rotvec[:, None, :]).reshape(-1, 3))
        T = np.zeros((L, m, 4, 4))
        T[..., 3, 3] = 1.0
        T[..., :3, :3] = self.T0[:, None, :3, :3] @ rot.as_matrix().reshape(L, m, 3, 3)
        T[..., :3, 3] = self.T0[:, None, :3, 3] + s[..., None] * self.dp[:, None, :]
        track = self.track[:, :1] + s * (self.track[:, 1:] - self.track[:, :1])
        w = s.reshape(s.shape + (1,) * (self.table.ndim - 2))
        table = self.table[:, :1] + w * (self.table[:, 1:] - self.table[:, :1])
        T_world = self.frame.world(self.cell, track, table) @ T
        T_R_F = invert(robot_pose(self.cell, track)) @ T_world @ self.tool_inv[:, None]
        sol = self.cell.robot.ik(T_R_F.reshape(-1, 4, 4), tool=np.eye(4))
        return sol.q.reshape(L, m, *sol.q.shape[-2:])

    def path(self, s: NDArray[np.float64], anchor: NDArray[np.float64],
             start: NDArray[np.float64] | None = None, end: NDArray[np.float64] | None = None
             ) -> NDArray[np.float64]:
        """Joints on each line's branch at ``s`` (``(L, m)``), unwrapped from ``anchor`` (the
        joints at ``s[:, 0]`` up to whole turns, ``(L, 6)``): shape ``(L, m, 6)``. ``start``
        and ``end``: the branches at the first and the last of ``s`` (``(L, 8, 6)``), when
        solved already (then only the samples between are solved)."""
        pick = self.branch[:, None, None, None]
        if start is None or end is None:
            q = np.take_along_axis(self.solve(s), pick, axis=2)[:, :, 0]
        else:
            inner = np.take_along_axis(self.solve(s[:, 1:-1]), pick, axis=2)[:, :, 0]
            ends = [np.take_along_axis(x, self.branch[:, None, None], axis=1) for x in (start, end)]
            q = np.concatenate([ends[0], inner, ends[1]], axis=1)
        return _unwrap(self.cell.robot, q, anchor)

    def start_branch(self, q8: NDArray[np.float64], q0: NDArray[np.float64]) -> None:
        """Set :attr:`branch`: the one of the branches ``q8`` (``(L, 8, 6)``) of the start pose
        that the start joints ``q0`` are on."""
        rev = ~self.cell.robot.prismatic
        d = q8 - q0[:, None]
        d[..., rev] = np.sin(0.5 * d[..., rev])  # 0 for whole turns, the distance near 0
        dist = np.einsum("...j,...j->...", d, d)
        self.branch = np.argmin(np.where(np.isfinite(dist), dist, np.inf), axis=-1)


def _ratio(robot: Robot, q: NDArray[np.float64], margins: _Margins) -> NDArray[np.float64]:
    """The smallest distance to a singularity in units of its margin (inf where unknown)."""
    with np.errstate(invalid="ignore"):
        wrist, elbow, shoulder = singular_distances(robot, np.nan_to_num(q))
        r = np.fmin(np.fmin(wrist / margins.wrist, elbow / margins.wrist),
                    shoulder / margins.shoulder)
    return np.where(np.isfinite(r) & np.isfinite(q).all(axis=-1), r, np.inf)


def _nearest_approach(lines: _Lines, s: NDArray, path: NDArray, margins: _Margins
                      ) -> tuple[NDArray, NDArray, NDArray]:
    """Where on each line the arm comes nearest to a singularity, the samples refined around
    it where they come near one: the path parameter ``(L,)``, the joints there ``(L, 6)``
    and the distance in units of the margin ``(L,)``."""
    robot = lines.cell.robot
    ratio = _ratio(robot, path, margins)
    k = np.argmin(ratio, axis=1)
    rows = np.arange(len(s))
    best_s, best_q, best_r = s[rows, k], path[rows, k], ratio[rows, k]
    near = np.flatnonzero(best_r < REFINE_BELOW)
    if near.size == 0:
        return best_s, best_q, best_r
    sub = lines.subset(near)
    ss, pp, rr = s[near], path[near], ratio[near]
    for _ in range(REFINE_ROUNDS):
        k = np.argmin(rr, axis=1)
        r = np.arange(len(near))
        lo, hi = np.maximum(k - 1, 0), np.minimum(k + 1, ss.shape[1] - 1)
        ss = np.linspace(ss[r, lo], ss[r, hi], REFINE_SAMPLES + 1, axis=1)
        pp = sub.path(ss, pp[r, lo])
        rr = _ratio(robot, pp, margins)
    k = np.argmin(rr, axis=1)
    r = np.arange(len(near))
    better = rr[r, k] < best_r[near]
    idx = near[better]
    best_s[idx], best_q[idx], best_r[idx] = ss[r, k][better], pp[r, k][better], rr[r, k][better]
    return best_s, best_q, best_r


def _singular_words(robot: Robot, q: NDArray[np.float64], margins: _Margins) -> list[str]:
    wrist, elbow, shoulder = (float(x) for x in singular_distances(robot, q))
    out = []
    if wrist < margins.wrist:
        out.append(f"passes {math.degrees(wrist):.2f} deg from the wrist singularity (axis 5; "
                   f"margin {math.degrees(margins.wrist):g} deg)")
    if elbow < margins.wrist:
        out.append(f"passes {math.degrees(elbow):.2f} deg from stretched or folded (elbow "
                   f"singularity, margin {math.degrees(margins.wrist):g} deg)")
    if shoulder < margins.shoulder:
        out.append(f"takes the wrist centre {shoulder * 1e3:.1f} mm from axis 1 (shoulder "
                   f"singularity, margin {margins.shoulder * 1e3:g} mm)")
    return out


def _arrival(robot: Robot, end: NDArray[np.float64], target: NDArray[np.float64]) -> str | None:
    """Words for a line that arrives (``end``) elsewhere than the point's joints ``target``."""
    if what := side_changes(robot, end, target):
        return f"changes the arm's configuration ({what}): a straight line cannot"
    diff = np.abs(end - target)
    j = int(np.argmax(diff))
    if diff[j] <= ARRIVAL_TOL:
        return None
    if robot.prismatic[j] or abs(_wrap(end[j] - target[j])) > 1e-3:
        return "changes the arm's configuration: a straight line cannot"
    return (f"arrives with axis {j + 1} at {math.degrees(end[j]):.1f} deg, a whole turn from "
            f"the point's {math.degrees(target[j]):.1f} deg as its configuration is written")


def line_problems(cell: Cell, data: LineData, singular_margin: float, shoulder_margin: float
                  ) -> dict[int, list[str]]:
    """What each linear motion asks of the arm that a controller refuses or an operator does not
    expect (the module's list), by the index of the point it moves to.

    Parameters
    ----------
    cell : Cell
        The cell whose model the controller computes with (its nominal arm, for a cell with an
        identified one).
    data : LineData
    singular_margin : float
        Closest good approach to the wrist or elbow singularity (rad).
    shoulder_margin : float
        Closest good distance of the wrist centre from axis 1 (m).

    Returns
    -------
    dict of int to list of str
        The problems of the lines, by their end point (0-based); lines without one are left out.
    """
    out: dict[int, list[str]] = {}
    if len(data.lines) == 0:
        return out
    robot = cell.robot
    margins = _Margins(singular_margin, shoulder_margin)
    a, b = data.lines[:, 0], data.lines[:, 1]
    tool = data.tools[b]
    start = robot_pose(cell, data.track[a]) @ robot.fk(data.q[a], tool=np.eye(4)) @ tool
    end = robot_pose(cell, data.track[b]) @ robot.fk(data.q[b], tool=np.eye(4)) @ tool
    groups: dict[int, list[int]] = {}
    for k, i in enumerate(b):
        groups.setdefault(id(data.frames[i]), []).append(k)
    for rows in groups.values():
        g = np.asarray(rows)
        frame = data.frames[b[g[0]]]
        T0 = invert(frame.world(cell, data.track[a[g]], data.table[a[g]])) @ start[g]
        T1 = invert(frame.world(cell, data.track[b[g]], data.table[b[g]])) @ end[g]
        intervals = _intervals(robot, T0, T1, data.q[a[g]], data.q[b[g]])
        for k in np.unique(intervals):
            sel = intervals == k
            _judge(cell, frame, data, g[sel], T0[sel], T1[sel], int(k), margins, out)
    return out


def _intervals(robot: Robot, T0: NDArray, T1: NDArray, q0: NDArray, q1: NDArray
               ) -> NDArray[np.int_]:
    """Intervals per line: a power of two between MIN_INTERVALS and MAX_INTERVALS."""
    length = np.linalg.norm(T1[:, :3, 3] - T0[:, :3, 3], axis=-1)
    turn = Rotation.from_matrix(np.swapaxes(T0[:, :3, :3], -1, -2) @ T1[:, :3, :3]).magnitude()
    rev = ~robot.prismatic
    change = np.max(np.abs(_wrap((q1 - q0)[:, rev])), axis=-1)
    need = np.maximum.reduce([length / SAMPLE_LENGTH, turn / SAMPLE_ANGLE, change / SAMPLE_ANGLE])
    k = np.ceil(np.log2(np.clip(need, MIN_INTERVALS, MAX_INTERVALS)))
    return (2 ** k).astype(int)


def _ends(lines: _Lines, data: LineData, a: NDArray[np.int_], b: NDArray[np.int_]
          ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Every IK branch at the start and at the end of the lines from ``a`` to ``b``: from
    ``data.branches`` where the check solved them (the start only where it has the end's tool
    and frame), else solved here. Shapes ``(L, 8, 6)``."""
    known = data.branches
    have = [np.zeros(len(a), dtype=bool), np.zeros(len(a), dtype=bool)]
    out = [None, None]
    if known is not None:
        have[1] = np.isfinite(known[b]).any(axis=(1, 2))
        have[0] = (np.isfinite(known[a]).any(axis=(1, 2))
                   & np.all(data.tools[a] == data.tools[b], axis=(1, 2))
                   & np.array([data.frames[i] is data.frames[j] for i, j in zip(a, b)],
                              dtype=bool))
        out = [known[a], known[b]]  # copies: indexed by arrays
    for k, s in ((0, 0.0), (1, 1.0)):
        rest = np.flatnonzero(~have[k])
        if rest.size:
            solved = lines.subset(rest).solve(np.full((rest.size, 1), s))[:, 0]
            if out[k] is None:
                out[k] = np.full((len(a),) + solved.shape[1:], np.nan)
            out[k][rest] = solved
    return out[0], out[1]


def _judge(cell: Cell, frame: Placement, data: LineData, rows: NDArray[np.int_], T0: NDArray,
           T1: NDArray, intervals: int, margins: _Margins, out: dict[int, list[str]]) -> None:
    """Follow the lines ``rows`` of ``data.lines`` in ``intervals`` steps and name their
    problems in ``out``."""
    robot = cell.robot
    a, b = data.lines[rows, 0], data.lines[rows, 1]
    lines = _Lines(cell, frame, T0, T1, np.stack([data.track[a], data.track[b]], axis=1),
                   np.stack([data.table[a], data.table[b]], axis=1), data.tools[b])
    s = np.broadcast_to(np.linspace(0.0, 1.0, intervals + 1), (len(rows), intervals + 1)).copy()
    start, end = _ends(lines, data, a, b)
    lines.start_branch(start, data.q[a])
    path = lines.path(s, data.q[a], start, end)
    reached = np.isfinite(path).all(axis=(1, 2))
    inside = robot._inside(path)
    at, q_near, ratio = _nearest_approach(lines, s, path, margins)
    ends = _ratio(robot, path[:, [0, -1]], margins).min(axis=1)
    singular = (ratio < 1.0) & (at > 0.0) & (at < 1.0) & (ratio < ends)
    arrive = np.abs(path[:, -1] - data.q[b]).max(axis=-1) > ARRIVAL_TOL
    for k in np.flatnonzero(~reached | ~inside.all(axis=1) | singular | arrive):
        words = []
        if not reached[k]:
            words.append("leaves the arm's reach on the way")
        else:
            if arrive[k] and (text := _arrival(robot, path[k, -1], data.q[b[k]])):
                words.append(text)
            if not inside[k].all():
                j = int(np.argmin(inside[k]))
                words.append(f"takes {outside_text(robot, path[k, j])}".replace(" is at ",
                                                                                 " to "))
            if singular[k]:
                words += _singular_words(robot, q_near[k], margins)
        prev = data.names[a[k]]
        out.setdefault(int(b[k]), []).extend(f"the linear motion from {prev} {w}" for w in words)
