"""The demo cell: a KUKA KR 16 on a 6 m linear track beside a turntable, true and nominal.

A welding torch, and a workpiece clamped on the table. The *true* cell (what the virtual
hardware really is) differs from the *nominal* cell (what the drawings say) by the errors a real
cell has: a tool a few millimetres off its CAD value, a robot base not quite aligned with its
track, a turntable placed centimetres from its layout position, a workpiece clamped off its
nominal place. The demo walk-through (:mod:`robotcell.demo`) commissions it; studies and
examples use it as a cell whose errors are known.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell, Frame, Tool, Track, Turntable
from robotcell.io.poseformats import pose_from_vendor
from robotcell.robot.models import load_robot

__all__ = ["DEMO_NOISE", "demo_cells", "seam_rows"]

#: Touch-up error of the demo (m, 1-sigma per coordinate): a careful technician with a pointed
#: tool on a sharp reference.
DEMO_NOISE = 1e-4

#: The seam of the demo program, in the workpiece frame 'part': (x, y, z) mm and (a, b, c) deg
#: of the torch on a circle of 200 mm, and the table angle (deg) at each point.
SEAM_POINTS = 36


def seam_rows() -> NDArray[np.float64]:
    """The demo seam as path rows ``x, y, z, a, b, c, table`` (mm, deg)."""
    k = np.arange(SEAM_POINTS)
    ang = np.radians(10.0 * k)
    return np.column_stack([200 * np.cos(ang), 200 * np.sin(ang), np.zeros_like(ang), 10.0 * k,
                            np.full_like(ang, 180.0), np.zeros_like(ang), 200.0 - 9.0 * k])


def _pose(x: float, y: float, z: float, a: float, b: float, c: float) -> NDArray[np.float64]:
    """Pose from KUKA X, Y, Z (mm), A, B, C (deg)."""
    return pose_from_vendor([x, y, z, a, b, c], "kuka")


def demo_cells() -> tuple[Cell, Cell]:
    """The demo's true cell and its nominal (as designed) cell.

    Returns
    -------
    truth, nominal : Cell
        Same robot, names and limits; the calibrated quantities differ.
    """
    robot = load_robot("kuka_kr16")

    def cell(T_L_R0: NDArray[np.float64], scale: float, T_world_B: NDArray[np.float64],
             T_F_TCP: NDArray[np.float64], T_B_W: NDArray[np.float64]) -> Cell:
        return Cell(
            robot=robot, robot_model="kuka_kr16", name="demo_kr16_track_turntable",
            track=Track(np.eye(4), T_L_R0, axis="x", scale=scale, lower=0.0, upper=6.0,
                        name="KL1500"),
            turntable=Turntable(T_world_B, parent="world", lower=-2 * math.pi, upper=2 * math.pi,
                                name="DKP_400"),
            tools={"torch": Tool(T_F_TCP, number=1, mass=3.2, cog=np.array([0.12, 0.0, 0.04]))},
            frames={"part": Frame(T_B_W, parent="turntable", number=1)},
        )

    truth = cell(_pose(0.8, -1.1, 450.3, 0.05, -0.03, 0.02), 1.0002,
                 _pose(3004.2, 1247.1, 551.6, 90.3, 0.12, -0.08),
                 _pose(313.7, -2.1, 94.2, 0.6, 45.4, -0.3),
                 _pose(152.3, -78.6, 121.1, 15.8, 0.1, -0.05))
    nominal = cell(_pose(0, 0, 450, 0, 0, 0), 1.0,
                   _pose(3000, 1250, 550, 90, 0, 0),
                   _pose(312.5, 0, 95, 0, 45, 0),
                   _pose(150, -80, 120, 15, 0, 0))
    return truth, nominal
