"""Robots of one controller placed in each other: the data of a coordinated pair.

A FANUC or YASKAWA controller that moves several robots (motion groups 1, 2, ...) holds where
each robot stands in another one's reference frame: FANUC's coordinated pair (MENU > SETUP >
Coord: the leader's WORLD in the follower's WORLD), YASKAWA's robot calibration (R2's robot
coordinates in R1's). :func:`robot_pairs` computes these poses from a cell of several robots,
taking the cell file's order of robots as the order of the motion groups (the first robot is
group 1, R1); each vendor's export writes them in its words (``docs/export.md``, "Robots of one
controller").

Only robots on a fixed base are paired: on a track, what the controller places (the track's
origin, or a robot frame that moves with the track) depends on the controller's setup of that
axis, which the sources do not state; such a pair is named with the reason instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell
from robotcell.kinematics.transforms import invert

__all__ = ["RobotPair", "robot_pairs"]


@dataclass(frozen=True)
class RobotPair:
    """One robot placed in the base of the robot of group 1.

    Attributes
    ----------
    reference, other : str
        Names of the robots in the cell: group 1 (the cell's first robot) and group ``group``.
    group : int
        Motion group number of ``other`` (its place in the cell file's ``robots:``, from 1).
    pose : ndarray, shape (4, 4), or None
        ``T_Rref_Rother``: the other robot's base in the reference robot's base (metres); None
        when it cannot be written (``why``).
    why : str
        Why no pose is given (empty when one is).
    provenance : str
        Where the other robot's base comes from, for the listing (``robot-to-robot, rms 0.120
        mm``; ``nominal``).
    """

    reference: str
    other: str
    group: int
    pose: NDArray[np.float64] | None
    why: str = ""
    provenance: str = ""


def _provenance(cell: Cell, name: str) -> str:
    p = cell.robots[name].base_provenance
    return p.source + (f", rms {p.rms_mm:.3f} mm" if p.rms_mm is not None else "")


def robot_pairs(cell: Cell, limit: int | None = None) -> list[RobotPair]:
    """Every robot of ``cell`` after the first, placed in the first robot's base.

    Parameters
    ----------
    cell : Cell
        A cell of several robots (one robot: no pairs).
    limit : int, optional
        Pair only the robots up to motion group ``limit``; the others get ``why`` (a controller
        whose sources show one pair only).

    Returns
    -------
    list of RobotPair
        In the cell file's order; a robot on a track, or a pair with the first robot on a
        track, has ``pose`` None and the reason in ``why``.
    """
    names = list(cell.robot_names)
    if len(names) < 2:
        return []
    ref = names[0]
    pairs = []
    for group, other in enumerate(names[1:], start=2):
        on_track = [n for n in (ref, other) if cell.robots[n].track is not None]
        why = ""
        if limit is not None and group > limit:
            why = f"group {group}: the sources show the pair of groups 1 and 2 only"
        elif on_track:
            why = (f"{' and '.join(on_track)} on a track: what the controller places then "
                   "depends on its setup of the track axis, which the sources do not state")
        pose = None if why else invert(cell.robots[ref].T_world_R) @ cell.robots[other].T_world_R
        pairs.append(RobotPair(ref, other, group, pose, why, _provenance(cell, other)))
    return pairs
