"""KUKA KR C4 / KR C5: everything robotcell knows of the controller, in :data:`KUKA`.

- Poses: X, Y, Z (mm), A, B, C (deg), ``R = Rz(A) Ry(B) Rx(C)``.
- Export (:mod:`.export`): ``$config.dat`` ``TOOL_DATA``/``BASE_DATA``/``MACHINE_DEF`` and
  ``$machine.dat`` ``$ROBROOT``/``$ERSYSROOT``/``$ETk_*`` lines, in ``$WORLD``; bases on the
  turntable through ``EK(...)``.
- Programs (:mod:`.program`): ``NAME.src`` with ``NAME.dat``.
- Flags: Status and Turn (:func:`robotcell.ik.config.kuka_status_turn`).
- Slots: ``TOOL_DATA[1..16]``, ``BASE_DATA[1..32]``; names of at most 24 characters.
- External axes: ``E1..E6``, the track first (mm), the table's axes after it (deg).

Sources: ``docs/export.md`` and ``docs/programs.md``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.controllers.axes import ExternalAxes, numbered_axes
from robotcell.controllers.base import Controller, IkFlags, SlotRange, ZeroOffsets
from robotcell.controllers.data import ControllerData, Slot
from robotcell.controllers.kuka import export as dat
from robotcell.controllers.kuka import program as krl
from robotcell.controllers.model import Config, Program, Ref
from robotcell.errors import InputError
from robotcell.ik.config import kuka_status_turn
from robotcell.io.poseformats import FORMATS
from robotcell.robot.robot import Robot

__all__ = ["KUKA", "Kuka"]


def _status_turn(robot: Robot, q: NDArray[np.float64]) -> NDArray[np.int_]:
    return np.stack(kuka_status_turn(robot, q), axis=-1)


class Kuka(Controller):
    """KUKA KR C4 / KR C5 (KRL)."""

    name = "kuka"
    label = "KUKA"
    pose_format = FORMATS["kuka"]
    reference = "world"
    table_frames = True
    world_ref = Ref(number=0, kind="world")
    world_name = "$WORLD"
    program_suffixes = (".src", ".dat")
    comment = ";"
    program_files = "KUKA .src with its .dat"
    export_name = "config.dat"
    name_limit = 24
    tool_slots = SlotRange("TOOL_DATA", 1, 16)
    frame_slots = SlotRange("BASE_DATA", 1, 32)
    config_fields = ("S", "T")
    edits_joints = True
    csv_config = ("s", "t")
    coordinated_missing = (
        "KUKA's coordinated motion of several robots (RoboTeam) is declared in the "
        "controllers' configuration and in KRL statements whose form no public KUKA manual or "
        "real program in the sources robotcell cites shows")
    ik_flags = IkFlags("S/T", ("status", "turn"), _status_turn, lambda v: f"S {v[0]} T {v[1]}")
    zero_offsets = ZeroOffsets(180 / math.pi, 1e3, "deg", "mm",
                               "joint zero corrections for KUKA: add to the current $MAMES[i] in "
                               "$machine.dat (deg; mm for linear axes)", "add to $MAMES[i]")
    sources = (
        "Roboception rc_visard documentation, 'Pose formats: KUKA' (A, B, C)",
        ("$config.dat of two KR C4 controllers (EdgarMontielG/Cell-3_R10 and "
         "HugoDanielson/ChinaMilling, KRC/R1/System/$config.dat): DECL FRAME TOOL_DATA[16], "
         "BASE_DATA[32], DECL CHAR TOOL_NAME[16,24], BASE_NAME[32,24]"),
        "KUKA Quickguide KRL-Syntax, KSS 8.x (2012): names of at most 24 characters",
        "KUKA KR C2 Machine Data handbook (2005): $ROBROOT, $ERSYSROOT, $EX_KIN",
        "RoboDK KUKA_KRC4 post; Robots in Grasshopper KRL post (Status and Turn)",
    )

    def format_export(self, data: ControllerData, cell_name: str) -> str:
        return dat.format_data(data, cell_name)

    def parse_export(self, text: str) -> ControllerData:
        return dat.parse(text)

    def write_program(self, program: Program, header: list[str]) -> dict[str, str]:
        return krl.write(program, header)

    def read_program(self, path: str | Path) -> tuple[Program, list[str]]:
        return krl.read(path)

    def point_names(self, n: int) -> list[str]:
        return [f"XP{i + 1}" for i in range(n)]

    def config_values(self, robot: Robot, q: NDArray[np.float64]) -> NDArray[np.int_]:
        return _status_turn(robot, q)

    def config_text(self, values: tuple[int, ...]) -> str:
        return krl.config_text(values)

    def external_axes(self, cell: Cell, pulses_per_degree: ArrayLike | None = None
                      ) -> ExternalAxes:
        return numbered_axes(cell, self.name, tuple(f"E{i + 1}" for i in range(6)))

    def check_table_ref(self, ref: Ref, slot: Slot) -> None:
        if ref.on_table is not None and ref.on_table != slot.on_table:
            raise InputError(f"base {ref.label()} ({slot.name}) is "
                             + ("carried by the turntable: set it with $BASE=EK(...)"
                                if slot.on_table else
                                "fixed in the cell, but the program sets it through EK(...)"))

    def set_joints(self, lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
        return krl.set_joints(lines, idx, q)

    def set_pose(self, lines: list[str], idx: int, T: NDArray[np.float64],
                 config: Config | None = None) -> bool:
        return krl.set_pose(lines, idx, T, config)


#: The KUKA controller.
KUKA = Kuka()
