"""Configurations to measure for an identification, inside the space the robot may use
(``robotcell identify --propose N``).

:func:`propose_configurations` takes the nominal model (a robot, or a cell's ``robot.model``),
the work volume (a box in the robot base frame, else the floor: the cell's world ``z >= 0``, or
the robot's base plane ``z >= 0`` without a cell), draws the candidates inside it
(:func:`robotcell.identification.workvolume.configurations_within`) and selects those of the
highest observability (:func:`robotcell.identification.validation.select_configurations`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.identification.validation import PoseSelection, select_configurations
from robotcell.identification.workvolume import WorkVolume, configurations_within
from robotcell.kinematics.transforms import invert
from robotcell.robot.models import load_robot
from robotcell.robot.robot import Robot

__all__ = ["CANDIDATES", "Proposal", "propose_configurations", "work_volume"]

#: Random configurations within the joint limits and the work volume the proposal picks from.
CANDIDATES = 1000


@dataclass(frozen=True)
class Proposal:
    """What :func:`propose_configurations` proposes.

    Attributes
    ----------
    robot : Robot
        The nominal model.
    selection : PoseSelection
        The configurations (rad, m), their O1 and that of random sets of the candidates.
    volume : WorkVolume
        Where the flange and the reflectors of every candidate are.
    """

    robot: Robot
    selection: PoseSelection
    volume: WorkVolume


def work_volume(box: ArrayLike | None = None, cell: Cell | None = None) -> WorkVolume:
    """The work volume of a proposal: the box, else the cell's floor, else the robot's base plane.

    Parameters
    ----------
    box : array_like, shape (6,), optional
        ``xmin, ymin, zmin, xmax, ymax, zmax`` in the robot base frame (m).
    cell : Cell, optional
        Without a box, its world's ``z >= 0`` (the floor), with the robot base where it is at
        track position 0.

    Returns
    -------
    WorkVolume
    """
    if box is not None:
        b = np.asarray(box, dtype=float)
        if b.shape != (6,):
            raise InputError(f"a box is 6 numbers xmin, ymin, zmin, xmax, ymax, zmax, got {b.size}")
        return WorkVolume.box(b[:3], b[3:])
    if cell is not None:
        return WorkVolume.above(invert(cell.frame_pose("robot")),
                                f"the floor of {cell.name} (z = 0 of its world)")
    return WorkVolume.above(np.eye(4), "the robot base plane (z = 0 of the robot base)")


def propose_configurations(n: int, robot: str | Path | None = None, cell: str | Path | None = None,
                           n_targets: int = 1, pose: bool = False, seed: int = 0,
                           sigma: float = 0.05e-3, angle_sigma: float = math.radians(0.02),
                           box: ArrayLike | None = None, cell_robot: str | None = None) -> Proposal:
    """Propose ``n`` configurations to measure: the most observable inside the work volume.

    Parameters
    ----------
    n : int
        Configurations to propose (1 to :data:`CANDIDATES` - 1).
    robot : str or Path, optional
        The nominal model (library name or model file); default the cell's ``robot.model``.
    cell : str or Path, optional
        A cell file: the nominal when ``robot`` is not given, and the floor without ``box``.
    n_targets : int
        Reflectors measured per configuration.
    pose : bool
        The orientation is measured too (one target).
    seed : int
        Seed of the candidates and of the random comparison sets.
    sigma, angle_sigma : float
        Accuracies (m, rad).
    box : array_like, shape (6,), optional
        The work volume, ``xmin, ymin, zmin, xmax, ymax, zmax`` in the robot base frame (m)
        (:func:`work_volume`).

    cell_robot : str, optional
        In a cell of several robots, the robot whose arm is proposed (a key of its
        ``robots``); None: the only robot.
    Returns
    -------
    Proposal

    Raises
    ------
    InputError
        Neither a robot nor a cell, ``n`` or ``n_targets`` out of range, orientation with several
        targets, a bad box, or a volume too small for the arm.
    """
    if robot is None and cell is None:
        raise InputError("propose needs the nominal model: a robot or a cell")
    if n < 1 or n_targets < 1:
        raise InputError(f"n and n_targets must be positive, got {n} and {n_targets}")
    if n >= CANDIDATES:
        raise InputError(f"n {n}: at most {CANDIDATES - 1} configurations (they are picked from "
                         f"{CANDIDATES} random candidates)")
    if pose and n_targets != 1:
        raise InputError("pose goes with one target per configuration (n_targets 1)")
    the_cell = None if cell is None else Cell.load(cell).for_robot(cell_robot)
    nominal = load_robot(robot) if robot is not None else the_cell.nominal_robot
    volume = work_volume(box, the_cell)
    candidates = configurations_within(nominal, volume, CANDIDATES, n_targets, pose, seed)
    sel = select_configurations(nominal, n, n_targets=n_targets, pose=pose, candidates=candidates,
                                seed=seed, sigma=sigma, angle_sigma=angle_sigma)
    return Proposal(nominal, sel, volume)
