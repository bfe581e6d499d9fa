"""Robot model files (YAML) and the built-in robot library.

A model file is written by hand in the vendor's units (see ``docs/models.md``)::

    name: my_robot
    convention: standard        # or: modified
    units: {length: mm, angle: deg}
    joints:
      - {type: revolute,  a: 25, alpha: -90, d: 400, theta: 0,  min: -170, max: 170}
      - {type: prismatic, a: 0,  alpha: 0,   d: 0,   theta: 90, min: 0,    max: 1500}
    coupling: {j23_factor: 1}   # optional: q_model = C q_controller + offset
    ik_seed: kuka_kr16          # optional: nominal model whose analytic IK seeds this one's

The loader converts to SI and reports any problem with the file, the joint and the key.
"""

from __future__ import annotations

import difflib
import math
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write, read_text
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.io.tables import MAX_ABS_VALUE
from robotcell.io.yamlfile import dump_yaml, parse_yaml
from robotcell.kinematics.coupling import Coupling
from robotcell.kinematics.covariance import ParameterCovariance, parameter_kind
from robotcell.robot.robot import Joint, Robot

__all__ = ["list_robots", "load_robot", "robot_from_dict", "robot_to_dict", "save_robot"]

_LENGTH = {"mm": 1e-3, "m": 1.0}
_ANGLE = {"deg": math.pi / 180, "rad": 1.0}
_JOINT_KEYS = {"type", "a", "alpha", "d", "theta", "beta", "sign", "min", "max", "name", "passive",
               "mass", "com"}
_COUPLING_KEYS = {"j23_factor", "matrix", "offset", "interaction"}
_POSE_KEYS = {"x", "y", "z", "a", "b", "c"}
#: Written constants: lengths in mm to 9 decimals (1e-12 m), angles in degrees to 12 (2e-14 rad,
#: 2e-13 m at 10 m): a model file reproduces the model it was written from to far below 1e-9 m.
_ANGLE_DECIMALS = 12
_ANGLE_KEYS = {"alpha", "theta", "beta"}
_TOP_KEYS = {"name", "title", "convention", "units", "joints", "base", "flange", "tool", "home",
             "source", "verified", "verification", "coupling", "ik_seed", "covariance",
             "repeatability", "link_radius"}


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
    return robot_from_dict(parse_yaml(text, origin), origin)


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{where} must be a number, got {value!r}")
    if not math.isfinite(value):
        raise InputError(f"{where} must be finite, got {value!r}")
    return float(value)


def _mapping(value: Any, where: str, allowed: set[str], not_mapping: str,
             required: tuple[str, ...] = (), listed: str | None = None) -> dict:
    """``value`` when it is a mapping with only ``allowed`` keys and every ``required`` one.

    ``not_mapping`` is the message for a value that is not a mapping; ``listed`` the allowed keys
    as the message names them (default: sorted).
    """
    if not isinstance(value, dict):
        raise InputError(not_mapping)
    unknown = set(value) - allowed
    if unknown:
        raise InputError(f"{where}: unknown key(s) {sorted(unknown)}; "
                         f"allowed: {listed or sorted(allowed)}")
    for key in required:
        if key not in value:
            raise InputError(f"{where}: missing key '{key}'")
    return value


#: Largest link radius a model file may give (m): no industrial arm's link is thicker.
LINK_RADIUS_MAX = 1.0


def _link_radius(value: Any, origin: str, ls: float) -> float:
    """Key ``link_radius``: the radius of the arm's capsules for clearance checks, in the file's
    length unit; returns metres."""
    where = f"{origin}: key 'link_radius'"
    r = _number(value, where) * ls
    if not 0 < r <= LINK_RADIUS_MAX:
        raise InputError(f"{where} must be a radius above 0 and at most "
                         f"{LINK_RADIUS_MAX / ls:g} (the file's length unit), got {value!r}")
    return r


def _repeatability(value: Any, origin: str) -> tuple[float, str]:
    """Key ``repeatability``: ``{mm: RP, source: citation}``, the datasheet's pose repeatability
    (mm) and where it is stated; returns metres and the citation."""
    where = f"{origin}: key 'repeatability'"
    entry = _mapping(value, where, {"mm", "source"},
                     f"{where} must be a mapping {{mm: RP, source: the datasheet}}",
                     ("mm", "source"))
    rp = _number(entry["mm"], f"{where}: key 'mm'")
    if not 0 < rp <= 10:
        raise InputError(f"{where}: key 'mm' must be a repeatability from 0 to 10 mm, got {rp:g}")
    if not str(entry["source"]).strip():
        raise InputError(f"{where}: key 'source' must name the datasheet that states it")
    return rp * 1e-3, str(entry["source"])


def _pose(value: Any, where: str, lscale: float, ascale: float) -> np.ndarray:
    _mapping(value, where, _POSE_KEYS, f"{where} must be a mapping with keys x, y, z, a, b, c",
             listed="x, y, z, a, b, c")
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
    _mapping(data, origin, _TOP_KEYS,
             f"{origin}: a model file must be a YAML mapping with keys name, joints, ...",
             ("name", "joints"))
    ls, as_ = _units(data, origin)
    joints_data = data["joints"]
    if not isinstance(joints_data, list) or not joints_data:
        raise InputError(f"{origin}: key 'joints' must be a non-empty list")
    joints = [_joint(jd, f"{origin}: joint {i}", i, ls, as_)
              for i, jd in enumerate(joints_data, start=1)]
    kwargs = _robot_options(data, joints, origin, ls, as_)
    convention = data.get("convention", "standard")
    if convention not in ("standard", "modified"):
        raise InputError(f"{origin}: key 'convention' must be 'standard' or 'modified', got {convention!r}")
    verified = data.get("verified", False)
    if not isinstance(verified, bool):
        raise InputError(f"{origin}: key 'verified' must be true or false, got {verified!r}")
    try:
        robot = Robot(
            name=str(data["name"]), joints=tuple(joints), convention=convention,
            title=str(data.get("title", data["name"])), source=str(data.get("source", "")),
            verified=verified, verification=str(data.get("verification", "")), **kwargs,
        )
    except InputError as exc:
        raise InputError(f"{origin}: {exc}") from None
    _check_lengths(robot, origin)
    return robot


def _units(data: dict, origin: str) -> tuple[float, float]:
    """The model file's ``units``: metres and radians per file length and angle unit."""
    units = data.get("units", {"length": "mm", "angle": "deg"})
    if not isinstance(units, dict):
        raise InputError(f"{origin}: key 'units' must be a mapping like {{length: mm, angle: deg}}")
    lunit, aunit = units.get("length", "mm"), units.get("angle", "deg")
    if lunit not in _LENGTH:
        raise InputError(f"{origin}: units.length must be 'mm' or 'm', got {lunit!r}")
    if aunit not in _ANGLE:
        raise InputError(f"{origin}: units.angle must be 'deg' or 'rad', got {aunit!r}")
    return _LENGTH[lunit], _ANGLE[aunit]


def _joint(jd: Any, where: str, i: int, ls: float, as_: float) -> Joint:
    """Joint ``i`` (from 1) of a model file, ``where`` naming it in messages; ``ls``, ``as_``:
    metres and radians per file unit (:func:`_units`)."""
    _mapping(jd, where, _JOINT_KEYS,
             f"{where} must be a mapping with keys type, a, alpha, d, theta",
             ("type", "a", "alpha", "d", "theta"))
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
    passive = jd.get("passive", False)
    if not isinstance(passive, bool):
        raise InputError(f"{where}: key 'passive' must be true or false, got {passive!r}")
    if passive and ("min" in jd or "max" in jd):
        raise InputError(f"{where}: a passive joint has no limits of its own (remove 'min', 'max'); "
                         "state limits on the controller axes or under coupling.interaction")
    mass = _number(jd.get("mass", 0.0), f"{where}: key 'mass'")
    if mass < 0:
        raise InputError(f"{where}: key 'mass' must be >= 0 (kg), got {jd['mass']!r}")
    com = jd.get("com", [0.0, 0.0, 0.0])
    if not isinstance(com, list) or len(com) != 3:
        raise InputError(f"{where}: key 'com' must be [x, y, z], the centre of mass in the "
                         "link's DH frame (file length unit)")
    return Joint(
        mass=mass, com=tuple(_number(v, f"{where}: key 'com'") * ls for v in com),
        type=jtype,
        a=_number(jd["a"], f"{where}: key 'a'") * ls,
        alpha=_number(jd["alpha"], f"{where}: key 'alpha'") * as_,
        d=_number(jd["d"], f"{where}: key 'd'") * ls,
        theta=_number(jd["theta"], f"{where}: key 'theta'") * as_,
        beta=_number(jd.get("beta", 0.0), f"{where}: key 'beta'") * as_,
        sign=sign, lower=lo, upper=hi, name=str(jd.get("name", f"P{i}" if passive else f"A{i}")),
        passive=passive,
    )


def _robot_options(data: dict, joints: list[Joint], origin: str, ls: float, as_: float
                   ) -> dict[str, Any]:
    """The optional :class:`Robot` arguments a model file gives: ``coupling``, ``ik_seed``,
    ``covariance``, ``base``, ``flange``, ``tool`` and ``home`` (SI units)."""
    kwargs: dict[str, Any] = {}
    if "coupling" in data:
        kwargs["coupling"] = _coupling(data["coupling"], joints, origin, ls, as_)
    elif any(j.passive for j in joints):
        raise InputError(f"{origin}: passive joints need key 'coupling' with a 'matrix' that says "
                         "how they move")
    if "ik_seed" in data:
        kwargs["ik_seed"] = _ik_seed(data["ik_seed"], origin)
    if "covariance" in data:
        kwargs["covariance"] = _covariance(data["covariance"], origin, ls, as_)
    if "repeatability" in data:
        kwargs["repeatability"], kwargs["repeatability_source"] = _repeatability(
            data["repeatability"], origin)
    if "link_radius" in data:
        kwargs["link_radius"] = _link_radius(data["link_radius"], origin, ls)
    for key in ("base", "flange", "tool"):
        if key in data:
            kwargs[key] = _pose(data[key], f"{origin}: key '{key}'", ls, as_)
    if "home" in data:
        home = data["home"]
        axes = [j for j in joints if not j.passive]
        if not isinstance(home, list) or len(home) != len(axes):
            raise InputError(f"{origin}: key 'home' must be a list of {len(axes)} joint values (one per controller axis)")
        kwargs["home"] = np.array([
            _number(v, f"{origin}: key 'home' value {k}") * (ls if j.prismatic else as_)
            for k, (v, j) in enumerate(zip(home, axes), start=1)
        ])
    return kwargs


def _check_lengths(robot: Robot, origin: str) -> None:
    """Refuse a model with a length beyond :data:`~robotcell.io.tables.MAX_ABS_VALUE` mm (a
    typing error, named by its key), as a measurement table does. The bound is not the size of
    a cell: the DH ``d`` of nearly parallel axes is far longer than the arm (an identified
    model's can be 100 m)."""
    lengths = []
    for i, j in enumerate(robot.joints, start=1):
        lengths += [(f"joint {i}: key 'a'", j.a), (f"joint {i}: key 'd'", j.d)]
        if j.prismatic:
            lengths += [(f"joint {i}: key 'min'", j.lower), (f"joint {i}: key 'max'", j.upper)]
    for key in ("base", "flange", "tool"):
        lengths.append((f"key '{key}'", float(np.abs(getattr(robot, key)[:3, 3]).max())))
    for key, v in lengths:
        if math.isfinite(v) and abs(v) * 1e3 > MAX_ABS_VALUE:
            raise InputError(f"{origin}: {key} is {v * 1e3:g} mm, beyond {MAX_ABS_VALUE:.0e} mm: "
                             "no robot has such a length; a typing error")


def _ik_seed(value: Any, origin: str) -> Robot:
    """Parse key ``ik_seed``: a library name or a nested model (mapping)."""
    where = f"{origin}: key 'ik_seed'"
    if isinstance(value, str):
        if value not in list_robots():
            raise InputError(f"{where}: {value!r} is not a library robot; give a library name or "
                             "the nominal model itself as a nested mapping (name, joints, ...)")
        return load_robot(value)
    if isinstance(value, dict):
        return robot_from_dict(value, where)
    raise InputError(f"{where} must be a library robot name or a nested model mapping")


def _unit_scales(names: tuple[str, ...], ls: float, as_: float) -> np.ndarray:
    """Per parameter, the SI value of one file unit (length ``ls``, angle ``as_``, number 1)."""
    return np.array([{"length": ls, "angle": as_, "number": 1.0}[parameter_kind(n)] for n in names])


def _covariance(value: Any, origin: str, ls: float, as_: float) -> ParameterCovariance:
    """Parse key ``covariance`` (file units) into a :class:`ParameterCovariance` in SI units."""
    where = f"{origin}: key 'covariance'"
    _mapping(value, where, {"parameters", "matrix", "model_error"},
             f"{where} must be a mapping with keys parameters, matrix (and model_error)",
             ("parameters", "matrix"))
    names, rows = value["parameters"], value["matrix"]
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise InputError(f"{where}.parameters must be a list of names (A2.a, A3.beta, ...)")
    if not isinstance(rows, list) or not all(isinstance(r, list) for r in rows):
        raise InputError(f"{where}.matrix must be a list of rows")
    M = np.array([[_number(v, f"{where}.matrix row {i}") for v in r]
                  for i, r in enumerate(rows, start=1)] if rows else np.zeros((0, 0)))
    model_error = _number(value.get("model_error", 0.0), f"{where}.model_error") * ls
    try:
        s = _unit_scales(tuple(names), ls, as_)
        return ParameterCovariance(tuple(names), M * s[:, None] * s[None, :], model_error)
    except (InputError, ValueError) as exc:
        raise InputError(f"{where}: {exc}") from None


def _coupling(value: Any, joints: list[Joint], origin: str, ls: float, as_: float) -> Coupling:
    """Parse key ``coupling`` (file units) into a :class:`Coupling` in SI units."""
    where = f"{origin}: key 'coupling'"
    _mapping(value, where, _COUPLING_KEYS,
             f"{where} must be a mapping with j23_factor, or matrix (and offset, interaction)")
    if ("j23_factor" in value) == ("matrix" in value):
        raise InputError(f"{where} needs exactly one of 'j23_factor' or 'matrix'")
    axes = [j for j in joints if not j.passive]
    m, n = len(joints), len(axes)
    # Scale of each joint's file unit in SI: C_SI[i, j] = C_file[i, j] * s_model[i] / s_axis[j].
    s_model = np.array([ls if j.prismatic else as_ for j in joints])
    s_axis = np.array([ls if j.prismatic else as_ for j in axes])
    if "j23_factor" in value:
        k = _number(value["j23_factor"], f"{where}.j23_factor")
        if m != n or m < 3:
            raise InputError(f"{where}.j23_factor needs at least 3 joints and no passive joint")
        if joints[1].prismatic != joints[2].prismatic:
            raise InputError(f"{where}.j23_factor couples joints 2 and 3, which must be of one type")
        C = np.eye(m)
        C[2, 1] = k
    else:
        rows = value["matrix"]
        if (not isinstance(rows, list) or len(rows) != m
                or not all(isinstance(r, list) and len(r) == n for r in rows)):
            raise InputError(f"{where}.matrix must be {m} rows (one per joint) of {n} numbers (one "
                             f"per controller axis, i.e. per joint that is not passive)")
        C = np.array([[_number(v, f"{where}.matrix row {i} value {c}") for c, v in enumerate(r, start=1)]
                      for i, r in enumerate(rows, start=1)])
        C = C * s_model[:, None] / s_axis[None, :]
    off = value.get("offset")
    if off is not None:
        if not isinstance(off, list) or len(off) != m:
            raise InputError(f"{where}.offset must be a list of {m} numbers (one per joint)")
        off = np.array([_number(v, f"{where}.offset value {i}") for i, v in enumerate(off, start=1)]) * s_model
    A, lo, hi = [], [], []
    limits = value.get("interaction", [])
    if not isinstance(limits, list):
        raise InputError(f"{where}.interaction must be a list of {{coefficients: [...], min: .., max: ..}}")
    for i, lim in enumerate(limits, start=1):
        w = f"{where}.interaction {i}"
        if not isinstance(lim, dict) or set(lim) - {"coefficients", "min", "max"} or "coefficients" not in lim:
            raise InputError(f"{w} must be a mapping with keys coefficients, min, max")
        co = lim["coefficients"]
        if not isinstance(co, list) or len(co) != n:
            raise InputError(f"{w}: coefficients must be {n} numbers, one per controller axis")
        a = np.array([_number(v, f"{w}: coefficient {c}") for c, v in enumerate(co, start=1)])
        used = {axes[c].prismatic for c in np.flatnonzero(a)}
        if len(used) != 1:
            raise InputError(f"{w}: coefficients must be nonzero on axes of one type (all revolute or "
                             "all prismatic), so that min and max have one unit")
        scale = ls if used.pop() else as_
        A.append(a * scale / s_axis)
        lo.append(_number(lim["min"], f"{w}: key 'min'") * scale if "min" in lim else -math.inf)
        hi.append(_number(lim["max"], f"{w}: key 'max'") * scale if "max" in lim else math.inf)
    try:
        return Coupling(C, off, np.array(A).reshape(-1, n), np.array(lo), np.array(hi))
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def _coupling_to_dict(robot: Robot) -> dict[str, Any]:
    """Key ``coupling`` of a model file (mm, deg) for ``robot.coupling``."""
    c = robot.coupling
    assert c is not None
    k = c.j23_factor
    s_model = np.array([1e3 if j.prismatic else 180 / math.pi for j in robot.joints])
    s_axis = np.array([1e3 if j.prismatic else 180 / math.pi for j in robot.axes])
    out: dict[str, Any]
    if k is not None:
        out = {"j23_factor": _clean(k, 12)}
    else:
        C = c.matrix * s_model[:, None] / s_axis[None, :]
        # 12 decimals: an identified scale of 1e-6 times a turn moves the TCP by micrometres
        out = {"matrix": [[_clean(float(v), 12) for v in row] for row in C]}
        if np.any(c.offset):
            out["offset"] = [_clean(float(v)) for v in c.offset * s_model]
    limits = []
    for a, lo, hi in zip(c.interaction, c.interaction_lower, c.interaction_upper):
        scale = 1e3 if robot.axes[int(np.flatnonzero(a)[0])].prismatic else 180 / math.pi
        lim: dict[str, Any] = {"coefficients": [_clean(float(v)) for v in a * s_axis / scale]}
        if math.isfinite(lo):
            lim["min"] = _clean(float(lo * scale))
        if math.isfinite(hi):
            lim["max"] = _clean(float(hi * scale))
        limits.append(lim)
    if limits:
        out["interaction"] = limits
    return out


def robot_to_dict(robot: Robot) -> dict[str, Any]:
    """The model-file content of ``robot`` (millimetres and degrees)."""
    joints = []
    for j in robot.joints:
        qs = 1e3 if j.prismatic else 180 / math.pi
        entry: dict[str, Any] = {
            "name": j.name, "type": j.type, "a": j.a * 1e3, "alpha": math.degrees(j.alpha),
            "d": j.d * 1e3, "theta": math.degrees(j.theta), "sign": int(j.sign),
        }
        if j.beta != 0.0:
            entry["beta"] = math.degrees(j.beta)
        if math.isfinite(j.lower):
            entry["min"] = j.lower * qs
        if math.isfinite(j.upper) and not j.passive:
            entry["max"] = j.upper * qs
        if j.passive:
            entry.pop("min", None)
            entry["passive"] = True
        if j.mass > 0:
            entry["mass"] = j.mass
            entry["com"] = [_clean(v * 1e3) for v in j.com]
        joints.append({k: _clean(v, _ANGLE_DECIMALS if k in _ANGLE_KEYS else 9)
                       for k, v in entry.items()})
    data: dict[str, Any] = {
        "name": robot.name, "title": robot.title, "convention": robot.convention,
        "units": {"length": "mm", "angle": "deg"}, "joints": joints,
    }
    for key in ("base", "flange", "tool"):
        T = getattr(robot, key)
        if not np.allclose(T, np.eye(4), atol=1e-15):
            data[key] = dict(zip("xyzabc", (_clean(v, 9 if i < 3 else _ANGLE_DECIMALS)
                                            for i, v in enumerate(pose_to_vendor(T, "kuka")))))
    if robot.coupling is not None:
        data["coupling"] = _coupling_to_dict(robot)
    if robot.ik_seed is not None:
        data["ik_seed"] = _ik_seed_to_dict(robot.ik_seed)
    if robot.covariance is not None:
        cov = robot.covariance
        s = 1.0 / _unit_scales(cov.names, 1e-3, math.pi / 180)
        M = cov.matrix * s[:, None] * s[None, :]
        data["covariance"] = {"parameters": list(cov.names),
                              "matrix": [[float(f"{v:.12g}") for v in row] for row in M]}
        if cov.model_error:
            data["covariance"]["model_error"] = float(f"{cov.model_error * 1e3:.6g}")
    if robot.home is not None:
        data["home"] = [
            _clean(v * (1e3 if j.prismatic else 180 / math.pi)) for v, j in zip(robot.home, robot.axes)
        ]
    data.update(source=robot.source, verified=robot.verified, verification=robot.verification)
    if robot.repeatability is not None:
        data["repeatability"] = {"mm": _clean(robot.repeatability * 1e3),
                                 "source": robot.repeatability_source}
    if robot.link_radius is not None:
        data["link_radius"] = _clean(robot.link_radius * 1e3)
    return data


def _ik_seed_to_dict(seed: Robot) -> str | dict[str, Any]:
    """Key ``ik_seed``: the library name when the seed is that library model, else the model."""
    data = robot_to_dict(seed)
    data.pop("ik_seed", None)
    if seed.name in list_robots() and robot_to_dict(load_robot(seed.name)) == data:
        return seed.name
    return data


def _clean(v: Any, decimals: int = 9) -> Any:
    """A plain Python int or float (YAML cannot write numpy scalars), rounded to ``decimals``."""
    if isinstance(v, (float, np.floating)):
        r = round(float(v), decimals)
        return int(r) if r == int(r) and abs(r) < 1e15 else r
    if isinstance(v, np.integer):
        return int(v)
    return v


def save_robot(robot: Robot, path: str | Path) -> None:
    """Write ``robot`` as a YAML model file (millimetres and degrees), atomically.

    The text is read back as a robot model before it replaces the file: a file that would not
    load is never written. Through a symbolic link the file it points to is written.

    Raises
    ------
    InputError
        The file cannot be written (missing folder, a folder, no permission, several hard
        links), or the model as written would not load (the reason is named); the file is
        unchanged.
    """
    text = dump_yaml(robot_to_dict(robot), str(path))
    try:
        robot_from_dict(parse_yaml(text, str(path)), str(path))
    except InputError as exc:
        raise InputError(f"the model as it would be written does not load ({exc}); {path} is "
                         "unchanged") from None
    atomic_write(path, text)
