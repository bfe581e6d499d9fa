"""A program's clearance: where its robot comes closer than a limit to the cell's parts.

The points whose joints are known are checked with :func:`robotcell.clearance.clearance`, one
run of consecutive points with one tool at a time; a linear motion (``lin``) is followed as the
controller moves, a circular one (``circ``) along its chord (docs/clearance.md), every other
motion in joint space. A point closer than the limit gets a problem naming the distance and the
pair; so does a motion between two clear points that comes closer on its way (at its end point).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from robotcell.cell.model import Cell
from robotcell.clearance import Clearance, clearance
from robotcell.clearance.bodies import BodiesFile

__all__ = ["CLEARANCE", "clearance_problems", "problem_text"]

#: Default smallest good clearance between the robot and a part (m): 10 mm, a margin for the
#: capsules' fit of the real links, not a safety distance (docs/clearance.md).
CLEARANCE = 0.010


def _runs(known: NDArray[np.bool_], tools: NDArray[np.float64]) -> list[NDArray[np.intp]]:
    """Runs of consecutive known points with one tool."""
    runs: list[list[int]] = []
    for i in np.flatnonzero(known):
        if runs and runs[-1][-1] == i - 1 and np.array_equal(tools[i], tools[i - 1]):
            runs[-1].append(int(i))
        else:
            runs.append([int(i)])
    return [np.array(r) for r in runs]


def clearance_problems(cell: Cell, motions: Sequence[str], q: NDArray[np.float64],
                       track: NDArray[np.float64], table: NDArray[np.float64],
                       tools: NDArray[np.float64], bodies: BodiesFile, limit: float
                       ) -> list[list[str]]:
    """Clearance problems of each point of a program.

    Parameters
    ----------
    cell : Cell
    motions : sequence of str
        Each point's motion (``ptp``, ``lin``, ``circ`` ...), length N.
    q : ndarray, shape (N, n)
        Joint values (rad, m; NaN where not known: those points are not checked).
    track : ndarray, shape (N,)
        Track values (m).
    table : ndarray, shape (N,) or (N, k)
        Table or positioner values (rad).
    tools : ndarray, shape (N, 4, 4)
        ``T_F_TCP`` of each point (m).
    bodies : BodiesFile
        The cell's parts, the arm's radii, the pairs never reported.
    limit : float
        Smallest good clearance (m).

    Returns
    -------
    list of list of str
        The problems of each point (empty where the point and the motion to it are clear).
    """
    problems: list[list[str]] = [[] for _ in range(len(q))]
    known = np.isfinite(q).all(axis=-1) & np.isfinite(tools).all(axis=(1, 2))
    for run in _runs(known, tools):
        kinds = ["linear" if motions[i] in ("lin", "circ") else "joint" for i in run[1:]]
        got = clearance(cell, q[run], track=track[run], table=table[run], tool=tools[run[0]],
                        bodies=bodies, motion=kinds)
        at_points = got.per_point()
        for k, i in enumerate(run):
            if at_points[k] < limit:
                problems[i].append(problem_text("clearance", got, k, at_points[k], limit))
        if len(run) > 1:
            along = got.per_segment()
            for k in np.flatnonzero((along < limit) & (at_points[1:] >= limit)
                                    & (at_points[:-1] >= limit)):
                problems[run[k + 1]].append(problem_text("on the way here, clearance", got,
                                                         k + 0.5, along[k], limit))
    return problems


def problem_text(what: str, got: Clearance, where: float, distance: float, limit: float) -> str:
    """``clearance 8.3 mm between link6 and plate (limit 10 mm)`` for the closest pair within
    half a segment of ``where``."""
    inside = np.flatnonzero(np.abs(got.position - where) <= 0.5 + 1e-9)
    a, b = got.pair[inside[np.argmin(got.distance[inside])]]
    if distance < 0:
        return (f"{what}: {a} and {b} overlap by {-distance * 1e3:.1f} mm "
                f"(limit {limit * 1e3:g} mm)")
    return f"{what} {distance * 1e3:.1f} mm between {a} and {b} (limit {limit * 1e3:g} mm)"
