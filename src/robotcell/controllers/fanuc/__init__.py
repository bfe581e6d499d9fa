"""FANUC R-30iA / R-30iB (TP): everything robotcell knows of the controller, in :data:`FANUC`.

- Poses: X, Y, Z (mm), W, P, R (deg), ``R = Rz(R) Ry(P) Rx(W)``.
- Export (:mod:`.export`): a Direct Entry listing of ``UTOOL[n]`` and ``UFRAME[n]`` in FANUC
  WORLD, the robot base at rail position 0; frames on the turntable at table axis 0, and the
  table's root as one more user frame.
- Programs (:mod:`.program`): ASCII listings ``NAME.ls``.
- Flags: ``CONFIG : 'F|N U|D T|B, t1, t4, t6'``: flip (J5 >= 0), elbow up, front, and the turn
  numbers of J1, J4, J6 (RoboDK's FANUC post).
- Slots: ``UTOOL[1..9]``, ``UFRAME[1..9]`` (more with extended frames: ``docs/export.md``);
  program names of at most 10 characters, in capitals.
- External axes: a rail as ``E1`` of group 1 (mm), the table's axes as group 2 ``J1..`` (deg).

Sources: ``docs/export.md`` and ``docs/programs.md``.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.controllers.axes import DEG, ExternalAxes, table_count
from robotcell.controllers.base import Controller, SlotRange
from robotcell.controllers.data import ControllerData
from robotcell.controllers.fanuc import export as listing
from robotcell.controllers.fanuc import program as tp
from robotcell.controllers.model import Config, Program, Ref
from robotcell.controllers.robotpairs import robot_pairs
from robotcell.errors import InputError
from robotcell.ik.config import arm_sides
from robotcell.ik.limits import TWO_PI
from robotcell.io.poseformats import FORMATS
from robotcell.robot.robot import Robot

__all__ = ["FANUC", "Fanuc"]

#: A comment line of a TP listing's ``/MN`` section: its line number, ``!``, the text, ``;``.
_COMMENT = re.compile(r"^\s*\d+\s*:\s*!(.*?);?\s*$", re.MULTILINE)
#: Axes (0-based) whose turn numbers ``CONFIG`` writes: J1, J4, J6.
_TURNING = (0, 3, 5)


def _turns(q: NDArray[np.float64]) -> NDArray[np.int_]:
    """Turn number of joint values (rad): 0 for |q| < 180 deg, +-1 up to 540 deg, ..."""
    return (np.sign(q) * np.floor((np.abs(q) + math.pi) / TWO_PI)).astype(int)


class Fanuc(Controller):
    """FANUC R-30iA / R-30iB (TP programs)."""

    name = "fanuc"
    label = "FANUC"
    pose_format = FORMATS["fanuc"]
    reference = "robot"
    table_frames = False
    world_ref = Ref(number=0, kind="base")
    world_name = "UF 0 (WORLD)"
    program_suffixes = (".ls",)
    comment = "!"
    program_files = "FANUC .ls"
    export_name = "frames.txt"
    name_limit = 10
    upper_names = True
    tool_slots = SlotRange("UTOOL", 1, 9)
    frame_slots = SlotRange("UFRAME", 1, 9)
    config_fields = ("flip", "down", "back", "turn1", "turn4", "turn6")
    edits_joints = True
    csv_config = ("config",)
    coordinated_missing = (
        "no public source states the frame of the follower's points in a COORD motion (the "
        "leader frame, which moves with the leader), so they can be neither computed nor "
        "checked")
    sources = (
        "Roboception rc_visard documentation, 'Pose formats: FANUC' (W, P, R)",
        ("industrialmonitordirect.com knowledge base, 'FANUC robot frame selection: UFRAME_NUM "
         "and UTOOL_NUM': UFRAME_NUM and UTOOL_NUM 0-9"),
        ("controller backups with extended frames: $MNUFRAME ARRAY[2,32] "
         "(irbzavalagit/UB10200_RBT01, sysframe.va), ARRAY[1,110] and $MNUTOOL ARRAY[1,15] "
         "(WILDER-SYSTEMS-LLC/git-ftp, sysframe.va)"),
        ("RoboDK Fanuc_R30iA post (ros-industrial-attic/robodk_postprocessors): program names "
         "cut to 10 characters, CONFIG flags and turn numbers, positions 'X =%10.3f  mm', "
         "'E1=%10.3f  mm'"),
        ("TP listings saved by FANUC controllers (JuniorNatalin/VASC, Backups/.../*.ls): "
         "'X =   -63.679  mm', 'P =      .153 deg', 'J1=     0.000  mm': 3 decimals, 10 "
         "characters"),
    )

    def pair_lines(self, cell: Cell) -> list[str]:
        return listing.pair_lines(robot_pairs(cell, limit=2))

    def format_export(self, data: ControllerData, cell_name: str) -> str:
        return listing.format_data(data, cell_name)

    def parse_export(self, text: str) -> ControllerData:
        return listing.parse(text)

    def write_program(self, program: Program, header: list[str]) -> dict[str, str]:
        return tp.write(program, header)

    def read_program(self, path: str | Path) -> tuple[Program, list[str]]:
        return tp.read(path)

    def comments(self, text: str) -> list[str]:
        """Comment lines of ``/MN``: ``  1:  ! text ;``."""
        return [m.group(1) for m in _COMMENT.finditer(text)]

    def point_names(self, n: int) -> list[str]:
        return [f"P[{i + 1}]" for i in range(n)]

    def config_values(self, robot: Robot, q: NDArray[np.float64]) -> NDArray[np.int_]:
        front, elbow = arm_sides(robot, q)
        flags = [q[..., 4] >= 0, ~elbow, ~front]
        return np.stack([f.astype(int) for f in flags] + [_turns(q[..., j]) for j in _TURNING],
                        axis=-1)

    def config_text(self, values: tuple[int, ...]) -> str:
        return tp.config_text(values)

    def configs_from_columns(self, path: str, cols: dict[str, Any]) -> list[Config]:
        out = []
        for i, text in enumerate(cols["config"]):
            try:
                out.append(tp.parse_config(str(text)))
            except InputError as exc:
                raise InputError(f"{path}: line {i + 2}: column 'config': {exc}") from None
        return out

    def external_axes(self, cell: Cell, pulses_per_degree: ArrayLike | None = None
                      ) -> ExternalAxes:
        n, chain = table_count(cell)
        return ExternalAxes(self.name, "E1" if cell.track is not None else None,
                            tuple(f"GP2:J{i + 1}" for i in range(n)), 1e3, (DEG,) * n, chain,
                            decimals=tp.TP_DECIMALS)

    def set_joints(self, lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
        return tp.set_joints(lines, idx, q)

    def set_pose(self, lines: list[str], idx: int, T: NDArray[np.float64],
                 config: Config | None = None) -> bool:
        return tp.set_pose(lines, idx, T, config)


#: The FANUC controller.
FANUC = Fanuc()
