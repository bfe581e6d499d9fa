"""YASKAWA Motoman (INFORM): everything robotcell knows of the controller, in :data:`YASKAWA`.

- Poses: X, Y, Z (mm), Rx, Ry, Rz (deg), ``R = Rz(Rz) Ry(Ry) Rx(Rx)``.
- Export (:mod:`.export`): a pendant listing of ``TOOL[n]`` and ``UFRAME[n]`` in the base
  coordinates, at the robot base at base-axis 0; frames on the turntable at station axis 0, and
  the table's root as one more user frame.
- Programs (:mod:`.program`): jobs ``NAME.jbi``; coordinated jobs of two robots and a station
  (:mod:`.multigroup`): one job, ``///GROUP1 RB1,ST1`` and ``///GROUP2 RB2``.
- Flags: ``RCONF l,m,n,o,p,q``: flip, lower arm, rear, and R, T, S at 180 deg or more (24
  values written, the rest 0); one ``RCONF`` holds for the points after it.
- Slots: tool and user frame numbers 0..23 (NX100 job format); job names of at most 8
  characters, in capitals.
- External axes: a base axis ``BC1`` (mm) in the robot's group, station axes ``EC1..`` in
  encoder pulses (pulses per degree per axis) in a group of their own, moved with ``+MOVJ``.

Sources: ``docs/export.md`` and ``docs/programs.md``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.controllers.axes import DEG, ExternalAxes, table_count
from robotcell.controllers.base import Controller, SlotRange
from robotcell.controllers.data import ControllerData
from robotcell.controllers.model import Config, Program, Ref
from robotcell.controllers.robotpairs import robot_pairs
from robotcell.controllers.yaskawa import export as listing
from robotcell.controllers.yaskawa import multigroup
from robotcell.controllers.yaskawa import program as inform
from robotcell.errors import InputError
from robotcell.ik.config import arm_sides
from robotcell.ik.limits import TWO_PI
from robotcell.io.poseformats import FORMATS
from robotcell.robot.robot import Robot

__all__ = ["YASKAWA", "Yaskawa"]


class Yaskawa(Controller):
    """YASKAWA Motoman NX100 / DX100 and later (INFORM jobs)."""

    name = "yaskawa"
    label = "YASKAWA"
    pose_format = FORMATS["yaskawa"]
    reference = "robot"
    table_frames = False
    world_ref = Ref(number=0, kind="base")
    world_name = "base coordinates"
    program_suffixes = (".jbi",)
    comment = "'"
    program_files = "YASKAWA .jbi"
    export_name = "frames.txt"
    name_limit = 8
    upper_names = True
    tool_slots = SlotRange("TOOL", 0, 23)
    frame_slots = SlotRange("UFRAME", 0, 23)
    config_fields = ("l", "m", "n", "o", "p", "q")
    shared_config = True
    coordinated_missing = None  # two robots and a station: controllers.yaskawa.multigroup
    coordinated_one_file = True
    sources = (
        "Roboception documentation, 'Pose formats: Yaskawa' (Rx, Ry, Rz)",
        ("Motoman NX100 manual HW0481924, 4.1 'Job Data Format': //NAME up to 8 characters, "
         "///USER and ///TOOL 0 to 23, RCONF"),
        ("Motoman DX100 manual 'Interface with an Easy Offline Teaching System' HW0482494, 4.1 and "
         "4.3: job data format, station axes in pulses"),
        "Yaskawa knowledge base, 'Information in UFRAME.CND'",
        "RoboDK Motoman post (relative jobs, ///FRAME USER)",
        ("RoboDK Motoman post 2015-2023 (TetraGenAdmin/TGRoboDKPostProcessors, Motoman.py): "
         "'MOVL C00008 BC00008 V=166.7 +MOVJ EC00008 VJ=100.00', pulses per degree per "
         "external axis"),
        ("rpiRobotics/dx200_motion_progam_exec, example_inform/R1-R2-S1.JBI and R1-R2-S1-2.JBI "
         "(c81cb4fb9b8255e8fbfdde596ccabdaa9672d22a): jobs a DX200 saved for two robots and a "
         "station: ///GROUP1 RB1,ST1, ///GROUP2 RB2, 'MOVL C00004 EC00002 V=11.0  +MOVL C00005 "
         "V=11.0', ///TOOL before each robot's C position"),
        ("jobs written for DX100 and later (e.g. '////FRAME USER 1', '///GROUP1 RB1' with "
         "'///GROUP2 ST1', '///RCONF 1,0,...' of 24 values): docs/programs.md"),
    )

    def pair_lines(self, cell: Cell) -> list[str]:
        return listing.pair_lines(robot_pairs(cell))

    def format_export(self, data: ControllerData, cell_name: str) -> str:
        return listing.format_data(data, cell_name)

    def parse_export(self, text: str) -> ControllerData:
        return listing.parse(text)

    def write_program(self, program: Program, header: list[str]) -> dict[str, str]:
        return inform.write(program, header)

    def read_program(self, path: str | Path) -> tuple[Program, list[str]]:
        return inform.read(path)

    def coordinated_robots(self, cell: Cell, robots: list[str]) -> None:
        multigroup.check_robots(len(robots), [r for r in robots
                                              if cell.for_robot(r).track is not None])

    def write_coordinated(self, programs: list[Program], header: list[str]) -> dict[str, str]:
        return multigroup.write_job(programs, header)

    def read_coordinated(self, paths: list[str | Path], n: int
                         ) -> list[tuple[Program, list[str]]]:
        """The robots of group 1 and group 2 of the one job (:func:`.program.read`)."""
        if len(paths) != 1:
            raise InputError(f"a YASKAWA coordinated program is one job for all robots; got "
                             f"{len(paths)} files")
        if n != multigroup.ROBOTS:
            raise InputError(f"a YASKAWA coordinated job holds two robots, group 1's and group "
                             f"2's; got {n}: name the two robots, group 1's first")
        return inform.read_groups(paths[0])

    def coordinated_problems(self, paths: list[str | Path]) -> list[str]:
        return [p for path in paths for p in multigroup.group_problems(path)]

    def point_names(self, n: int) -> list[str]:
        return [f"C{i:05d}" for i in range(n)]

    def config_values(self, robot: Robot, q: NDArray[np.float64]) -> NDArray[np.int_]:
        front, elbow = arm_sides(robot, q)
        r = np.mod(q[..., 3] + math.pi / 2, TWO_PI)  # Flip: R in (-90, 90] deg, modulo 360
        flip = (r > 0) & (r <= math.pi)
        big = [np.abs(q[..., j]) >= math.pi for j in (3, 5, 0)]
        return np.stack([(~flip).astype(int), (~elbow).astype(int), (~front).astype(int)]
                        + [b.astype(int) for b in big], axis=-1)

    def config_text(self, values: tuple[int, ...]) -> str:
        return inform.config_text(values)

    def external_axes(self, cell: Cell, pulses_per_degree: ArrayLike | None = None
                      ) -> ExternalAxes:
        """Station axes in encoder pulses: ``pulses_per_degree``, one value per station axis
        (each axis has its own gear and encoder), is needed as soon as a station value is
        written or read; a job that moves no station axis is read without it."""
        n, chain = table_count(cell)
        need = None
        if n and pulses_per_degree is None:
            need = ("YASKAWA jobs hold station axes in encoder pulses: give pulses_per_degree, "
                    "the pulses per degree of " + ("the turntable's axis" if n == 1 else
                                                    f"each of the station's {n} axes")
                    + " (from the station's parameters)")
            ppd = np.full(n, np.nan)
        else:
            ppd = np.atleast_1d(np.asarray(pulses_per_degree if n else [], dtype=float))
            if ppd.shape != (n,):
                raise InputError(f"pulses_per_degree: the station has {n} axes, each with its "
                                 f"own pulses per degree; give {n} values, got "
                                 f"{pulses_per_degree!r}")
            if not np.all(np.isfinite(ppd) & (ppd > 0)):
                raise InputError(f"pulses_per_degree must be positive numbers, got "
                                 f"{pulses_per_degree!r}")
        return ExternalAxes(self.name, "BC1" if cell.track is not None else None,
                            tuple(f"EC{i + 1}" for i in range(n)), 1e3,
                            tuple(float(p) * DEG for p in ppd), chain, whole_units=True,
                            table_optional=True, unit_needed=need)

    def set_pose(self, lines: list[str], idx: int, T: NDArray[np.float64],
                 config: Config | None = None) -> bool:
        return inform.set_pose(lines, idx, T, config)


#: The YASKAWA controller.
YASKAWA = Yaskawa()
