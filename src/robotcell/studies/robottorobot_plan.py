"""Planning a robot-to-robot calibration: where to put the common points.

For a cell of several robots (its values taken as the truth), :func:`plan_robot_to_robot` samples
the volume about the two robots' bases, keeps the points both robots reach with their tools
pointing straight down (each through :meth:`robotcell.cell.Cell.ik` of its own view, a robot on
a track at the track position it will touch from: 0 unless given), and builds designs of K common points (:data:`SIZES`) spread over that common
volume by farthest-point selection. For each design the calibration of exact touches with
``sigma = noise`` gives the *predicted* 1-sigma of ``T_ref_other`` (first-order propagation, the
covariance :func:`robotcell.calibration.robottorobot.robot_to_robot` reports), and a Monte Carlo
run (``runs`` calibrations of touches with Gaussian TCP errors of ``noise`` per coordinate)
gives the RMS of the actual pose errors. Docs: docs/calibration.md, "Robot to robot".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.robottorobot import RobotTouches, robot_to_robot
from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.kinematics.transforms import invert, make_pose, transform_points
from robotcell.studies.plan import LEVER, NOISE_MIN, pose_error

__all__ = ["SIZES", "R2RDesign", "R2RPlan", "common_volume", "plan_robot_to_robot"]

#: Numbers of common points of the proposed designs.
SIZES = (3, 4, 5, 6)

#: Tool pointing straight down in the world: its Z along -Z of the world.
_DOWN = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class R2RDesign:
    """One design of common points and its predicted uncertainty.

    Attributes
    ----------
    points : ndarray, shape (K, 3)
        The common points in the reference robot's base (m).
    position : float
        Predicted 1-sigma of the position of ``T_ref_other`` (m, length of the 3-vector).
    rotation : float
        Predicted 1-sigma of its rotation (rad, length of the rotation-vector sigma).
    position_rms, rotation_rms : float
        RMS of the Monte Carlo pose errors (m, rad); NaN without runs.
    """

    points: NDArray[np.float64]
    position: float
    rotation: float
    position_rms: float = float("nan")
    rotation_rms: float = float("nan")


@dataclass(frozen=True)
class R2RPlan:
    """The designs of a robot-to-robot plan.

    Attributes
    ----------
    designs : list of R2RDesign
        One per number of points (:data:`SIZES`, those the common points sampled allow),
        fewest first.
    best : R2RDesign
        The recommended design: the smallest predicted 1-sigma of a point ``LEVER`` from the
        other robot's base, ``sqrt(position^2 + (LEVER * rotation)^2)``.
    reachable : int
        How many sampled points both robots reach.
    tools : tuple of str
        The tools of the reference and the other robot that touch.
    """

    designs: list[R2RDesign]
    best: R2RDesign
    reachable: int
    tools: tuple[str, str]


def _tool(view: Cell, robot: str, tool: str | None) -> str:
    """The tool ``robot`` touches with: ``tool``, or its first tool in the cell."""
    if tool is None:
        if not view.tools:
            raise InputError(f"robot {robot!r} has no tool in the cell; add the tool it touches "
                             "with")
        return next(iter(view.tools))
    if tool not in view.tools:
        raise InputError(f"robot {robot!r} has no tool {tool!r}; its tools: "
                         f"{', '.join(view.tools) or 'none'}")
    return tool


def _track(cell: Cell, robot: str, track: float) -> float | None:
    """``track`` (m) for ``robot``: None for a robot without a track (where it must be 0).

    Raises
    ------
    InputError
        A track position for a robot without a track, or outside its track's limits.
    """
    t = cell.for_robot(robot).track
    if t is None:
        if track != 0.0:
            raise InputError(f"robot {robot!r} has no track; do not give its track position")
        return None
    if not t.within_limits(track):
        raise InputError(f"track position {track * 1e3:g} mm of robot {robot!r} is outside its "
                         f"track limits {t.lower * 1e3:g} .. {t.upper * 1e3:g} mm")
    return track


def _reaches(cell: Cell, robot: str, tool: str, p_world: NDArray[np.float64],
             track: float | None) -> NDArray[np.bool_]:
    """Which world points (N, 3) ``robot`` reaches with ``tool`` pointing down, at ``track``
    (m; None without a track)."""
    view = cell.for_robot(robot)
    T = make_pose(np.broadcast_to(_DOWN, (len(p_world), 3, 3)), p_world)
    sol = view.ik(T, "world", track=track, tool=tool)
    return np.asarray(sol.valid, dtype=bool).any(axis=-1)


def common_volume(cell: Cell, robots: tuple[str, str], tools: tuple[str, str], *,
                  samples: int = 400, rng: np.random.Generator,
                  tracks: tuple[float, float] = (0.0, 0.0)) -> NDArray[np.float64]:
    """Points of the world (M, 3, m) both robots reach with their tools pointing down.

    Samples ``samples`` points uniformly in the box spanning the two bases (each at its track
    position ``tracks``, m; 0 for a robot without a track) widened by 1 m in x and y, 0.1 m to
    1.2 m above the lower base.
    """
    at = [_track(cell, r, x) for r, x in zip(robots, tracks)]
    bases = np.array([cell.for_robot(r).frame_pose("robot", track=x or 0.0)[:3, 3]
                      for r, x in zip(robots, at)])
    lo = np.array([*(bases[:, :2].min(axis=0) - 1.0), bases[:, 2].min() + 0.1])
    hi = np.array([*(bases[:, :2].max(axis=0) + 1.0), bases[:, 2].min() + 1.2])
    p = lo + rng.random((samples, 3)) * (hi - lo)
    ok = _reaches(cell, robots[0], tools[0], p, at[0])
    ok[ok] = _reaches(cell, robots[1], tools[1], p[ok], at[1])
    return p[ok]


def _spread(points: NDArray[np.float64], k: int) -> NDArray[np.int64]:
    """Indices of ``k`` points chosen by farthest-point selection from the two farthest apart."""
    d = np.linalg.norm(points[:, None] - points[None], axis=-1)
    chosen = list(np.unravel_index(d.argmax(), d.shape))
    while len(chosen) < k:
        chosen.append(int(d[:, chosen].min(axis=1).argmax()))
    return np.array(chosen[:k])


def _predict(p_ref: NDArray[np.float64], p_oth: NDArray[np.float64], noise: float,
             runs: int, rng: np.random.Generator, T_true: NDArray[np.float64]) -> R2RDesign:
    """Predicted 1-sigma (and Monte Carlo RMS) of ``T_ref_other`` from touches of the points."""
    names = tuple(f"P{i + 1}" for i in range(len(p_ref)))
    res = robot_to_robot(RobotTouches(p_ref, names, robot="ref"),
                         RobotTouches(p_oth, names, robot="other"), sigma=noise)
    sp = float(np.linalg.norm(res.sigma["T_ref_other_position"]))
    sr = float(np.linalg.norm(res.sigma["T_ref_other_rotation"]))
    errors = np.array([pose_error(robot_to_robot(
        RobotTouches(p_ref + rng.normal(0.0, noise, p_ref.shape), names, robot="ref"),
        RobotTouches(p_oth + rng.normal(0.0, noise, p_oth.shape), names, robot="other"),
        sigma=noise).values["T_ref_other"], T_true) for _ in range(runs)]).reshape(-1, 2)
    rms = np.sqrt(np.mean(errors**2, axis=0)) if runs else np.full(2, np.nan)
    return R2RDesign(p_ref, sp, sr, float(rms[0]), float(rms[1]))


def plan_robot_to_robot(cell: Cell, robot: str, reference: str, *,
                        tools: tuple[str | None, str | None] = (None, None), noise: float,
                        runs: int = 0, seed: int | None = None, candidates: int = 400,
                        tracks: tuple[float, float] = (0.0, 0.0)) -> R2RPlan:
    """Designs of K common points (:data:`SIZES`) both robots touch, with their predicted 1-sigma.

    Parameters
    ----------
    cell : Cell
        A cell of several robots, taken as the truth (bases, tools).
    robot : str
        The robot whose base is calibrated.
    reference : str
        The robot whose base the result (and the points) are in.
    tools : tuple of (str or None)
        The tools of the reference robot and of ``robot`` that touch; None: each robot's first.
    noise : float
        Touch accuracy (m, 1-sigma per coordinate), > 0.
    runs : int
        Monte Carlo calibrations per design (0: prediction only).
    seed : int, optional
        Seed of the sampled volume and of the Monte Carlo errors.
    candidates : int
        Points sampled about the two bases (the common volume is those both reach; a design
        of K points needs K of them).
    tracks : tuple of float
        The track positions (m) the reference robot and ``robot`` touch from; 0 for a robot
        without a track. The predicted 1-sigma is that of the two bases at those positions (the
        tracks' own errors are not counted: a track's calibration adds its stated sigma).

    Returns
    -------
    R2RPlan

    Raises
    ------
    InputError
        A cell of one robot, an unknown robot or tool, the same robot twice, a noise below
        :data:`robotcell.studies.plan.NOISE_MIN` or not finite, a track position for a robot without a track or outside its limits, or fewer
        than 3 sampled points both robots reach.
    """
    if len(cell.robots) < 2:
        raise InputError("the cell has one robot; a robot-to-robot plan needs a cell of two or "
                         "more robots")
    names = (cell.robot_key(reference), cell.robot_key(robot))
    if names[0] == names[1]:
        raise InputError(f"the reference and the other robot are both {robot!r}; name two "
                         "robots of the cell")
    if not (math.isfinite(noise) and noise >= NOISE_MIN):
        raise InputError(f"noise must be a positive distance (m) of at least {NOISE_MIN:g} (1 um, "
                         f"below any touch-up accuracy), got {noise!r}")
    use = (_tool(cell.for_robot(names[0]), names[0], tools[0]),
           _tool(cell.for_robot(names[1]), names[1], tools[1]))
    rng = np.random.default_rng(seed)
    p_w = common_volume(cell, names, use, samples=candidates, rng=rng, tracks=tracks)
    sizes = [k for k in SIZES if k <= len(p_w)]
    if not sizes:
        raise InputError(f"robots {names[0]!r} and {names[1]!r} reach {len(p_w)} of "
                         f"{candidates} sampled points with their tools pointing down, fewer "
                         f"than {min(SIZES)}: no common reachable volume; move the robots or "
                         "their tracks closer")
    # each robot records its touches in its base at the track position it touches from
    T_w_ref, T_w_oth = (cell.for_robot(n).frame_pose("robot", track=x)
                        for n, x in zip(names, tracks))
    T_true = invert(T_w_ref) @ T_w_oth
    p_ref, p_oth = transform_points(invert(T_w_ref), p_w), transform_points(invert(T_w_oth), p_w)
    order = _spread(p_w, max(sizes))
    designs = [_predict(p_ref[order[:k]], p_oth[order[:k]], noise, runs, rng, T_true)
               for k in sizes]
    best = min(designs, key=lambda d: np.hypot(d.position, LEVER * d.rotation))
    return R2RPlan(designs, best, len(p_w), use)
