"""The cell file: its YAML schema, the reader and the writer, and the atomic save.

A cell file is written in millimetres and degrees (see ``docs/cell.md`` for the schema); the
:class:`~robotcell.cell.model.Cell` it is read into holds the same content in SI units. Poses in
the file are mappings ``{x, y, z, a, b, c}`` with ``R = Rz(a) Ry(b) Rx(c)`` (the KUKA convention,
as in robot model files).

This module knows the parts of a cell (:mod:`robotcell.cell.parts`) and reads of a cell what
:class:`CellRecord` names; the cell (:mod:`robotcell.cell.model`) stands on it:
:func:`~robotcell.cell.model.cell_from_dict` builds a :class:`~robotcell.cell.model.Cell` from
the keyword arguments :func:`cell_fields` reads, and :meth:`Cell.save
<robotcell.cell.model.Cell.save>` calls :func:`save_cell`.

:func:`save_cell` updates an existing file as the user wrote it: the file is read as a round-trip
YAML document (:mod:`robotcell.io.yamlfile`), the values the cell changed are put in place and
the rest (comments, key order, layout, the spelling of unchanged numbers) stays as it was. It
writes atomically: a temporary file in the same directory, flushed and fsynced, then
``os.replace``; the previous file is kept as a numbered backup ``<name>.<N>.bak`` that no later
update overwrites (:mod:`robotcell.cell.history`). The file and its backups keep the permissions
the file had (see :mod:`robotcell.io.fileio`, which also gives the encoding rule of
:func:`read_cell_file`). The text is read back as a cell before it replaces the file, and the
file is locked while it is read and replaced; :mod:`robotcell.cell.update` makes a whole
read-change-write one locked step.
"""

from __future__ import annotations

import datetime as _dt
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from robotcell.cell.history import keep_version
from robotcell.cell.kinematics import CellModel
from robotcell.cell.parts import (
    DEFAULT_ROBOT,
    CellRobot,
    Frame,
    IdentifiedArm,
    Positioner,
    Provenance,
    Tool,
    Track,
    Turntable,
    check_identified,
    check_name,
)
from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write, check_destination, read_text
from robotcell.io.locking import file_lock
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.io.yamlfile import parse_yaml, update_document, written_yaml
from robotcell.robot.models import load_robot, robot_from_dict, robot_to_dict

__all__ = ["CellRecord", "cell_fields", "cell_to_dict", "read_cell_file", "robots_fields",
           "robots_to_dict", "save_cell"]


class CellRecord(CellModel, Protocol):
    """What the cell file holds of a cell; :class:`robotcell.cell.Cell` is one.

    Attributes
    ----------
    robot_model : str
        How the file names the robot: a library name or a model file.
    identified : IdentifiedArm or None
    name : str
    (and those of :class:`~robotcell.cell.kinematics.CellModel`)
    """

    @property
    def robot_model(self) -> str: ...

    @property
    def identified(self) -> IdentifiedArm | None: ...

    @property
    def name(self) -> str: ...

    @property
    def robots(self) -> dict[str, CellRobot]: ...

_POSE_KEYS = ("x", "y", "z", "a", "b", "c")

_PROVENANCE_KEYS = {"source", "time", "rms_mm", "note", "id", "measurements", "sha256", "options",
                    "inputs", "sigma", "covariance_mm_rad", "sources_mm_rad"}


def _mm_rad(size: int) -> NDArray[np.float64]:
    """Per parameter of a calibrated value (origin, rotation vector; a track's scale; a
    positioner's ``a``, ``alpha``, ``d``, ``theta`` of each axis after its root): SI to the file."""
    pose = np.r_[np.full(min(size, 3), 1e3), np.ones(min(max(size - 3, 0), 3))]
    if size == 7:
        return np.r_[pose, 1.0]
    return np.r_[pose, np.tile([1e3, 1.0, 1e3, 1.0], max(size - 6, 0) // 4)]

_HEADER = ("# robotcell cell file: lengths in mm, angles in deg; poses {x, y, z, a, b, c} with\n"
           "# R = Rz(a) Ry(b) Rx(c). Schema: docs/cell.md\n")


def read_cell_file(path: str | Path) -> tuple[Any, str, Path]:
    """Read a cell file (millimetres, degrees) as a YAML document.

    Parameters
    ----------
    path : str or Path
        YAML cell file.

    Returns
    -------
    data : mapping
        The parsed content, for :func:`cell_fields`.
    origin : str
        ``path`` as given, for messages.
    base_dir : Path
        The file's directory, against which a robot model path inside it is resolved.
    """
    p = Path(path)
    return parse_yaml(read_text(p, "cell file"), str(path)), str(path), p.resolve().parent


def save_cell(cell: CellRecord, path: str | Path,
              read: Callable[[Any, str, Path], CellRecord],
              written: tuple[Any, dict[str, Any]] | None = None) -> Path | None:
    """Write ``cell`` to a cell file atomically, keeping the file as the user wrote it.

    An existing file that reads as a cell is updated in place: only the values that differ from
    what the file says change, in their places; comments, key order, layout and keys this
    writer does not use are kept. Another file is replaced whole. Either way the previous file is
    first copied to the next numbered backup ``<name>.<N>.bak``, which no later save overwrites.
    The new text is read back as a cell before it replaces the file: a text that would not load
    is never installed. The file is locked (:func:`robotcell.io.locking.file_lock`) from before
    it is read until it is replaced. A symbolic link is followed: the file it points to is
    updated, its backup goes beside that file, and the link stays. This is what
    :meth:`Cell.save <robotcell.cell.model.Cell.save>` does.

    Parameters
    ----------
    cell : CellRecord
        The cell (SI units), written in millimetres and degrees.
    path : str or Path
        Destination; a robot model file is written relative to its directory.
    read : callable
        ``read(data, origin, base_dir)``: the cell that the content of a cell file is
        (:func:`robotcell.cell.model.cell_from_dict`); an existing file that it reads is
        updated in place, and the new text must read with it.
    written : (document, dict), optional
        The file as it is, read under its lock by the caller: its round-trip document
        (:func:`robotcell.io.yamlfile.parse_yaml`, changed in place here) and what it says
        (:func:`cell_to_dict` of its cell). Default: the file is read here.

    Returns
    -------
    Path or None
        The backup of the previous file, or None when there was none.

    Raises
    ------
    InputError
        The file cannot be written (read-only, several hard links, no folder), its lock is held
        by another process for longer than :data:`robotcell.io.locking.LOCK_WAIT`, or the new
        text would not load as a cell (the reason is named); the file is unchanged.
    """
    real = check_destination(path)  # a read-only file is refused before the backup is made
    base = real.resolve().parent
    new = cell_to_dict(cell, base)
    with file_lock(real):
        if written is None and real.is_file():
            written = _as_written(real, base, read)
        if written is None:
            text, back = written_yaml(new, str(path))
            text = _HEADER + text
        else:
            doc, old = written
            update_document(doc, old, new)
            text, back = written_yaml(doc, str(path))
        try:
            read(back, str(path), base)
        except InputError as exc:
            raise InputError(f"the cell as it would be written does not load ({exc}); "
                             f"{path} is unchanged") from None
        backup = keep_version(real) if real.exists() else None
        atomic_write(real, text)
    return backup


def _as_written(path: Path, base: Path, read: Callable[[Any, str, Path], CellRecord]
                ) -> tuple[Any, dict[str, Any]] | None:
    """The file's round-trip document and what it says in this writer's spelling, or None.

    None when the file does not read as a cell (it is then replaced whole; its backup keeps it).
    """
    try:
        doc = parse_yaml(read_text(path, "cell file"), str(path))
        return doc, cell_to_dict(read(doc, str(path), base), base)
    except InputError:
        return None


# -- file content <-> cell ------------------------------------------------------------------------
class _Reader:
    """Typed access to the parsed YAML with errors naming the file and the key."""

    def __init__(self, origin: str, base_dir: str | Path = "."):
        self.origin = origin
        self.base_dir = Path(base_dir)

    def fail(self, key: str, msg: str) -> InputError:
        return InputError(f"{self.origin}: {f'key {key!r}' if key else 'the top level'} {msg}")

    def mapping(self, value: Any, key: str, allowed: set[str], required: tuple[str, ...] = ()
                ) -> dict:
        if not isinstance(value, dict):
            raise self.fail(key, f"must be a mapping, got {type(value).__name__}")
        unknown = set(value) - allowed
        if unknown:
            raise self.fail(key, f"has unknown key(s) {sorted(map(str, unknown))}; "
                            f"allowed: {sorted(allowed)}")
        for r in required:
            if r not in value:
                raise self.fail(f"{key}.{r}" if key else r, "is missing")
        return value

    def number(self, value: Any, key: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(key, f"must be a number, got {value!r}")
        if not math.isfinite(value):
            raise self.fail(key, f"must be finite, got {value!r}")
        return float(value)

    def string(self, value: Any, key: str) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.fail(key, f"must be a non-empty string, got {value!r}")
        return value

    def pose(self, value: Any, key: str) -> NDArray[np.float64]:
        m = self.mapping(value, key, set(_POSE_KEYS))
        v = [self.number(m.get(k, 0), f"{key}.{k}") for k in _POSE_KEYS]
        return pose_from_vendor(v, "kuka")

    def provenance(self, value: Any, key: str) -> Provenance:
        if value is None:
            return Provenance()
        m = self.mapping(value, key, _PROVENANCE_KEYS, ("source",))
        time = m.get("time")
        if isinstance(time, (_dt.datetime, _dt.date)):  # YAML reads unquoted timestamps
            time = time.isoformat()
        try:
            measurements = m.get("measurements")
            if measurements is not None:
                path = Path(self.string(measurements, f"{key}.measurements"))
                measurements = str(path if path.is_absolute() else self.base_dir / path)
            options = self.mapping(m.get("options") or {}, f"{key}.options",
                                   set(m.get("options") or {}))
            inputs = m.get("inputs") or []
            if not isinstance(inputs, list):
                raise self.fail(f"{key}.inputs", f"must be a list of item names, got {inputs!r}")
            return Provenance(
                source=self.string(m["source"], f"{key}.source"),
                time=time,
                rms_mm=None if m.get("rms_mm") is None else self.number(m["rms_mm"], f"{key}.rms_mm"),
                note=str(m.get("note", "")),
                id=None if m.get("id") is None else self.string(m["id"], f"{key}.id"),
                measurements=measurements,
                sha256=None if m.get("sha256") is None else self.string(m["sha256"],
                                                                        f"{key}.sha256"),
                options=dict(options),
                inputs=tuple(self.string(v, f"{key}.inputs") for v in inputs),
                sources=self.sources(m, key),
            )
        except InputError as exc:
            raise self.fail(key, f"is invalid: {str(exc).lstrip()}") from None

    def matrix(self, value: Any, key: str) -> NDArray[np.float64]:
        if not isinstance(value, list) or not value or not all(isinstance(r, list) for r in value):
            raise self.fail(key, "must be a matrix: a list of rows, each a list of numbers")
        rows = [[self.number(v, f"{key}[{i}]") for v in r] for i, r in enumerate(value)]
        if len({len(r) for r in rows}) != 1:
            raise self.fail(key, "must have rows of equal length")
        return np.array(rows)

    def sources(self, m: dict, key: str) -> dict[str, NDArray[np.float64]]:
        """``sources_mm_rad`` (per source a factor, mm and rad), or a ``covariance_mm_rad`` alone."""
        out: dict[str, NDArray[np.float64]] = {}
        given = m.get("sources_mm_rad")
        if given is not None:
            for name, f in self.mapping(given, f"{key}.sources_mm_rad", set(given)).items():
                out[str(name)] = self.matrix(f, f"{key}.sources_mm_rad.{name}")
        elif m.get("covariance_mm_rad") is not None:
            cov = self.matrix(m["covariance_mm_rad"], f"{key}.covariance_mm_rad")
            try:
                if cov.shape[0] != cov.shape[1] or not np.allclose(cov, cov.T):
                    raise np.linalg.LinAlgError
                out[str(m.get("id") or key)] = np.linalg.cholesky(cov)
            except np.linalg.LinAlgError:
                raise self.fail(f"{key}.covariance_mm_rad", "must be a symmetric positive "
                                "definite matrix (the stated accuracy of the value)") from None
        return {k: f / _mm_rad(len(f))[:, None] for k, f in out.items()}

    def limits(self, m: dict, key: str, scale: float) -> tuple[float, float]:
        lo = self.number(m["min"], f"{key}.min") * scale if "min" in m else -math.inf
        hi = self.number(m["max"], f"{key}.max") * scale if "max" in m else math.inf
        if not lo < hi:
            raise self.fail(f"{key}.min", f"({m.get('min')}) must be below {key}.max ({m.get('max')})")
        return lo, hi

    def integer(self, value: Any, key: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise self.fail(key, f"must be an integer >= 1, got {value!r}")
        return value


def _is_model_path(text: str) -> bool:
    return text.lower().endswith((".yaml", ".yml")) or "/" in text or os.sep in text


def _robot(rd: _Reader, value: Any, key: str, base_dir: str | Path) -> tuple[str, Any]:
    """A robot the cell file names at ``key``: how the cell keeps the name, and the model."""
    model = rd.string(value, key)
    if _is_model_path(model):
        model_path = Path(model) if Path(model).is_absolute() else Path(base_dir) / model
        if not model_path.is_file():
            raise rd.fail(key, f"names model file {str(model_path)!r}, which does not exist")
        model = str(model_path)
    try:
        return model, load_robot(model)
    except InputError as exc:
        raise rd.fail(key, f"is invalid: {exc}") from None


def _relative(model: str, base_dir: str | Path) -> str:
    """A model file path as the cell file in ``base_dir`` writes it (a library name as it is)."""
    if _is_model_path(model):
        return os.path.relpath(Path(model).resolve(), Path(base_dir).resolve())
    return model


def cell_fields(data: Any, origin: str = "cell", base_dir: str | Path = ".") -> dict[str, Any]:
    """The keyword arguments of :class:`~robotcell.cell.model.Cell` that the content of a cell
    file gives (:func:`robotcell.cell.model.cell_from_dict` builds the cell).

    Parameters
    ----------
    data : dict
        Parsed YAML (millimetres, degrees).
    origin : str
        What to call the source in error messages (a file name).
    base_dir : str or Path
        Directory against which a relative robot model path is resolved.

    Returns
    -------
    dict
        ``robot``, ``robot_model``, ``tools``, ``frames`` and those of ``T_world_R``, ``name``,
        ``track``, ``turntable`` and ``identified`` the file gives (SI units).

    Raises
    ------
    InputError
        Naming ``origin`` and the key at fault.
    """
    rd = _Reader(origin, base_dir)
    if not isinstance(data, dict):
        raise InputError(f"{origin}: a cell file must be a YAML mapping with keys robot, tools, "
                         "frames, ...")
    if "robots" in data:
        return robots_fields(data, origin, base_dir)
    if "joints" in data and "robot" not in data:
        raise InputError(f"{origin}: this is a robot model file (it has 'joints'), not a cell "
                         "file; a cell file names it as robot: {model: FILE} (docs/cell.md)")
    top = rd.mapping(data, "", {"name", "robot", "track", "turntable", "positioner", "tools",
                                "frames"}, ("robot",))
    rob = rd.mapping(top["robot"], "robot", {"model", "frame", "identified", "provenance"},
                     ("model",))
    kwargs = _robot_fields(rd, rob, base_dir)
    if "name" in top:
        kwargs["name"] = rd.string(top["name"], "name")
    if top.get("track") is not None:
        kwargs["track"] = _track_from_dict(rd, top["track"], "frame" in rob)
    if top.get("turntable") is not None:
        kwargs["turntable"] = _turntable_from_dict(rd, top["turntable"])
    if top.get("positioner") is not None:
        if "turntable" in kwargs:
            raise rd.fail("positioner", "and key 'turntable' both describe the axes carrying the "
                          "work; keep one (a turntable is a positioner of one axis)")
        kwargs["turntable"] = _positioner_from_dict(rd, top["positioner"])
    tools = {name: _tool_from_dict(rd, name, td) for name, td in
             rd.mapping(top.get("tools") or {}, "tools", set(top.get("tools") or {})).items()}
    frames = {name: _frame_from_dict(rd, name, fd, "turntable" in kwargs) for name, fd in
              rd.mapping(top.get("frames") or {}, "frames", set(top.get("frames") or {})).items()}
    return {**kwargs, "tools": tools, "frames": frames}


def _robot_fields(rd: _Reader, rob: dict, base_dir: str | Path) -> dict[str, Any]:
    """``robot``, ``robot_model`` and those of ``identified`` and ``T_world_R`` the ``robot``
    section ``rob`` gives."""
    model, robot = _robot(rd, rob["model"], "robot.model", base_dir)
    kwargs: dict[str, Any] = {"robot": robot, "robot_model": model}
    if rob.get("identified") is not None:
        path, arm = _robot(rd, rob["identified"], "robot.identified", base_dir)
        prov = (rd.provenance(rob["provenance"], "robot.provenance") if "provenance" in rob
                else Provenance("manual"))
        kwargs.update(robot=arm, identified=IdentifiedArm(robot, path, prov))
        try:
            check_identified(robot, arm)
        except InputError as exc:
            raise rd.fail("robot.identified", f"is refused: {exc}") from None
    elif "provenance" in rob:
        raise rd.fail("robot.provenance", "is the provenance of an identified arm: give "
                      "robot.identified (the identified model file) or remove it")
    if "frame" in rob:
        kwargs["T_world_R"] = rd.pose(rob["frame"], "robot.frame")
    return kwargs


def _track_from_dict(rd: _Reader, value: Any, robot_placed: bool) -> Track:
    """The ``track`` section (mm); ``robot_placed``: whether the ``robot`` section gives a frame
    (refused: the track places the robot)."""
    t = rd.mapping(value, "track", {"name", "frame", "robot_at_zero", "axis", "scale", "min",
                                    "max", "provenance"})
    if robot_placed:
        raise rd.fail("robot.frame", "must be omitted when the cell has a track: the track "
                      "places the robot (track.frame and track.robot_at_zero)")
    axis = t.get("axis", "x")
    if axis not in ("x", "y", "z"):
        raise rd.fail("track.axis", f"must be x, y or z, got {axis!r}")
    lo, hi = rd.limits(t, "track", 1e-3)
    scale = rd.number(t.get("scale", 1.0), "track.scale")
    if scale <= 0:
        raise rd.fail("track.scale", f"must be > 0, got {scale}")
    return Track(
        T_world_L=rd.pose(t.get("frame", {}), "track.frame"),
        T_L_R0=rd.pose(t.get("robot_at_zero", {}), "track.robot_at_zero"),
        axis=axis, scale=scale, lower=lo, upper=hi,
        name=rd.string(t.get("name", "track"), "track.name"),
        provenance=rd.provenance(t.get("provenance"), "track.provenance"),
    )


def _turntable_from_dict(rd: _Reader, value: Any) -> Turntable:
    """The ``turntable`` section (mm, deg)."""
    t = rd.mapping(value, "turntable", {"name", "frame", "parent", "min", "max", "provenance"})
    parent = t.get("parent", "world")
    if parent not in ("world", "robot"):
        raise rd.fail("turntable.parent", f"must be world or robot, got {parent!r}")
    lo, hi = rd.limits(t, "turntable", math.pi / 180)
    return Turntable(
        T_parent_B=rd.pose(t.get("frame", {}), "turntable.frame"), parent=parent,
        lower=lo, upper=hi, name=rd.string(t.get("name", "turntable"), "turntable.name"),
        provenance=rd.provenance(t.get("provenance"), "turntable.provenance"),
    )


def _tool_from_dict(rd: _Reader, name: Any, value: Any) -> Tool:
    """The entry ``name`` of the ``tools`` section (mm, kg)."""
    key = f"tools.{name}"
    _named(rd, name, key, "tool")
    td = rd.mapping(value, key, {"number", "frame", "mass", "cog", "provenance"}, ("frame",))
    cog = td.get("cog")
    if cog is not None and (not isinstance(cog, list) or len(cog) != 3):
        raise rd.fail(f"{key}.cog", f"must be a list [x, y, z] in mm, got {cog!r}")
    mass = rd.number(td["mass"], f"{key}.mass") if "mass" in td else None
    if mass is not None and mass <= 0:
        raise rd.fail(f"{key}.mass", f"must be > 0 kg, got {td['mass']}")
    return Tool(
        T_F_TCP=rd.pose(td["frame"], f"{key}.frame"),
        number=rd.integer(td["number"], f"{key}.number") if "number" in td else None,
        mass=mass,
        cog=None if cog is None else np.array(
            [rd.number(v, f"{key}.cog[{i}]") for i, v in enumerate(cog)]) * 1e-3,
        provenance=rd.provenance(td.get("provenance"), f"{key}.provenance"),
    )


def _frame_from_dict(rd: _Reader, name: Any, value: Any, has_turntable: bool) -> Frame:
    """The entry ``name`` of the ``frames`` section (mm, deg); ``has_turntable``: whether the
    cell has a turntable or positioner to carry it."""
    key = f"frames.{name}"
    _named(rd, name, key, "frame")
    fd = rd.mapping(value, key, {"number", "parent", "frame", "provenance"}, ("frame",))
    parent = fd.get("parent", "world")
    if parent not in ("world", "robot", "turntable"):
        raise rd.fail(f"{key}.parent", f"must be world, robot or turntable, got {parent!r}")
    if parent == "turntable" and not has_turntable:
        raise rd.fail(f"{key}.parent", "is turntable, but the cell has no turntable")
    return Frame(
        pose=rd.pose(fd["frame"], f"{key}.frame"), parent=parent,
        number=rd.integer(fd["number"], f"{key}.number") if "number" in fd else None,
        provenance=rd.provenance(fd.get("provenance"), f"{key}.provenance"),
    )


_AXIS_KEYS = {"name", "a", "alpha", "d", "theta", "beta", "sign", "min", "max"}


def _positioner_from_dict(rd: _Reader, value: Any) -> Positioner:
    """The ``positioner`` section: root frame, DH axes (mm, deg), plate, limits."""
    p = rd.mapping(value, "positioner", {"name", "parent", "frame", "convention", "axes", "plate",
                                         "provenance"}, ("axes",))
    parent = p.get("parent", "world")
    if parent not in ("world", "robot"):
        raise rd.fail("positioner.parent", f"must be world or robot, got {parent!r}")
    axes = p["axes"]
    if not isinstance(axes, list) or not 1 <= len(axes) <= 3:
        raise rd.fail("positioner.axes", "must be a list of 1 to 3 axes {a, alpha, d, theta, "
                      "sign, min, max} (mm, deg)")
    for i, ax in enumerate(axes, start=1):
        rd.mapping(ax, f"positioner.axes[{i}]", _AXIS_KEYS)
    name = rd.string(p.get("name", "positioner"), "positioner.name")
    model: dict[str, Any] = {"name": name, "convention": p.get("convention", "standard"),
                             "joints": [{"type": "revolute", **ax} for ax in axes],
                             "base": rd.mapping(p.get("frame", {}), "positioner.frame",
                                                set(_POSE_KEYS)),
                             "flange": rd.mapping(p.get("plate", {}), "positioner.plate",
                                                  set(_POSE_KEYS))}
    chain = robot_from_dict(model, f"{rd.origin}: positioner")
    return Positioner(chain, parent=parent, name=name,
                      provenance=rd.provenance(p.get("provenance"), "positioner.provenance"))


def _positioner_dict(pos: Positioner, base_dir: str | Path) -> dict[str, Any]:
    """The ``positioner`` section of ``pos`` (mm, deg)."""
    out: dict[str, Any] = {"name": pos.name, "parent": pos.parent,
                           "frame": _pose_dict(pos.chain.base),
                           "convention": pos.chain.convention}
    out["axes"] = [{k: _clean(v) if isinstance(v, float) else v for k, v in j.items()
                    if k != "type"} for j in robot_to_dict(pos.chain)["joints"]]
    if not np.allclose(pos.chain.flange, np.eye(4), atol=0):
        out["plate"] = _pose_dict(pos.chain.flange)
    out["provenance"] = _prov_dict(pos.provenance, base_dir)
    return out


def _named(rd: _Reader, name: Any, key: str, what: str) -> None:
    try:
        check_name(name, what)
    except InputError as exc:
        raise rd.fail(key, f"is not a valid name: {exc}") from None


def _clean(v: float) -> float | int:
    # 10 decimals of mm or deg: 1e-10 mm, or 2e-12 rad (1e-11 mm at 6 m), far below any
    # measurement, and a file a person can read (90 rather than 89.99999999999999).
    r = round(float(v), 10) + 0.0
    return int(r) if r == int(r) and abs(r) < 1e15 else r


def _pose_dict(T: NDArray[np.float64]) -> dict[str, float | int]:
    return {k: _clean(v) for k, v in zip(_POSE_KEYS, pose_to_vendor(T, "kuka"))}


def _prov_dict(p: Provenance, base_dir: str | Path = ".") -> dict[str, Any]:
    out: dict[str, Any] = {"source": p.source}
    if p.time is not None:
        out["time"] = p.time
    if p.rms_mm is not None:
        out["rms_mm"] = p.rms_mm
    if p.note:
        out["note"] = p.note
    if p.id is not None:
        out["id"] = p.id
    if p.measurements is not None:
        out["measurements"] = os.path.relpath(Path(p.measurements).resolve(),
                                              Path(base_dir).resolve())
    if p.sha256 is not None:
        out["sha256"] = p.sha256
    if p.options:
        out["options"] = dict(p.options)
    if p.inputs:
        out["inputs"] = list(p.inputs)
    if p.sources:
        size = len(next(iter(p.sources.values())))
        unit = _mm_rad(size)
        cov = sum(f @ f.T for f in p.sources.values()) * np.outer(unit, unit)
        sd = np.sqrt(np.diag(cov))
        sigma = {"position_mm": [_clean(v) for v in sd[:3]],
                 "rotation_deg": [_clean(math.degrees(v)) for v in sd[3:6]]}
        if size > 6:
            sigma["scale"] = _clean(sd[6])
        out["sigma"] = sigma
        out["covariance_mm_rad"] = [[float(f"{v:.6g}") for v in row] for row in cov]
        out["sources_mm_rad"] = {k: [[float(f"{v:.6g}") for v in row] for row in f * unit[:, None]]
                                 for k, f in p.sources.items()}
    return out


def cell_to_dict(cell: CellRecord, base_dir: str | Path = ".") -> dict[str, Any]:
    """The cell-file content of ``cell`` (millimetres, degrees).

    Parameters
    ----------
    cell : CellRecord
        A :class:`~robotcell.cell.model.Cell` (SI units).
    base_dir : str or Path
        Directory of the file to be written; a robot model path is written relative to it.

    Returns
    -------
    dict
    """
    if tuple(cell.robots) != (DEFAULT_ROBOT,):
        return robots_to_dict(cell, base_dir)
    rob: dict[str, Any] = {"model": _relative(cell.robot_model, base_dir)}
    if not np.allclose(cell.T_world_R, np.eye(4), atol=0):
        rob["frame"] = _pose_dict(cell.T_world_R)
    if cell.identified is not None:
        rob["identified"] = _relative(cell.identified.model, base_dir)
        rob["provenance"] = _prov_dict(cell.identified.provenance)
    data: dict[str, Any] = {"name": cell.name, "robot": rob}
    if cell.track is not None:
        t = cell.track
        td: dict[str, Any] = {"name": t.name, "frame": _pose_dict(t.T_world_L),
                              "robot_at_zero": _pose_dict(t.T_L_R0), "axis": t.axis,
                              "scale": _clean(t.scale)}
        if math.isfinite(t.lower):
            td["min"] = _clean(t.lower * 1e3)
        if math.isfinite(t.upper):
            td["max"] = _clean(t.upper * 1e3)
        td["provenance"] = _prov_dict(t.provenance, base_dir)
        data["track"] = td
    if isinstance(cell.turntable, Positioner):
        data["positioner"] = _positioner_dict(cell.turntable, base_dir)
    elif cell.turntable is not None:
        b = cell.turntable
        bd: dict[str, Any] = {"name": b.name, "parent": b.parent, "frame": _pose_dict(b.T_parent_B)}
        if math.isfinite(b.lower):
            bd["min"] = _clean(math.degrees(b.lower))
        if math.isfinite(b.upper):
            bd["max"] = _clean(math.degrees(b.upper))
        bd["provenance"] = _prov_dict(b.provenance, base_dir)
        data["turntable"] = bd
    tools: dict[str, Any] = {}
    for name, tool in cell.tools.items():
        entry: dict[str, Any] = {}
        if tool.number is not None:
            entry["number"] = tool.number
        entry["frame"] = _pose_dict(tool.T_F_TCP)
        if tool.mass is not None:
            entry["mass"] = _clean(tool.mass)
        if tool.cog is not None:
            entry["cog"] = [_clean(v * 1e3) for v in tool.cog]
        entry["provenance"] = _prov_dict(tool.provenance, base_dir)
        tools[name] = entry
    data["tools"] = tools
    frames: dict[str, Any] = {}
    for name, fr in cell.frames.items():
        entry = {}
        if fr.number is not None:
            entry["number"] = fr.number
        entry["parent"] = fr.parent
        entry["frame"] = _pose_dict(fr.pose)
        entry["provenance"] = _prov_dict(fr.provenance, base_dir)
        frames[name] = entry
    data["frames"] = frames
    return data


# -- a cell of several robots: the robots section -------------------------------------------------
_ROBOT_KEYS = {"model", "frame", "identified", "provenance", "base_provenance", "track", "tools"}


def robots_fields(data: dict, origin: str = "cell", base_dir: str | Path = ".") -> dict[str, Any]:
    """The keyword arguments of :class:`~robotcell.cell.model.Cell` that a cell file with a
    ``robots`` section gives: ``robots`` (name -> :class:`CellRobot`), ``turntable``, ``frames``
    and ``name``.

    Each robot's entry is read as the one-robot sections are (``robot`` keys, ``track``,
    ``tools``), its messages prefixed by the robot's name; a frame's parent (and the turntable's
    or positioner's, in a cell of one robot) may be a robot's name.

    Parameters
    ----------
    data : dict
        Parsed YAML (millimetres, degrees).
    origin : str
        What to call the source in error messages (a file name).
    base_dir : str or Path
        Directory against which a relative robot model path is resolved.

    Returns
    -------
    dict

    Raises
    ------
    InputError
        Naming ``origin``, the robot and the key at fault.
    """
    rd = _Reader(origin, base_dir)
    top = rd.mapping(data, "", {"name", "robots", "turntable", "positioner", "frames"})
    entries = rd.mapping(top["robots"], "robots", set(top["robots"] or {}))
    if not entries:
        raise rd.fail("robots", "must name at least one robot: {NAME: {model: ..., ...}}")
    robots: dict[str, CellRobot] = {}
    for name, entry in entries.items():
        _named(rd, name, f"robots.{name}", "robot")
        robots[name] = _robot_entry(rd, name, entry, base_dir)
    names = list(robots)
    shared = {k: v for k, v in top.items() if k != "robots"}
    owner: dict[str, str] = {}
    frames = rd.mapping(top.get("frames") or {}, "frames", set(top.get("frames") or {}))
    shared["frames"] = {f: _placeholder_parent(rd, f"frames.{f}", fd, names, owner, f)
                        for f, fd in frames.items()}
    for key in ("turntable", "positioner"):
        if top.get(key) is not None:
            shared[key] = _placeholder_parent(rd, key, top[key], names[:1] if len(names) == 1
                                              else [], {}, key)
    shared["robot"] = {"model": entries[names[0]]["model"]}
    fields = cell_fields(shared, origin, base_dir)
    out = {"robots": robots, "frames": fields["frames"]}
    for key in ("turntable", "name"):
        if key in fields:
            out[key] = fields[key]
    for f, rname in owner.items():
        out["frames"][f].parent = rname
    return out


def _robot_entry(rd: _Reader, name: str, entry: Any, base_dir: str | Path) -> CellRobot:
    """One robot of the ``robots`` section, read as a one-robot cell's robot, track and tools."""
    key = f"robots.{name}"
    m = rd.mapping(entry, key, _ROBOT_KEYS, ("model",))
    one = {"robot": {k: m[k] for k in ("model", "frame", "identified", "provenance") if k in m},
           **{k: m[k] for k in ("track", "tools") if k in m}}
    fields = cell_fields(one, f"{rd.origin}: robot {name!r}", base_dir)
    prov = (rd.provenance(m["base_provenance"], f"{key}.base_provenance")
            if "base_provenance" in m else Provenance())
    try:
        return CellRobot(robot=fields["robot"], model=fields["robot_model"],
                         T_world_R=fields.get("T_world_R", np.eye(4)), track=fields.get("track"),
                         tools=fields["tools"], identified=fields.get("identified"),
                         base_provenance=prov)
    except InputError as exc:
        raise rd.fail(key, f"is invalid: {exc}") from None


def _placeholder_parent(rd: _Reader, key: str, value: Any, names: list[str],
                        owner: dict[str, str], item: str) -> Any:
    """``value`` with a robot's name as ``parent`` read as the one-robot reader's ``robot``
    (frames: ``world``, the robot noted in ``owner``); ``parent: robot`` is refused."""
    if not isinstance(value, dict) or "parent" not in value:
        return value
    parent = value["parent"]
    if parent == "robot":
        raise rd.fail(f"{key}.parent", f"must name the robot in a cell with a robots section "
                      f"({', '.join(names) or 'world only: the robots share it'}), got 'robot'")
    frame = key.startswith("frames.")
    if frame and parent not in (*names, "world", "turntable"):
        raise rd.fail(f"{key}.parent", f"must be world, turntable or a robot of the cell "
                      f"({', '.join(names)}), got {parent!r}")
    if parent not in names:
        return value
    if frame:
        owner[item] = parent
        return {**value, "parent": "world"}
    return {**value, "parent": "robot"}


def robots_to_dict(cell: CellRecord, base_dir: str | Path = ".") -> dict[str, Any]:
    """The content of a cell file with a ``robots`` section (millimetres, degrees).

    Parameters
    ----------
    cell : CellRecord
        A :class:`~robotcell.cell.model.Cell` (SI units).
    base_dir : str or Path
        Directory of the file to be written; a robot model path is written relative to it.

    Returns
    -------
    dict
    """
    names = list(cell.robots)
    robots: dict[str, Any] = {}
    for name, unit in cell.robots.items():
        one = cell_to_dict(_OneRobot(unit, None, {}, cell.name), base_dir)
        entry = dict(one["robot"])
        if _prov_dict(unit.base_provenance) != {"source": "nominal"}:
            entry["base_provenance"] = _prov_dict(unit.base_provenance, base_dir)
        if "track" in one:
            entry["track"] = one["track"]
        entry["tools"] = one["tools"]
        robots[name] = entry
    first = cell.robots[names[0]]
    shared = cell_to_dict(_OneRobot(first, cell.turntable, cell.frames, cell.name), base_dir)
    data: dict[str, Any] = {"name": cell.name, "robots": robots}
    for key in ("turntable", "positioner"):
        if key in shared:
            data[key] = shared[key]
            if data[key]["parent"] == "robot":
                data[key]["parent"] = names[0]
    data["frames"] = shared["frames"]
    for entry in data["frames"].values():
        if entry["parent"] == "robot":
            entry["parent"] = names[0]
    return data


class _OneRobot:
    """One robot of a cell with the shared parts, as :func:`cell_to_dict` reads a cell."""

    def __init__(self, unit: CellRobot, turntable: Any, frames: dict[str, Frame], name: str):
        self.robots = {DEFAULT_ROBOT: unit}
        self.robot_model, self.T_world_R, self.identified = unit.model, unit.T_world_R, unit.identified
        self.robot, self.track, self.tools = unit.robot, unit.track, unit.tools
        self.turntable, self.frames, self.name = turntable, frames, name
