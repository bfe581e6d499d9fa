"""Several robots' paths matched by time: the points of a coordinated program from the files'
``time`` columns.

Point ``k`` of every robot's path in a coordinated program is reached together. Paths without
times are matched by index (they have as many points). Paths whose files all have a ``time``
column (s) are matched by time: the program's points are the union of the files' times (times
within :data:`robotcell.programs.path.TIME_TOL` of each other are one), and a robot's pose at a
time its file does not hold is where the controller's motion between its two points puts the
TCP at that fraction of the time:

- a linear motion (``lin``) to the next point: the position on the straight line, the
  orientation turned about one axis at a constant rate (spherical linear interpolation,
  ``scipy.spatial.transform.Rotation``), as a linear motion moves the TCP;
- a joint motion (``ptp``): refused. A joint motion moves the axes, not the TCP, along a line;
  its TCP between the points follows from the arm's joints at both ends, which are only solved
  after the points are chosen, and from the controller's own synchronisation of the axes.
  Give that time in the file, or make the motion linear.

The track (where the file gives it) and the table's values (where the file gives them) are
interpolated linearly; an inserted point moves ``lin`` with the speed and zone of the motion it
is on. The first times of all files agree, and so do the last ones (within the tolerance).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from robotcell.errors import InputError
from robotcell.programs.path import TIME_TOL, PathTargets

__all__ = ["at_times", "match_by_time", "union_times"]


def union_times(times: list[NDArray[np.float64]]) -> NDArray[np.float64]:
    """The sorted union of several increasing time series (s), times within
    :data:`~robotcell.programs.path.TIME_TOL` of the one before counted once.

    Parameters
    ----------
    times : list of ndarray, each shape (N_i,)

    Returns
    -------
    ndarray, shape (N,)
    """
    t = np.sort(np.concatenate(times))
    keep = np.concatenate([[True], np.diff(t) > TIME_TOL])
    # a run of times each within the tolerance of the one before is one time, its first
    return t[keep]


def _rows(path: PathTargets, times: NDArray[np.float64]
          ) -> tuple[NDArray[np.intp], NDArray[np.bool_], NDArray[np.float64]]:
    """For each time: the path's point at or after it (N,), whether the path holds that time
    (N,), and the fraction of the motion to that point done at it (N,)."""
    own = path.time
    k = np.clip(np.searchsorted(own, times - TIME_TOL), 0, len(own) - 1)
    exact = np.abs(own[k] - times) <= TIME_TOL
    start = np.maximum(k - 1, 0)
    span = np.where(exact, 1.0, own[k] - own[start])
    frac = np.where(exact, 1.0, (times - own[start]) / span)
    return k, exact, frac


def at_times(path: PathTargets, times: NDArray[np.float64]) -> PathTargets:
    """The path at ``times`` (s): its own points where it holds a time, poses interpolated as
    the controller moves a linear motion elsewhere.

    Parameters
    ----------
    path : PathTargets
        With ``time``; its first and last times are the first and last of ``times``.
    times : ndarray, shape (N,)
        Increasing times (s), each of the path's among them.

    Returns
    -------
    PathTargets
        N points, ``time`` = ``times``, ``lines`` 0 at the points put in.

    Raises
    ------
    InputError
        A time that falls on a joint motion (``ptp``) of the path, naming the file and line.
    """
    k, exact, frac = _rows(path, times)
    start = np.maximum(k - 1, 0)
    ptp = np.flatnonzero(~exact & (np.asarray(path.motion)[k] == "ptp"))
    if ptp.size:
        i = int(ptp[0])
        raise InputError(f"{path.line(int(k[i]))}: the motion to this point is a joint motion "
                         f"(ptp), and another path has a point at {times[i]:g} s on it; a joint "
                         "motion's TCP between its points is not interpolated: give that time "
                         "in this file, or make the motion lin")
    T = path.T[k].copy()
    T[:, :3, 3] = (1 - frac)[:, None] * path.T[start, :3, 3] + frac[:, None] * T[:, :3, 3]
    r0 = Rotation.from_matrix(path.T[start, :3, :3])
    turn = (r0.inv() * Rotation.from_matrix(path.T[k, :3, :3])).as_rotvec()
    T[:, :3, :3] = (r0 * Rotation.from_rotvec(frac[:, None] * turn)).as_matrix()
    T[exact] = path.T[k[exact]]

    def lerp(v: NDArray[np.float64]) -> NDArray[np.float64]:
        f = frac.reshape(-1, *([1] * (v.ndim - 1)))
        return np.where(exact.reshape(f.shape), v[k], (1 - f) * v[start] + f * v[k])

    motion = [path.motion[j] if e else "lin" for j, e in zip(k, exact)]
    lines = np.where(exact, path.lines[k] if path.lines is not None else k + 2, 0)
    return replace(path, T=T, motion=motion, speed=path.speed[k], zone=path.zone[k],
                   track=None if path.track is None else lerp(path.track),
                   table=lerp(path.table), extra={}, time=np.asarray(times, dtype=float),
                   lines=lines)


def match_by_time(paths: Mapping[str, PathTargets]) -> dict[str, PathTargets]:
    """The robots' paths at the union of their times, when every file has times.

    Parameters
    ----------
    paths : mapping of str to PathTargets
        Each robot's path.

    Returns
    -------
    dict of str to PathTargets
        The paths unchanged when no file has times; else each at the union of all times
        (:func:`at_times`).

    Raises
    ------
    InputError
        Some files with times and some without (naming both), first or last times that differ
        (naming each file's), a time on a joint motion (:func:`at_times`).
    """
    timed = {r: p for r, p in paths.items() if p.time is not None}
    if not timed:
        return dict(paths)
    if len(timed) < len(paths):
        without = [p.source for p in paths.values() if p.time is None]
        one = len(timed) == 1
        raise InputError(f"{', '.join(p.source for p in timed.values())} "
                         f"{'gives' if one else 'give'} a time column and {', '.join(without)} "
                         f"{'does' if len(without) == 1 else 'do'} not: points are matched by "
                         "time only when every file gives times; add the column to every file, "
                         "or remove it")
    for end, what in ((0, "first"), (-1, "last")):
        ends = np.array([p.time[end] for p in timed.values()])
        if np.ptp(ends) > TIME_TOL:
            raise InputError(f"the paths' {what} times differ: "
                             + ", ".join(f"{p.source} {p.time[end]:g} s" for p in timed.values())
                             + "; every robot's path starts and ends together")
    times = union_times([p.time for p in timed.values()])
    return {r: at_times(p, times) for r, p in paths.items()}
