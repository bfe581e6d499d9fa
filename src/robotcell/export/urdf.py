"""URDF of a calibrated cell: robot, track, turntable, tools and frames as one kinematic tree.

ROS tools (RViz, MoveIt, tf) and the Robotics Toolbox then see the calibrated cell. The tree
(``docs/export.md``, "URDF"):

- ``world``; the track frame ``track`` (L) fixed in it, a prismatic joint ``track_axis`` moving
  the link ``track_carriage`` along the track axis (its Z, origin at the robot base at position
  0), and the robot base ``base_link`` (R) fixed on the carriage so that it is at ``T_L_R0`` at
  position 0; without a track a fixed joint places ``base_link`` at ``T_world_R``;
- the arm's DH chain: revolute (or prismatic) joints ``<name>`` (the model's joint names, else
  ``joint_1..n``) moving the links ``link_1..n``; each joint's origin holds the constant part of
  the DH link before it (:func:`robotcell.cell.axischain.axis_frames`), so its axis is the DH joint
  axis; then ``flange`` fixed at the rest of the chain;
- the turntable: ``turntable_root`` (B) fixed in ``world`` or ``base_link`` at ``T_parent_B``, a
  revolute joint ``turntable_axis`` about its Z moving ``turntable_link_1`` and the fixed link
  ``turntable`` that carries the frames; a positioner chain the same way, with the joints
  ``turntable_axis_1..n`` and the links ``turntable_link_1..n``, ``turntable`` at its plate;
- every tool of the cell as a fixed link ``tool_<name>`` on the flange at ``T_F_TCP``, every frame
  as a fixed link ``frame_<name>`` on its parent (``world``, ``base_link`` or ``turntable``).

Every moving joint turns about or slides along the Z axis of its frame (``axis`` ``0 0 1`` or
``0 0 -1``), the form every URDF reader takes without a change of frame.

Joint values of the URDF are the DH chain's in SI units (rad, m): a DH joint's sign is the
direction of its URDF axis, its constant offset part of the next origin. Without a coupling they
are the controller's values. With one (``docs/models.md``, "Coupled joints") they are the model's
joint values ``q_model = C q + offset``, the ROS-Industrial convention: its FANUC driver
publishes URDF ``joint_3 = J3 + J23_factor * J2`` (``fanuc_driver`` ``linkage_transform``; 1 for
the M-20iA and LR Mate 200iD), its ABB driver ``joint_3 = axis3 - axis2`` for an arm with
``J23_coupled`` (IRB 2400). A passive joint (the IRB 460's parallelogram) has no value of its
own: it is a ``mimic`` joint of the joints it follows, split into coincident mimic joints
(``<name>``, ``<name>_2``, ...) when it follows more than one, since a URDF joint mimics one
joint. An XML comment in the file states each mapping. The limits of a coupled joint are the
range its value takes over the controller's axis limits (a URDF limit is a box on the joint's own
value; the controller's limits and interaction limits are stricter). The track joint's value is
the carriage's displacement (m), the controller value times the track's ``scale`` (a URDF joint
cannot scale its value). Lengths in metres, angles in radians, as URDF prescribes; every number
is written with all its digits (``repr``), so the tree reproduces the cell's poses exactly.
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from robotcell.cell import Cell, CellRobot, Turntable
from robotcell.cell.axischain import axis_frames
from robotcell.errors import InputError
from robotcell.robot.robot import Robot

__all__ = ["chain_elements", "export", "urdf_origin"]


def _num(v: float) -> str:
    return repr(float(v) + 0.0)


def urdf_origin(T: NDArray[np.float64]) -> dict[str, str]:
    """Attributes ``xyz`` (m) and ``rpy`` (rad) of a URDF ``<origin>`` for the pose ``T``.

    URDF's ``rpy`` is the fixed-axis roll, pitch, yaw: ``R = Rz(yaw) Ry(pitch) Rx(roll)``, which
    is scipy's extrinsic ``"xyz"``.
    """
    with warnings.catch_warnings():  # gimbal lock: scipy's split of the outer angles is exact
        warnings.simplefilter("ignore", UserWarning)
        rpy = Rotation.from_matrix(T[:3, :3]).as_euler("xyz")
    return {"xyz": " ".join(_num(v) for v in T[:3, 3]), "rpy": " ".join(_num(v) for v in rpy)}


#: Rotations that turn Z onto the track axis x, y or z (as ``T_L_J`` of the track joint).
_Z_TO = {"x": Rotation.from_euler("y", 90, degrees=True).as_matrix(),
         "y": Rotation.from_euler("x", -90, degrees=True).as_matrix(),
         "z": np.eye(3)}


def _link(root: ET.Element, name: str) -> None:
    ET.SubElement(root, "link", name=name)


def _joint(root: ET.Element, name: str, kind: str, parent: str, child: str,
           T: NDArray[np.float64], axis: NDArray[np.float64] | None = None,
           lower: float = -math.inf, upper: float = math.inf,
           mimic: tuple[str, float, float] | None = None) -> None:
    if kind == "revolute" and not (math.isfinite(lower) and math.isfinite(upper)):
        kind = "continuous"
    j = ET.SubElement(root, "joint", name=name, type=kind)
    ET.SubElement(j, "parent", link=parent)
    ET.SubElement(j, "child", link=child)
    ET.SubElement(j, "origin", urdf_origin(T))
    if axis is not None:
        ET.SubElement(j, "axis", xyz=" ".join(_num(v) for v in axis))
    if mimic is not None:
        ET.SubElement(j, "mimic", joint=mimic[0], multiplier=_num(mimic[1]), offset=_num(mimic[2]))
    if kind in ("revolute", "prismatic"):
        # URDF needs finite limits on these joints; an open side becomes a bound far outside
        # any cell (1e6 m or rad). effort and velocity are not known to the cell: 0.
        lo = lower if math.isfinite(lower) else -1e6
        hi = upper if math.isfinite(upper) else 1e6
        ET.SubElement(j, "limit", lower=_num(lo), upper=_num(hi), effort="0", velocity="0")


def chain_elements(root: ET.Element, robot: Robot, parent: str, prefix: str, end: str,
                   names: list[str] | None = None) -> None:
    """Add the DH chain of ``robot`` under link ``parent``, ending in the fixed link ``end``.

    Parameters
    ----------
    root : xml.etree.ElementTree.Element
        The ``<robot>`` element.
    robot : Robot
        A DH chain; ``robot.base`` places frame 0 in ``parent``, ``robot.flange`` places ``end``
        on the last DH frame.
    parent : str
        Link the chain is fixed to.
    prefix : str
        Prefix of the moving links ``<prefix>link_1..n``.
    end : str
        Name of the link at the chain's flange.
    names : list of str, optional
        Joint names; default the model's, else ``<prefix>joint_1..n``.

    Notes
    -----
    With a coupling the joints take the model's values ``C q + offset`` and their limits are the
    range of those over the controller's limits; a passive joint becomes mimic joints; XML
    comments before the chain state the mapping (module docstring).
    """
    names = names or [j.name or f"{prefix}joint_{i + 1}" for i, j in enumerate(robot.joints)]
    pre, post = axis_frames(robot)
    lower, upper = _value_ranges(robot)
    mimics = _mimics(robot, names)
    for text in _mapping_comments(robot, names, mimics):
        root.append(ET.Comment(text))
    last = parent
    for i, j in enumerate(robot.joints):
        axis = np.array([0.0, 0.0, j.sign])
        T = robot.base @ pre[i] if i == 0 else pre[i]
        # a passive joint: one mimic joint per joint it follows, the first at the DH origin
        parts = mimics.get(i) or [None]
        for k, mimic in enumerate(parts):
            child = f"{prefix}link_{i + 1}" + (f"_{k + 1}" if k + 1 < len(parts) else "")
            lo, hi = ((lower[i], upper[i]) if mimic is None
                      else _mimic_range(mimic, names, lower, upper))
            _link(root, child)
            _joint(root, names[i] if k == 0 else f"{names[i]}_{k + 1}", j.type, last, child,
                   T if k == 0 else np.eye(4), axis, lo, hi, mimic)
            last = child
    _link(root, end)
    _joint(root, f"{end}_fixed", "fixed", last, end, post)


def _value_ranges(robot: Robot) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Range of each chain joint's value over the controller's axis limits, shape ``(m,)`` each.

    Without a coupling the joint limits; with one, interval arithmetic on ``C q + offset`` (a
    passive joint's range too).
    """
    c = robot.coupling
    if c is None:
        return robot.lower, robot.upper
    lo, hi = robot.lower, robot.upper
    out_lo, out_hi = c.offset.copy(), c.offset.copy()
    for i in range(c.n_model):
        for k in np.flatnonzero(c.matrix[i]):
            a, b = c.matrix[i, k] * lo[k], c.matrix[i, k] * hi[k]
            out_lo[i] += min(a, b)
            out_hi[i] += max(a, b)
    return out_lo, out_hi


def _mimics(robot: Robot, names: list[str]) -> dict[int, list[tuple[str, float, float]]]:
    """Passive chain joint -> its mimic terms ``(joint, multiplier, offset)``, one per joint it
    follows, in the URDF's (chain) values: ``value = sum(multiplier * value(joint) + offset)``.
    """
    c = robot.coupling
    if c is None or c.square:
        return {}
    active = [i for i, j in enumerate(robot.joints) if not j.passive]
    Ca = c.matrix[active]
    if np.linalg.matrix_rank(Ca) < len(active):
        raise InputError(f"{robot.name}: the coupling of the joints with a motor is not invertible, "
                         "so the passive joints cannot be written as URDF mimic joints")
    Cinv = np.linalg.inv(Ca)
    out = {}
    for i, j in enumerate(robot.joints):
        if not j.passive:
            continue
        w = c.matrix[i] @ Cinv
        w = np.where(np.abs(w - np.round(w)) < 1e-12, np.round(w), w) + 0.0
        off = float(c.offset[i] - w @ c.offset[active])
        terms = ([(names[active[k]], float(w[k])) for k in np.flatnonzero(w)]
                 or [(names[active[0]], 0.0)])  # a joint held still: mimic with multiplier 0
        out[i] = [(nm, m, off if k == 0 else 0.0) for k, (nm, m) in enumerate(terms)]
    return out


def _mimic_range(mimic: tuple[str, float, float], names: list[str], lower: NDArray[np.float64],
                 upper: NDArray[np.float64]) -> tuple[float, float]:
    """Range of a mimic joint's value, from the range of the joint it follows."""
    k = names.index(mimic[0])
    a, b = mimic[1] * lower[k] + mimic[2], mimic[1] * upper[k] + mimic[2]
    return min(a, b), max(a, b)


def _expression(terms: list[tuple[float, str]], offset: float = 0.0) -> str:
    """A linear combination written out: ``J3 + J2``, ``-A2 - A3``, ``1.0002 * J2 + 0.01``."""
    parts = [(c < 0, ("" if abs(c) == 1 else f"{abs(c):.15g} * ") + nm) for c, nm in terms if c]
    if offset:
        parts.append((offset < 0, f"{abs(offset):.15g}"))
    if not parts:
        return "0"
    out = ("-" if parts[0][0] else "") + parts[0][1]
    return out + "".join(f" {'-' if neg else '+'} {t}" for neg, t in parts[1:])


def _row(robot: Robot, i: int, axes: list[str], name: str) -> str:
    """Chain joint ``i``'s value in controller values, its own axis first."""
    c = robot.coupling
    order = sorted(np.flatnonzero(c.matrix[i]), key=lambda k: axes[k] != name)
    return _expression([(float(c.matrix[i, k]), axes[k]) for k in order], float(c.offset[i]))


def _mapping_comments(robot: Robot, names: list[str],
                      mimics: dict[int, list[tuple[str, float, float]]]) -> list[str]:
    """XML comments stating how the URDF joint values follow from the controller's values."""
    c = robot.coupling
    if c is None:
        return []
    axes = [names[i] for i, j in enumerate(robot.joints) if not j.passive]
    lines = [(" Joint values of the arm: its model's joint values q_model = C q + offset of the "
              "controller's axis values q (rad, m), as ROS-Industrial's drivers publish joint_3 "
              "of a coupled arm (fanuc_driver linkage_transform: J3 + J23_factor * J2; abb_driver "
              "J23_coupled: axis3 - axis2); robotcell docs/export.md, URDF. ")]
    for i, j in enumerate(robot.joints):
        expr = _row(robot, i, axes, names[i])
        if i in mimics:
            terms = mimics[i]
            mine = _expression([(m, nm) for nm, m, _ in terms], sum(o for _, _, o in terms))
            joints = ", ".join(names[i] if k == 0 else f"{names[i]}_{k + 1}"
                               for k in range(len(terms)))
            lines.append(f" {names[i]} is passive: {names[i]} = {expr} of the controller = {mine} "
                         f"of this file (mimic joints {joints}) ")
        elif expr != names[i]:
            lines.append(f" {names[i]} = {expr} of the controller ")
    return lines


def export(cell: Cell) -> str:
    """URDF text of ``cell`` (metres, radians; see the module docstring for the tree).

    A cell of several robots writes every robot, each with its track and tools, its links and
    joints prefixed by its name (``kuka_base_link``, ``kuka_A1``, ``kuka_track_axis``,
    ``kuka_tool_torch``), beside the shared turntable or positioner and frames; a frame fixed
    to a robot hangs from that robot's ``<name>_base_link``.

    Parameters
    ----------
    cell : Cell

    Returns
    -------
    str
        ``<?xml ...?>`` and one ``<robot name=CELL_NAME>`` element.
    """
    root = ET.Element("robot", name=cell.name)
    _link(root, "world")
    prefix = {n: "" if len(cell.robots) == 1 else f"{n}_" for n in cell.robots}
    for name, unit in cell.robots.items():
        _robot_elements(root, unit, prefix[name])
    if cell.turntable is not None:
        b = cell.turntable
        _link(root, "turntable_root")
        _joint(root, "turntable_frame", "fixed", "world" if b.parent == "world" else "base_link",
               "turntable_root", b.T_parent_root)
        names = (["turntable_axis"] if isinstance(b, Turntable)
                 else [f"turntable_axis_{i + 1}" for i in range(b.n_axes)])
        chain_elements(root, b.chain.with_base(np.eye(4)), "turntable_root", "turntable_",
                       "turntable", names)
    for name, unit in cell.robots.items():
        p = prefix[name]
        for tname, tool in unit.tools.items():
            _link(root, f"{p}tool_{tname}")
            _joint(root, f"{p}tool_{tname}_fixed", "fixed", f"{p}flange", f"{p}tool_{tname}",
                   tool.T_F_TCP)
    parents = {"world": "world", "robot": "base_link", "turntable": "turntable",
               **{n: f"{p}base_link" for n, p in prefix.items()}}
    for name, fr in cell.frames.items():
        _link(root, f"frame_{name}")
        _joint(root, f"frame_{name}_fixed", "fixed", parents[fr.parent], f"frame_{name}",
               fr.pose)
    ET.indent(root)
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _robot_elements(root: ET.Element, unit: CellRobot, p: str) -> None:
    """A robot's base link, its track or fixed base, and its arm, names prefixed by ``p``."""
    _link(root, f"{p}base_link")
    if unit.track is not None:
        t = unit.track
        _link(root, f"{p}track")
        _joint(root, f"{p}track_frame", "fixed", "world", f"{p}track", t.T_world_L)
        T_L_J = np.eye(4)  # the joint frame: at the robot base at position 0, Z along the motion
        T_L_J[:3, :3] = _Z_TO[t.axis]
        T_L_J[:3, 3] = t.T_L_R0[:3, 3]
        _link(root, f"{p}track_carriage")
        _joint(root, f"{p}track_axis", "prismatic", f"{p}track", f"{p}track_carriage", T_L_J,
               np.array([0.0, 0.0, 1.0]), t.lower * t.scale, t.upper * t.scale)
        _joint(root, f"{p}robot_on_track", "fixed", f"{p}track_carriage", f"{p}base_link",
               np.linalg.solve(T_L_J, t.T_L_R0))
    else:
        _joint(root, f"{p}robot_frame", "fixed", "world", f"{p}base_link", unit.T_world_R)
    names = None if not p else [f"{p}{j.name or f'joint_{i + 1}'}"
                                for i, j in enumerate(unit.robot.joints)]
    chain_elements(root, unit.robot, f"{p}base_link", p, f"{p}flange", names)
