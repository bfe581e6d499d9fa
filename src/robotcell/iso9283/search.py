"""The largest test cube inside the reach of an arm, with one tool orientation.

A cube is *clear* when one arm configuration (one analytic branch of the IK) reaches every
sample point of it, with the TCP in the orientation given, within every joint limit and away
from singular configurations: ``sqrt(det(J J^T))`` (Yoshikawa's manipulability, ``|det J|`` for
a six-axis arm) at least :data:`MIN_MANIPULABILITY` times the arm's largest over random
configurations (:func:`manipulability_scale`). The samples are a grid over the whole cube
(:data:`SEARCH_GRID` points per edge while searching, :data:`CHECK_GRID` for the cube kept) and
every point of the test poses and paths.

The cube's edges are parallel to the robot base frame R. Its centre is searched on a grid of
the plane ``y = 0`` of R (in front of the arm), its edge by bisection at every centre at once;
its lowest face stays on or above the base plane ``z = 0`` of R, clear of the floor, track or
pedestal the arm stands on. The best centre is then refined on finer local grids.
"""

from __future__ import annotations

import weakref

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError
from robotcell.iso9283.cube import (
    circle_points,
    grid_points,
    line_points,
    pose_points,
    with_orientation,
)
from robotcell.robot.robot import Robot

__all__ = ["CHECK_GRID", "MIN_MANIPULABILITY", "SEARCH_GRID", "clear_branches", "cube_points",
           "largest_cube", "manipulability_scale"]

#: Smallest manipulability at a sample point, as a fraction of :func:`manipulability_scale`.
MIN_MANIPULABILITY = 0.05
#: Grid points per edge of the cube while searching, and for the cube kept.
SEARCH_GRID = 3
CHECK_GRID = 5
#: Centres per axis of the coarse search grid; rounds and centres per axis of its refinement.
CENTRE_GRID = 8
REFINE_ROUNDS, REFINE_GRID = 3, 5
#: Bisection steps of the edge (the edge is then known to the arm's reach / 2**steps).
BISECTION_STEPS = 12
#: Factor by which the edge shrinks when the fine check fails, and the most shrinks tried.
SHRINK, MAX_SHRINKS = 0.98, 25
#: Random configurations that set the manipulability scale and the reach of an arm.
SAMPLES = 4096

#: Per arm, per tool (its bytes): what :func:`manipulability_scale` found.
_SCALES: weakref.WeakKeyDictionary[Robot, dict[bytes, tuple[float, float, float, float]]] = \
    weakref.WeakKeyDictionary()


def manipulability_scale(robot: Robot, tool: NDArray[np.float64] | None = None
                         ) -> tuple[float, float, float, float]:
    """The arm's largest manipulability and the extent of its reach, from seeded samples.

    Parameters
    ----------
    robot : Robot
    tool : ndarray, shape (4, 4), optional
        ``T_F_TCP`` (m); only the reach depends on it.

    Returns
    -------
    scale : float
        Largest ``sqrt(det(J J^T))`` over :data:`SAMPLES` configurations within the limits
        (revolute axes within ``[-pi, pi]``; m^3 for a six-axis arm).
    radius : float
        Largest horizontal distance of the TCP from the Z axis of R (m).
    z_low, z_high : float
        Lowest and highest TCP height in R (m).
    """
    known = _SCALES.setdefault(robot, {})
    key = b"" if tool is None else np.asarray(tool, dtype=float).tobytes()
    if key in known:
        return known[key]
    rng = np.random.default_rng(0)
    lo, hi = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
    q = rng.uniform(lo, hi, (SAMPLES, robot.n_joints))
    scale = float(np.max(_manipulability(robot, q)))
    p = robot.fk(q, tool=tool)[:, :3, 3]
    out = (scale, float(np.max(np.hypot(p[:, 0], p[:, 1]))), float(p[:, 2].min()),
           float(p[:, 2].max()))
    known[key] = out
    return out


def _manipulability(robot: Robot, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """``sqrt(det(J J^T))`` at joints ``q`` (..., n)."""
    J = robot.jacobian(q)
    return np.sqrt(np.abs(np.linalg.det(J @ np.swapaxes(J, -1, -2))))


def cube_points(size: float, grid: int) -> NDArray[np.float64]:
    """Every sample point of a cube: a grid over it, the test poses and the paths' points.

    Parameters
    ----------
    size : float
        Edge (m).
    grid : int
        Grid points per edge.

    Returns
    -------
    ndarray, shape (K, 3)
        Metres, in the cube's coordinates.
    """
    return np.vstack([grid_points(size, grid), pose_points(size), line_points(size),
                      circle_points(size)])


def clear_branches(robot: Robot, T_R_TCP: NDArray[np.float64], tool: NDArray[np.float64] | None,
                   floor: float) -> NDArray[np.bool_]:
    """Which IK branches reach every target within the limits and away from singularities.

    Parameters
    ----------
    robot : Robot
    T_R_TCP : ndarray, shape (..., K, 4, 4)
        Targets in R (m), K per batch entry.
    tool : ndarray, shape (4, 4) or None
        ``T_F_TCP`` (m).
    floor : float
        Smallest manipulability (m^3 for a six-axis arm).

    Returns
    -------
    ndarray of bool, shape (..., 8)
        Branch ``k`` clears all K targets of the entry.
    """
    sol = robot.ik(T_R_TCP, tool=tool)
    ok = sol.valid.copy()
    if ok.any():
        ok[ok] = _manipulability(robot, sol.q[ok]) >= floor
    return ok.all(axis=-2)


def _capacity(robot: Robot, tool: NDArray[np.float64] | None, R_R_TCP: NDArray[np.float64],
              centres: NDArray[np.float64], top: NDArray[np.float64], floor: float
              ) -> NDArray[np.float64]:
    """The largest clear edge (m) at each of ``centres`` (M, 3), up to ``top`` (M,): bisection
    on the search grid; 0 where not even the centre is clear."""
    lo, hi = np.zeros(len(centres)), top.copy()
    T = np.tile(np.eye(4), (len(centres), 1, 1))
    T[:, :3, 3] = centres
    for _ in range(BISECTION_STEPS):
        mid = (lo + hi) / 2
        pts = grid_points(1.0, SEARCH_GRID)[None] * mid[:, None, None]
        targets = with_orientation(np.eye(4), pts.reshape(-1, 3), R_R_TCP)
        targets[:, :3, 3] += np.repeat(centres, len(pts[0]), axis=0)
        ok = clear_branches(robot, targets.reshape(len(centres), -1, 4, 4), tool, floor)
        ok = ok.any(axis=-1)
        lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
    return lo


def _grid_centres(centre: NDArray[np.float64], step: NDArray[np.float64], n: int
                  ) -> NDArray[np.float64]:
    """An ``n x n`` grid of centres in the plane ``y = 0`` around ``centre`` (x, z spacing
    ``step``)."""
    k = np.arange(n) - (n - 1) / 2
    x, z = np.meshgrid(centre[0] + k * step[0], centre[2] + k * step[1], indexing="ij")
    return np.column_stack([x.ravel(), np.zeros(x.size), z.ravel()])


def largest_cube(robot: Robot, tool: NDArray[np.float64] | None, R_R_TCP: NDArray[np.float64],
                 centre: NDArray[np.float64] | None = None
                 ) -> tuple[NDArray[np.float64], float]:
    """The centre and edge of the largest clear cube (coarse: :data:`SEARCH_GRID` samples).

    Parameters
    ----------
    robot : Robot
    tool : ndarray, shape (4, 4) or None
        ``T_F_TCP`` (m).
    R_R_TCP : ndarray, shape (3, 3)
        The TCP's orientation in R.
    centre : ndarray, shape (3,), optional
        The cube's centre in R (m); default searched.

    Returns
    -------
    centre : ndarray, shape (3,)
        In R (m).
    size : float
        Edge (m); 0 when no cube is clear.
    """
    scale, radius, z_low, z_high = manipulability_scale(robot, tool)
    floor = MIN_MANIPULABILITY * scale
    if centre is not None:
        c = np.asarray(centre, dtype=float)[None]
        return c[0], float(_capacity(robot, tool, R_R_TCP, c, np.array([radius]), floor)[0])
    lo_z = max(z_low, 0.0)
    step = np.array([radius, z_high - lo_z]) / CENTRE_GRID
    centres = _grid_centres(np.array([radius / 2, 0.0, (lo_z + z_high) / 2]), step, CENTRE_GRID)
    best, size = centres[0], 0.0
    for _ in range(1 + REFINE_ROUNDS):
        keep = centres[:, 2] > 0
        centres = centres[keep]
        top = np.minimum(2 * centres[:, 2], radius)  # the lowest face stays above z = 0 of R
        cap = _capacity(robot, tool, R_R_TCP, centres, top, floor)
        k = int(np.argmax(cap))
        if cap[k] > size:
            best, size = centres[k], float(cap[k])
        step = step / 2
        centres = _grid_centres(best, step, REFINE_GRID)
    return best, size


def shrink_until_clear(robot: Robot, tool: NDArray[np.float64] | None,
                       R_R_TCP: NDArray[np.float64], centre: NDArray[np.float64], size: float,
                       shrink: bool = True) -> tuple[float, int]:
    """The largest edge up to ``size``, in steps of :data:`SHRINK`, whose cube clears the fine
    check (:data:`CHECK_GRID` samples, the test poses and paths), and the branch that clears it.

    Parameters
    ----------
    robot : Robot
    tool : ndarray, shape (4, 4) or None
    R_R_TCP : ndarray, shape (3, 3)
    centre : ndarray, shape (3,)
        In R (m).
    size : float
        Edge to start from (m).
    shrink : bool
        False: check ``size`` only.

    Returns
    -------
    size : float
        Metres.
    branch : int
        The IK branch (``4 * shoulder + 2 * elbow + wrist``) that clears it with the largest
        smallest manipulability.

    Raises
    ------
    InputError
        No cube of this centre clears the check.
    """
    scale = manipulability_scale(robot, tool)[0]
    T_R_cube = np.eye(4)
    T_R_cube[:3, 3] = centre
    for _ in range(MAX_SHRINKS if shrink else 1):
        if size <= 0:
            break
        targets = with_orientation(T_R_cube, cube_points(size, CHECK_GRID), R_R_TCP)
        sol = robot.ik(targets, tool=tool)
        m = np.where(sol.valid, _manipulability(robot, np.nan_to_num(sol.q)), 0.0)
        worst = m.min(axis=0)
        if worst.max() >= MIN_MANIPULABILITY * scale:
            return size, int(np.argmax(worst))
        size *= SHRINK
    if not shrink:
        raise InputError(f"the cube of edge {size * 1e3:g} mm is not clear on a grid of "
                         f"{CHECK_GRID} points per edge: give a smaller size")
    raise InputError("no test cube at this place is clear: the arm does not reach it in one "
                     "configuration with the tool orientation given, within its limits and away "
                     "from singular configurations; give another orientation or centre")
