"""ABB IRC5 / OmniCore (RAPID): everything robotcell knows of the controller, in :data:`ABB`.

- Poses: x, y, z (mm) and a unit quaternion ``[q1, q2, q3, q4]``, scalar first.
- Export (:mod:`.export`): a RAPID module of ``tooldata``, ``wobjdata`` (coordinated work
  objects on the turntable's mechanical unit) and base frames as ``CONST pose``, in world.
- Programs (:mod:`.program`): one module ``NAME.mod`` (``.prg`` and RobotStudio's ``.modx``
  read too).
- Flags: ``confdata`` ``[cf1, cf4, cf6, cfx]`` (:func:`robotcell.ik.config.abb_confdata`).
- Slots: none; tools and work objects are RAPID identifiers of at most 32 characters; program
  names of at most 28, so that the module ``MOD_NAME`` is one too.
- External axes: ``eax_a..eax_f``, the track first (mm), the table's axes after it (deg),
  ``9E9`` for an axis the cell lacks.

Sources: ``docs/export.md`` and ``docs/programs.md``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.controllers.abb import export as rapid_data
from robotcell.controllers.abb import multimove
from robotcell.controllers.abb import program as rapid
from robotcell.controllers.axes import ExternalAxes, numbered_axes
from robotcell.controllers.base import Controller, IkFlags, ZeroOffsets
from robotcell.controllers.data import ControllerData
from robotcell.controllers.model import Config, Program, Ref
from robotcell.ik.config import abb_confdata
from robotcell.io.poseformats import FORMATS
from robotcell.robot.robot import Robot

__all__ = ["ABB", "Abb"]


class Abb(Controller):
    """ABB IRC5 / OmniCore (RAPID)."""

    name = "abb"
    label = "ABB"
    pose_format = FORMATS["abb"]
    reference = "world"
    table_frames = True
    world_ref = Ref(name="wobj0", kind="world")
    world_name = "wobj0"
    program_suffixes = (".mod", ".prg", ".modx")
    comment = "!"
    program_files = "ABB .mod"
    export_name = "cell.mod"
    name_limit = 28  # MOD_ + 28 characters: a RAPID name of 32
    config_fields = ("cf1", "cf4", "cf6", "cfx")
    edits_joints = True
    csv_config = ("cf1", "cf4", "cf6", "cfx")
    coordinated_missing = None  # MultiMove: controllers.abb.multimove
    ik_flags = IkFlags("confdata", ("cf1", "cf4", "cf6", "cfx"),
                       lambda robot, q: np.atleast_2d(abb_confdata(robot, q)),
                       lambda v: "[" + ",".join(str(x) for x in v) + "]")
    zero_offsets = ZeroOffsets(1.0, 1.0, "rad", "m",
                               "joint zero offsets for ABB, arm side (rad; m for linear axes); "
                               "robotcell writes no MOC.cfg line: apply them with ABB's "
                               "calibration tools (docs/identification.md)", "offset")
    sources = (
        ("ABB RAPID reference, data types orient, tooldata, wobjdata, confdata, speeddata, "
         "zonedata"),
        "ABB MultiMove application manual 3HAC021272-001, 6.3 'Coordinated work objects'",
        "KnoP-01/rapid-for-vim, syntax/rapid.vim: RAPID names of at most 32 characters",
        ("RoboDK ABB_RAPID_IRC5 post (ros-industrial-attic/robodk_postprocessors): confdata; "
         "MODULE MOD_<name> holding PROC <name>(); LOCAL PERS tooldata and wobjdata declared in "
         "the program's module"),
        ("ABB RobotStudio SDK, RapidDomain Scope enumeration: LOCAL data is available for its "
         "module only"),
        ("ABB MultiMove application manual 3HAC021272-001, 'Synchronized movements': "
         "SyncMoveOn/SyncMoveOff, syncident, tasks, \\ID on every synchronised move"),
        ("industrialmonitordirect.com, 'Configuring Shared RAPID System Modules in ABB "
         "OmniCore': RobotStudio saves program modules as .modx"),
        ("ebruun/ECL_robotic_cell, _controller_backups/4600-COMPAS_RRC_BACKUP_2022-04-12_"
         "3rob_setup/HOME/1/1_T_ROB1.mod and 1_T_ROB2.mod: MultiMove modules an offline tool "
         "saved on a controller"),
    )

    def format_export(self, data: ControllerData, cell_name: str) -> str:
        return rapid_data.format_data(data, cell_name)

    def parse_export(self, text: str) -> ControllerData:
        return rapid_data.parse(text)

    def write_program(self, program: Program, header: list[str]) -> dict[str, str]:
        return rapid.write(program, header)

    def read_program(self, path: str | Path) -> tuple[Program, list[str]]:
        return rapid.read(path)

    def write_coordinated(self, programs: list[Program], header: list[str]) -> dict[str, str]:
        return multimove.write_tasks(programs, header)

    def coordinated_problems(self, paths: list[str | Path]) -> list[str]:
        return multimove.id_problems({str(p): multimove.sync_moves(p) for p in paths})

    def point_names(self, n: int) -> list[str]:
        return [f"p{i + 1}" for i in range(n)]

    def config_values(self, robot: Robot, q: NDArray[np.float64]) -> NDArray[np.int_]:
        return abb_confdata(robot, q)

    def config_text(self, values: tuple[int, ...]) -> str:
        return rapid.config_text(values)

    def external_axes(self, cell: Cell, pulses_per_degree: ArrayLike | None = None
                      ) -> ExternalAxes:
        return numbered_axes(cell, self.name, rapid.EAX)

    def set_joints(self, lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
        return rapid.set_joints(lines, idx, q)

    def set_pose(self, lines: list[str], idx: int, T: NDArray[np.float64],
                 config: Config | None = None) -> bool:
        return rapid.set_pose(lines, idx, T, config)


#: The ABB controller.
ABB = Abb()
