"""The cell's parts as simple shapes attached to its frames, and the file that describes them.

A bodies file (YAML, lengths in mm, angles in deg, docs/clearance.md)::

    links: {radius: 110, tool_radius: 25}          # the arm's capsules (optional)
    bodies:
      plate:   {parent: plate, cylinder: {radius: 400, length: 30}, frame: {z: -15}}
      fixture: {parent: world, box: [800, 600, 400], frame: {x: 1800, y: -1200, z: 400}}
    ignore:
      - [tool, part]                               # pairs never reported (e.g. the torch at work)

A shape is centred on its frame; a cylinder's and a capsule's axis is its z.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.clearance.skeleton import LinkModel
from robotcell.errors import InputError
from robotcell.io.fileio import read_text
from robotcell.io.poseformats import pose_from_vendor
from robotcell.io.yamlfile import parse_yaml

__all__ = ["SHAPES", "BodiesFile", "Body", "read_bodies"]

#: The shapes and the sizes each takes (m).
SHAPES = {"box": ("x", "y", "z"), "cylinder": ("radius", "length"), "sphere": ("radius",),
          "capsule": ("radius", "length")}
#: Frames a body may be attached to besides the cell's own frames: the track carriage moves
#: with the robot (``robot``), the positioner's plate turns with it (``plate``), a gripper and
#: its part move with the flange (``flange``).
PARENTS = ("world", "robot", "turntable", "plate", "flange")
_POSE_KEYS = ("x", "y", "z", "a", "b", "c")


@dataclass(frozen=True)
class Body:
    """A rigid shape attached to a frame of the cell.

    Parameters
    ----------
    name : str
        Its name in reports.
    shape : str
        ``box``, ``cylinder``, ``sphere`` or ``capsule``.
    size : tuple of float
        ``box``: edge lengths (x, y, z); ``cylinder``, ``capsule``: (radius, length along z);
        ``sphere``: (radius,) (m).
    parent : str
        The frame it is fixed in: ``world``, ``robot`` (the base, moving with the track),
        ``turntable`` (the table's fixed root), ``plate`` (turning with the table), ``flange``
        (held by the robot), or a frame of the cell.
    pose : ndarray, shape (4, 4)
        ``T_parent_body`` (m), the shape's centre and axes.
    """

    name: str
    shape: str
    size: tuple[float, ...]
    parent: str = "world"
    pose: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))

    def __post_init__(self) -> None:
        if self.shape not in SHAPES:
            raise InputError(f"body {self.name!r}: unknown shape {self.shape!r}; "
                             f"use one of {', '.join(SHAPES)}")
        if len(self.size) != len(SHAPES[self.shape]) or not all(
                np.isfinite(v) and v > 0 for v in self.size):
            raise InputError(f"body {self.name!r}: a {self.shape} takes "
                             f"{', '.join(SHAPES[self.shape])} > 0 (m), got {self.size}")

    @property
    def bounding_radius(self) -> float:
        """Radius of the smallest sphere about its centre that holds it (m)."""
        s = self.size
        if self.shape == "box":
            return 0.5 * float(np.linalg.norm(s))
        if self.shape == "sphere":
            return s[0]
        if self.shape == "cylinder":
            return float(np.hypot(s[0], s[1] / 2))
        return s[0] + s[1] / 2


@dataclass(frozen=True)
class BodiesFile:
    """What a bodies file holds: the parts, the arm's capsule radii and pairs never reported."""

    bodies: tuple[Body, ...] = ()
    links: LinkModel = field(default_factory=LinkModel)
    ignore: tuple[tuple[str, str], ...] = ()


def _fail(origin: str, key: str, msg: str) -> InputError:
    return InputError(f"{origin}: key {key!r} {msg}")


def _mapping(value: Any, origin: str, key: str, allowed: set[str]) -> dict:
    if not isinstance(value, dict):
        raise _fail(origin, key, f"must be a mapping, got {type(value).__name__}")
    unknown = set(value) - allowed
    if unknown:
        raise _fail(origin, key, f"has unknown key(s) {sorted(map(str, unknown))}; "
                    f"allowed: {sorted(allowed)}")
    return value


#: The largest length a bodies file may hold (mm): 100 m, as for a cell file.
MAX_MM = 100_000.0


def _mm(value: Any, origin: str, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
        raise _fail(origin, key, f"must be a finite number (mm), got {value!r}")
    if abs(value) > MAX_MM:
        raise _fail(origin, key, f"is {value:g} mm, beyond the {MAX_MM / 1000:g} m of any cell")
    return float(value) / 1000.0


def _body(name: str, value: Any, origin: str) -> Body:
    key = f"bodies.{name}"
    m = _mapping(value, origin, key, {"parent", "frame", *SHAPES})
    shapes = [s for s in SHAPES if s in m]
    if len(shapes) != 1:
        raise _fail(origin, key, f"must give exactly one shape ({', '.join(SHAPES)})")
    shape = shapes[0]
    spec = m[shape]
    if shape == "box":
        if not isinstance(spec, list) or len(spec) != 3:
            raise _fail(origin, f"{key}.box", f"must be [x, y, z] edge lengths (mm), got {spec!r}")
        size = tuple(_mm(v, origin, f"{key}.box") for v in spec)
    elif shape == "sphere":
        size = (_mm(spec, origin, f"{key}.sphere"),)
    else:
        spec = _mapping(spec, origin, f"{key}.{shape}", {"radius", "length"})
        size = tuple(_mm(spec.get(k), origin, f"{key}.{shape}.{k}") for k in ("radius", "length"))
    frame = _mapping(m.get("frame") or {}, origin, f"{key}.frame", set(_POSE_KEYS))
    values = [frame.get(k, 0) for k in _POSE_KEYS]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
               and abs(v) <= MAX_MM for v in values):
        raise _fail(origin, f"{key}.frame", f"must hold finite numbers (mm, deg) within "
                    f"{MAX_MM / 1000:g} m, got {frame!r}")
    parent = m.get("parent", "world")
    if not isinstance(parent, str) or not parent.strip():
        raise _fail(origin, f"{key}.parent", f"must be a frame's name, got {parent!r}")
    try:
        return Body(str(name), shape, size, parent, pose_from_vendor(values, "kuka"))
    except InputError as exc:
        raise InputError(f"{origin}: {exc}") from None


def read_bodies(path: str | Path) -> BodiesFile:
    """Read a bodies file (YAML, mm and deg; see the module's docstring).

    Raises
    ------
    InputError
        The file is missing or unreadable, or a key is unknown, missing or out of range (the
        message names the file and the key).
    """
    origin = str(path)
    data = parse_yaml(read_text(path, "bodies file"), origin)
    if data is None:
        data = {}
    top = _mapping(data, origin, "", {"links", "bodies", "ignore"})
    links = _mapping(top.get("links") or {}, origin, "links", {"radius", "tool_radius"})
    model = LinkModel(
        radius=None if links.get("radius") is None else _mm(links["radius"], origin,
                                                            "links.radius"),
        tool_radius=(LinkModel().tool_radius if links.get("tool_radius") is None
                     else _mm(links["tool_radius"], origin, "links.tool_radius")))
    bodies = _mapping(top.get("bodies") or {}, origin, "bodies", set(top.get("bodies") or {}))
    ignore = top.get("ignore") or []
    if not isinstance(ignore, list) or not all(
            isinstance(p, list) and len(p) == 2 and all(isinstance(n, str) for n in p)
            for p in ignore):
        raise _fail(origin, "ignore", "must be a list of [name, name] pairs")
    return BodiesFile(tuple(_body(str(n), v, origin) for n, v in bodies.items()), model,
                      tuple((a, b) for a, b in ignore))
