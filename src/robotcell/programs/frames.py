"""Tools and reference frames of a program, tied to a cell as ``robotcell export`` numbers them.

A program names its tool and the frame of its Cartesian points by a number (KUKA ``TOOL_DATA``,
``BASE_DATA``; FANUC ``UT``, ``UF``; YASKAWA tool and user frame numbers) or a name (ABB
``tooldata``, ``wobjdata``). The numbers and names are the ones the export of the cell writes
(:func:`robotcell.controllers.data.collect`), so a program and the export of the same cell refer
to the same data. Each controller measures a frame in its own reference (its ``reference`` and
``table_frames``, ``docs/export.md``): KUKA and ABB in the cell's world (a frame on the turntable
through the turntable's kinematic, KUKA ``EK``, ABB ``ufmec``), FANUC and YASKAWA at the robot
base at track position 0 (a frame on the turntable as it is at table axis 0).

:func:`program_refs` gives the references a program writes for a tool and a frame of the cell;
:func:`tool_pose_of` and :func:`placement` tie the references a file writes back to the cell.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import RESERVED_FRAMES, Cell, Positioner
from robotcell.cell.kinematics import frame_pose, robot_pose
from robotcell.controllers.model import Ref
from robotcell.controllers.registry import get
from robotcell.errors import InputError

__all__ = ["Placement", "placement", "program_refs", "tool_pose_of"]


@dataclass(frozen=True)
class Placement:
    """Where a program's reference frame is in the cell.

    Attributes
    ----------
    kind : {"fixed", "table", "robot"}
        ``fixed``: ``pose`` is ``T_world_X``; ``table``: ``pose`` is the frame in the plate of
        the turntable or positioner (``T_B_X`` at table angle 0, ``T_P_X``); ``robot``: ``pose``
        is ``T_R_X``, the frame moves with the robot base.
    pose : ndarray, shape (4, 4)
        Metres.
    label : str
        How the program names it, for messages.
    """

    kind: str
    pose: NDArray[np.float64]
    label: str

    def world(self, cell: Cell, track: ArrayLike, table: ArrayLike) -> NDArray[np.float64]:
        """``T_world_X`` at track values (m) and table values (rad), shape ``(..., 4, 4)``."""
        if self.kind == "fixed":
            shape = np.broadcast_shapes(np.shape(track), _table_batch(cell, table))
            return np.broadcast_to(self.pose, shape + (4, 4))
        if self.kind == "robot":
            return robot_pose(cell, track) @ self.pose
        assert cell.turntable is not None
        root = frame_pose(cell, "turntable", track, table)
        return root @ cell.turntable.T_root_P(table) @ self.pose


def _table_batch(cell: Cell, table: ArrayLike) -> tuple[int, ...]:
    shape = np.shape(table)
    return shape[:-1] if isinstance(cell.turntable, Positioner) and shape else shape


def program_refs(cell: Cell, vendor: str, tool: str, frame: str) -> tuple[Ref, Ref, Placement]:
    """The tool and frame references a program writes, and where the frame is.

    Parameters
    ----------
    cell : Cell
    vendor : str
        A registered controller.
    tool : str
        A tool of the cell.
    frame : str
        ``world`` or a frame of the cell (fixed, or carried by the turntable or positioner).

    Returns
    -------
    tool_ref, frame_ref : Ref
    placement : Placement
        The frame the Cartesian points are written in.

    Raises
    ------
    InputError
        A tool or frame the cell lacks; a frame no controller holds (fixed to a robot on a
        track, or one of the reserved frames other than ``world``); a tool or frame number the
        controller does not have.
    """
    controller = get(vendor, "program format")
    data = controller.data(cell)
    tools = {s.name: s for s in data.tools}
    if tool not in tools:
        known = ", ".join(sorted(tools)) or "none"
        raise InputError(f"tool {tool!r} is not in the cell; the cell has: {known}")
    t = tools[tool]
    controller.check_tool(t)
    tool_ref = Ref(number=t.number, name=t.name)
    if frame == "world":
        ref = controller.world_ref
        return tool_ref, ref, placement(cell, vendor, ref)
    if frame in RESERVED_FRAMES:
        raise InputError(f"frame {frame!r}: a program's points are in 'world' or in a frame of "
                         f"the cell ({', '.join(sorted(cell.frames)) or 'none'})")
    if frame in data.skipped:
        raise InputError(f"frame {frame!r} moves with the robot on the track: no controller "
                         "frame holds it (docs/export.md); give the path in another frame")
    slots = {s.name: s for s in data.frames}
    if frame not in slots:
        known = ", ".join(sorted(cell.frames)) or "none"
        raise InputError(f"frame {frame!r} is not in the cell; the cell has: world, {known}")
    s = next(f for f in controller.frames(data) if f.name == frame)
    controller.check_frame(s)
    ref = Ref(number=s.number, name=s.name, on_table=s.on_table, kind=controller.frame_kind)
    return tool_ref, ref, placement(cell, vendor, ref)


def tool_pose_of(cell: Cell, vendor: str, ref: Ref) -> NDArray[np.float64]:
    """``T_F_TCP`` (m) of the tool a program names.

    A pose written in the program wins; then a name of the cell's tools (ABB: case-insensitive;
    ``tool0`` is the flange); then the number the export gives the cell's tool (0: the flange).

    Raises
    ------
    InputError
        The cell has no such tool.
    """
    if ref.pose is not None:
        return ref.pose
    tools = get(vendor, "program format").data(cell).tools
    if ref.name is not None:
        if ref.name.lower() == "tool0":
            return np.eye(4)
        for s in tools:
            if s.name.lower() == ref.name.lower():
                return s.pose
        if ref.number is None:
            raise InputError(f"tool {ref.name!r} is not in the cell (the cell has: "
                             f"{', '.join(s.name for s in tools) or 'none'})")
    if ref.number == 0 or ref.number is None:
        return np.eye(4)
    for s in tools:
        if s.number == ref.number:
            return s.pose
    raise InputError(f"tool number {ref.number} is not in the cell (the cell's tools: "
                     f"{', '.join(f'{s.number} {s.name}' for s in tools) or 'none'})")


def placement(cell: Cell, vendor: str, ref: Ref) -> Placement:
    """Where the frame a program names is in the cell.

    Parameters
    ----------
    cell : Cell
    vendor : str
        A registered controller.
    ref : Ref
        As a reader or :func:`program_refs` gives it.

    Returns
    -------
    Placement

    Raises
    ------
    InputError
        The cell has no frame of that number or name, or a frame on a turntable the cell lacks.
    """
    controller = get(vendor, "program format")
    base = robot_pose(cell, 0.0)
    if ref.pose is not None:
        if ref.on_table:
            if cell.turntable is None:
                raise InputError(f"frame {ref.label()} is carried by a turntable; the cell has "
                                 "none")
            return Placement("table", ref.pose, ref.label())
        pose = ref.pose if ref.kind == "world" else base @ ref.pose
        return Placement("robot" if ref.kind == "robot" else "fixed", pose, ref.label())
    world_ref = ref.number in (None, 0) and (ref.name is None or ref.name.lower() == "wobj0")
    if world_ref:
        if ref.kind == "robot":
            return Placement("robot", np.eye(4), "robot coordinates")
        pose = np.eye(4) if ref.kind == "world" else base
        return Placement("fixed", pose, controller.world_name)
    slots = controller.frames(controller.data(cell))
    slot = None
    for s in slots:
        if (ref.name is not None and s.name.lower() == ref.name.lower()) or (
                ref.name is None and s.number == ref.number):
            slot = s
            break
    if slot is None:
        known = ", ".join(f"{s.number} {s.name}" for s in slots) or "none"
        raise InputError(f"frame {ref.label()} is not in the cell (the cell's frames as "
                         f"{vendor} numbers them: {known})")
    controller.check_table_ref(ref, slot)
    if slot.on_table:
        return Placement("table", slot.pose, slot.name)
    return Placement("fixed", slot.pose if controller.reference == "world" else base @ slot.pose,
                     slot.name)
