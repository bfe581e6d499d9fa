"""Universal Robots (URScript): everything robotcell knows of the controller, in :data:`UR`.

- Poses: ``p[x, y, z, rx, ry, rz]``, metres and a rotation vector in radians.
- Export (:mod:`.export`): ``set_tcp`` of each tool (TCP in the tool flange frame) and each
  frame as a feature ``global NAME=p[..]`` in the robot base frame.
- Programs (:mod:`.program`): one URScript file ``NAME.script``, ``def NAME():`` .. ``end``.
- Flags: none; a UR arm's joints are written, or its poses with the joints left to the
  controller (the solution nearest to where the arm is).
- Slots: none; tools and features are named, program and feature names are URScript names.
- External axes: none; a cell with a track or a turntable is refused.

Sources: ``docs/export.md`` and ``docs/programs.md``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.controllers.axes import ExternalAxes
from robotcell.controllers.base import Controller
from robotcell.controllers.data import ControllerData, collect
from robotcell.controllers.model import Config, Program, Ref
from robotcell.controllers.ur import export as urexport
from robotcell.controllers.ur import program as urscript
from robotcell.errors import InputError
from robotcell.io.poseformats import FORMATS
from robotcell.robot.robot import Robot

__all__ = ["UR", "UniversalRobots"]


class UniversalRobots(Controller):
    """Universal Robots CB3 / e-Series (URScript)."""

    name = "ur"
    label = "Universal Robots"
    pose_format = FORMATS["ur"]
    reference = "robot"
    table_frames = False
    world_ref = Ref(kind="base")
    world_name = "Base"
    program_suffixes = (".script",)
    comment = "#"
    program_files = "URScript .script"
    export_name = "cell.script"
    #: No public source robotcell cites limits a URScript name's length; this bound is
    #: robotcell's own, long enough for every name it writes.
    name_limit = 64
    edits_joints = True
    coordinated_missing = (
        "a Universal Robots arm is programmed alone; no public manual or script in the sources "
        "robotcell cites coordinates several arms in one URScript program")
    sources = (
        ("Universal Robots, 'The URScript Programming Language' (script manual), module "
         "motion: movej, movel, pose_trans, set_tcp, set_payload; poses p[x, y, z, rx, ry, rz] "
         "in m with an axis-angle rotation"),
        ("RoboDK Universal_Robots post (ros-industrial-attic/robodk_postprocessors, Apache-2.0): "
         "def NAME(): .. end then NAME(), set_tcp(p[..]), movej([rad..], a, v, t, r), "
         "movel(p[..], a, v, t, r), .script"),
        ("RoboDK/Industrial-Robots-VSCode examples/Prog1.script and UniveralRobots.script "
         "(MIT): URScript programs as RoboDK writes them for a UR10"),
        ("a script PolyScope saved (ilo21/universal_robots_scripts, record_data_pointURprogram/"
         "test_holding_force.script): set_tcp(p[0.0,..]) first, waypoints as global "
         "Start_pos_p=p[..], $ lines of the program tree"),
        ("forum.universal-robots.com, 'How are the final joint positions chosen in MoveL?': "
         "movel takes the shortest path to the pose"),
    )

    @staticmethod
    def refuse_axes(cell: Cell) -> None:
        """Refuse a cell with a track or a turntable: a UR program moves the arm alone.

        Raises
        ------
        InputError
            The cell has a track or a turntable (or positioner); the message names it.
        """
        parts = [f"a track {cell.track.name!r}"] if cell.track is not None else []
        if cell.turntable is not None:
            parts.append(f"a turntable {cell.turntable.name!r}")
        if parts:
            raise InputError(f"Universal Robots programs and exports hold no external axes "
                             f"(URScript moves the arm's six joints), and the cell has "
                             f"{' and '.join(parts)}; write this cell for another controller, "
                             "or remove the axis from the cell")

    def data(self, cell: Cell) -> ControllerData:
        """The cell's tools and frames in the robot base frame; a cell with a track or a
        turntable is refused (:meth:`refuse_axes`)."""
        self.refuse_axes(cell)
        return collect(cell, self.reference)

    def format_export(self, data: ControllerData, cell_name: str) -> str:
        return urexport.format_data(data, cell_name)

    def parse_export(self, text: str) -> ControllerData:
        return urexport.parse(text)

    def write_program(self, program: Program, header: list[str]) -> dict[str, str]:
        return urscript.write(program, header)

    def read_program(self, path: str | Path) -> tuple[Program, list[str]]:
        return urscript.read(path)

    def point_names(self, n: int) -> list[str]:
        return [f"p{i + 1}" for i in range(n)]

    def program_name(self, name: str) -> str:
        """``name`` as a program name: a URScript name (not a word of URScript).

        Raises
        ------
        InputError
            Not a letter followed by letters, digits or ``_``, too long, or a URScript word.
        """
        out = super().program_name(name)
        return urexport.identifier(out, "program name")

    def config_values(self, robot: Robot, q: NDArray[np.float64]) -> NDArray[np.int_]:
        return np.zeros(np.shape(q)[:-1] + (0,), dtype=int)

    def config_text(self, values: tuple[int, ...]) -> str:
        return ""

    def external_axes(self, cell: Cell, pulses_per_degree: ArrayLike | None = None
                      ) -> ExternalAxes:
        self.refuse_axes(cell)
        return ExternalAxes(self.name, None, (), 1e3, ())

    def set_joints(self, lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
        return urscript.set_joints(lines, idx, q)

    def set_pose(self, lines: list[str], idx: int, T: NDArray[np.float64],
                 config: Config | None = None) -> bool:
        return urscript.set_pose(lines, idx, T, config)


#: The Universal Robots controller.
UR = UniversalRobots()
