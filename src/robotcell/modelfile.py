"""Robot model files (YAML) and the built-in robot library.

A model file is written by hand in the vendor's units (see ``docs/models.md``)::

    name: my_robot
    convention: standard        # or: modified
    units: {length: mm, angle: deg}
    joints:
      - {type: revolute,  a: 25, alpha: -90, d: 400, theta: 0,  min: -170, max: 170}
      - {type: prismatic, a: 0,  alpha: 0,   d: 0,   theta: 90, min: 0,    max: 1500}

The loader converts to SI and reports any problem with the file, the joint and the key.
"""

from __future__ import annotations

import difflib
import math
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from robotcell.errors import InputError
from robotcell.fileio import atomic_write, read_text
from robotcell.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.robot import Joint, Robot

__all__ = ["list_robots", "load_robot", "robot_from_dict", "robot_to_dict", "save_robot"]

_LENGTH = {"mm": 1e-3, "m": 1.0}
_ANGLE = {"deg": math.pi / 180, "rad": 1.0}
_JOINT_KEYS = {"type", "a", "alpha", "d", "theta", "sign", "min", "max", "name"}
_POSE_KEYS = {"x", "y", "z", "a", "b", "c"}
_TOP_KEYS = {"name", "title", "convention", "units", "joints", "base", "flange", "tool", "home",
             "source", "verified", "verification"}


def _library_dir():
    return resources.files("robotcell") / "robots"


def list_robots() -> list[str]:
    """Names of the robots in the built-in library, sorted."""
    return sorted(p.name[:-5] for p in _library_dir().iterdir() if p.name.endswith(".yaml"))


def load_robot(name_or_path: str | Path) -> Robot:
    """Load a robot from the built-in library or from a YAML model file.

    Parameters
    ----------
    name_or_path : str or Path
        A library name (``kuka_kr16``, ``ur5e``; see :func:`list_robots`) or the path of a model
        file.

    Returns
    -------
    Robot

    Raises
    ------
    InputError
        Unknown name (the closest library names are offered), unreadable file, or a file whose
        content is invalid (the message names the file, the joint and the key).
    """
    text = str(name_or_path)
    path = Path(text)
    if path.suffix.lower() in (".yaml", ".yml") or path.exists():
        if not path.is_file():
            raise InputError(f"robot model file {text!r} does not exist")
        return _load_file(read_text(path, "robot model file"), str(path))
    lib = _library_dir() / f"{text}.yaml"
    if lib.is_file():
        return _load_file(lib.read_text(encoding="utf-8"), f"library robot {text!r}")
    close = difflib.get_close_matches(text.lower(), list_robots(), n=3, cutoff=0.4)
    hint = f"; did you mean {', '.join(close)}?" if close else "; run 'robotcell robots' for the list"
    raise InputError(f"unknown robot {text!r} (neither a library name nor a model file){hint}")


def _load_file(text: str, origin: str) -> Robot:
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise InputError(f"{origin}: not valid YAML: {exc}") from None
    return robot_from_dict(data, origin)


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{where} must be a number, got {value!r}")
    if not math.isfinite(value):
        raise InputError(f"{where} must be finite, got {value!r}")
    return float(value)


def _pose(value: Any, where: str, lscale: float, ascale: float) -> np.ndarray:
    if not isinstance(value, dict):
        raise InputError(f"{where} must be a mapping with keys x, y, z, a, b, c")
    unknown = set(value) - _POSE_KEYS
    if unknown:
        raise InputError(f"{where}: unknown key(s) {sorted(unknown)}; allowed: x, y, z, a, b, c")
    v = [_number(value.get(k, 0.0), f"{where}: key '{k}'") for k in ("x", "y", "z", "a", "b", "c")]
    # KUKA ABC convention; convert the file's units to mm / deg first.
    v = [x * lscale * 1e3 for x in v[:3]] + [math.degrees(x * ascale) for x in v[3:]]
    return pose_from_vendor(v, "kuka")


def robot_from_dict(data: Any, origin: str = "model") -> Robot:
    """Build a robot from the parsed content of a model file.

    Parameters
    ----------
    data : dict
        Parsed YAML (file units).
    origin : str
        What to call the source in error messages (a file name).

    Returns
    -------
    Robot
    """
    if not isinstance(data, dict):
        raise InputError(f"{origin}: a model file must be a YAML mapping with keys name, joints, ...")
    unknown = set(data) - _TOP_KEYS
    if unknown:
        raise InputError(f"{origin}: unknown key(s) {sorted(unknown)}; allowed: {sorted(_TOP_KEYS)}")
    for key in ("name", "joints"):
        if key not in data:
            raise InputError(f"{origin}: missing key '{key}'")
    units = data.get("units", {"length": "mm", "angle": "deg"})
    if not isinstance(units, dict):
        raise InputError(f"{origin}: key 'units' must be a mapping like {{length: mm, angle: deg}}")
    lunit, aunit = units.get("length", "mm"), units.get("angle", "deg")
    if lunit not in _LENGTH:
        raise InputError(f"{origin}: units.length must be 'mm' or 'm', got {lunit!r}")
    if aunit not in _ANGLE:
        raise InputError(f"{origin}: units.angle must be 'deg' or 'rad', got {aunit!r}")
    ls, as_ = _LENGTH[lunit], _ANGLE[aunit]
    joints_data = data["joints"]
    if not isinstance(joints_data, list) or not joints_data:
        raise InputError(f"{origin}: key 'joints' must be a non-empty list")
    joints = []
    for i, jd in enumerate(joints_data, start=1):
        where = f"{origin}: joint {i}"
        if not isinstance(jd, dict):
            raise InputError(f"{where} must be a mapping with keys type, a, alpha, d, theta")
        unknown = set(jd) - _JOINT_KEYS
        if unknown:
            raise InputError(f"{where}: unknown key(s) {sorted(unknown)}; allowed: {sorted(_JOINT_KEYS)}")
        for key in ("type", "a", "alpha", "d", "theta"):
            if key not in jd:
                raise InputError(f"{where}: missing key '{key}'")
        jtype = jd["type"]
        if jtype not in ("revolute", "prismatic"):
            raise InputError(f"{where}: key 'type' must be 'revolute' or 'prismatic', got {jtype!r}")
        qscale = ls if jtype == "prismatic" else as_
        sign = _number(jd.get("sign", 1), f"{where}: key 'sign'")
        if sign not in (1.0, -1.0):
            raise InputError(f"{where}: key 'sign' must be +1 or -1, got {jd['sign']!r}")
        lo = _number(jd["min"], f"{where}: key 'min'") * qscale if "min" in jd else -math.inf
        hi = _number(jd["max"], f"{where}: key 'max'") * qscale if "max" in jd else math.inf
        if not lo < hi:
            raise InputError(f"{where}: key 'min' ({jd.get('min')}) must be below key 'max' ({jd.get('max')})")
        joints.append(Joint(
            type=jtype,
            a=_number(jd["a"], f"{where}: key 'a'") * ls,
            alpha=_number(jd["alpha"], f"{where}: key 'alpha'") * as_,
            d=_number(jd["d"], f"{where}: key 'd'") * ls,
            theta=_number(jd["theta"], f"{where}: key 'theta'") * as_,
            sign=sign, lower=lo, upper=hi, name=str(jd.get("name", f"A{i}")),
        ))
    kwargs: dict[str, Any] = {}
    for key in ("base", "flange", "tool"):
        if key in data:
            kwargs[key] = _pose(data[key], f"{origin}: key '{key}'", ls, as_)
    if "home" in data:
        home = data["home"]
        if not isinstance(home, list) or len(home) != len(joints):
            raise InputError(f"{origin}: key 'home' must be a list of {len(joints)} joint values")
        kwargs["home"] = np.array([
            _number(v, f"{origin}: key 'home' value {k}") * (ls if j.prismatic else as_)
            for k, (v, j) in enumerate(zip(home, joints), start=1)
        ])
    convention = data.get("convention", "standard")
    if convention not in ("standard", "modified"):
        raise InputError(f"{origin}: key 'convention' must be 'standard' or 'modified', got {convention!r}")
    verified = data.get("verified", False)
    if not isinstance(verified, bool):
        raise InputError(f"{origin}: key 'verified' must be true or false, got {verified!r}")
    try:
        return Robot(
            name=str(data["name"]), joints=tuple(joints), convention=convention,
            title=str(data.get("title", data["name"])), source=str(data.get("source", "")),
            verified=verified, verification=str(data.get("verification", "")), **kwargs,
        )
    except InputError as exc:
        raise InputError(f"{origin}: {exc}") from None


def robot_to_dict(robot: Robot) -> dict[str, Any]:
    """The model-file content of ``robot`` (millimetres and degrees)."""
    joints = []
    for j in robot.joints:
        qs = 1e3 if j.prismatic else 180 / math.pi
        entry: dict[str, Any] = {
            "name": j.name, "type": j.type, "a": j.a * 1e3, "alpha": math.degrees(j.alpha),
            "d": j.d * 1e3, "theta": math.degrees(j.theta), "sign": int(j.sign),
        }
        if math.isfinite(j.lower):
            entry["min"] = j.lower * qs
        if math.isfinite(j.upper):
            entry["max"] = j.upper * qs
        joints.append({k: _clean(v) for k, v in entry.items()})
    data: dict[str, Any] = {
        "name": robot.name, "title": robot.title, "convention": robot.convention,
        "units": {"length": "mm", "angle": "deg"}, "joints": joints,
    }
    for key in ("base", "flange", "tool"):
        T = getattr(robot, key)
        if not np.allclose(T, np.eye(4), atol=1e-15):
            data[key] = dict(zip("xyzabc", (_clean(v) for v in pose_to_vendor(T, "kuka"))))
    if robot.home is not None:
        data["home"] = [
            _clean(v * (1e3 if j.prismatic else 180 / math.pi)) for v, j in zip(robot.home, robot.joints)
        ]
    data.update(source=robot.source, verified=robot.verified, verification=robot.verification)
    return data


def _clean(v: Any) -> Any:
    """A plain Python int or float (YAML cannot write numpy scalars), rounded to 9 decimals."""
    if isinstance(v, (float, np.floating)):
        r = round(float(v), 9)
        return int(r) if r == int(r) and abs(r) < 1e15 else r
    if isinstance(v, np.integer):
        return int(v)
    return v


def save_robot(robot: Robot, path: str | Path) -> None:
    """Write ``robot`` as a YAML model file (millimetres and degrees), atomically.

    Raises
    ------
    InputError
        The file cannot be written (missing folder, a folder, no permission).
    """
    atomic_write(path, yaml.safe_dump(robot_to_dict(robot), sort_keys=False,
                                      default_flow_style=None))
