"""Changing the values of one point in a program's text, and nothing else.

A program read back keeps where each point's values stand (``ProgramPoint.where``: file and
line). Retargeting and filtering change those values in the text as it is, so that every other
line, comment and number stays as the pendant or the offline-programming tool wrote it:

- :func:`set_joints`: the six axis values of a joint point (KUKA ``E6AXIS``/``AXIS``, ABB
  ``jointtarget``, FANUC joint position);
- :func:`set_pose`: the Cartesian values of a point and its configuration flags (KUKA ``E6POS``,
  ``POS`` fields X..C and S, T; ABB ``robtarget`` position, quaternion and ``confdata``; FANUC
  ``GP1`` X..R and ``CONFIG``; YASKAWA ``Cnnnnn`` X..Rz, whose ``///RCONF`` is shared by the
  points after it and is not changed).

Each returns False when the line does not hold the values where the format puts them (a
declaration split over lines); the caller then refuses rather than write a half-changed program.
Numbers are written with the decimals of the program writers (:mod:`robotcell.programs.kuka`, ...).
"""

from __future__ import annotations

import math
import re

import numpy as np
from numpy.typing import NDArray

from robotcell.export.common import DEG_DECIMALS, MM_DECIMALS, QUAT_DECIMALS
from robotcell.io.poseformats import pose_to_vendor
from robotcell.programs.config import config_text
from robotcell.programs.model import Config
from robotcell.programs.text import fmt_num
from robotcell.programs.yaskawa import DEG_PLACES, MM_PLACES

__all__ = ["JOINT_DECIMALS", "set_joints", "set_pose"]

#: Decimals of the joint values written (deg): 1e-9 deg.
JOINT_DECIMALS = 9
_NUM = r"[-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?\d+)?"


def _set_kuka_joints(lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
    line = lines[idx]
    for i in range(6):
        line, n = re.subn(rf"(\bA{i + 1}\s+){_NUM}", lambda m, v=q[i]: m.group(1)
                          + fmt_num(math.degrees(v), JOINT_DECIMALS), line, count=1,
                          flags=re.IGNORECASE)
        if n != 1:
            return False
    lines[idx] = line
    return True


def _set_abb_joints(lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
    line = lines[idx]
    m = re.search(r"\[\s*\[([^\[\]]*)\]", line)
    if not m or len(m.group(1).split(",")) != 6:
        return False
    values = ",".join(fmt_num(math.degrees(v), JOINT_DECIMALS) for v in q)
    lines[idx] = line[:m.start(1)] + values + line[m.end(1):]
    return True


def _gp1(lines: list[str], idx: int) -> range:
    """The lines of a FANUC position block's group 1, from its header line ``idx``."""
    end = idx
    for k in range(idx, len(lines)):
        if k > idx and re.match(r"^\s*GP[2-9]\s*:", lines[k]):
            break
        end = k
        if "};" in lines[k]:
            break
    return range(idx, end + 1)


def _set_fanuc_joints(lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
    done = 0
    for k in _gp1(lines, idx):
        for i in range(6):
            lines[k], n = re.subn(rf"(\bJ{i + 1}\s*=\s*){_NUM}",
                                  lambda m, v=q[i]: m.group(1)
                                  + fmt_num(math.degrees(v), JOINT_DECIMALS), lines[k], count=1)
            done += n
    return done == 6


_JOINTS = {"kuka": _set_kuka_joints, "abb": _set_abb_joints, "fanuc": _set_fanuc_joints}


def set_joints(vendor: str, lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
    """Write the six axis values ``q`` (rad) of the joint point on line ``idx`` (0-based).

    Parameters
    ----------
    vendor : {"kuka", "abb", "fanuc"}
    lines : list of str
        The file's lines, changed in place.
    idx : int
        The line of the point's values (FANUC: its ``P[n]{`` line).
    q : ndarray, shape (6,)

    Returns
    -------
    bool
        False when the values are not found there (nothing changed for KUKA and ABB).
    """
    setter = _JOINTS.get(vendor)
    return setter is not None and setter(lines, idx, q)


def _replace_fields(line: str, values: dict[str, str], pattern: str) -> tuple[str, int]:
    """Replace the number after each key of ``values`` (``pattern`` has {key} and {num})."""
    done = 0
    for key, text in values.items():
        line, n = re.subn(pattern.format(key=key, num=_NUM), lambda m, t=text: m.group(1) + t,
                          line, count=1, flags=re.IGNORECASE)
        done += n
    return line, done


def _set_kuka_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None
                   ) -> bool:
    v = pose_to_vendor(T, "kuka")
    values = {k: fmt_num(x, MM_DECIMALS if i < 3 else DEG_DECIMALS)
              for i, (k, x) in enumerate(zip("XYZABC", v))}
    line, done = _replace_fields(lines[idx], values, r"([{{,]\s*{key}\s+){num}")
    if done != 6:
        return False
    if config is not None:
        flags = {"S": str(config.values[0]), "T": str(config.values[1])}
        line, n = _replace_fields(line, flags, r"([{{,]\s*{key}\s+)(?:'B[01]+'|{num})")
        if n != 2:
            return False
    lines[idx] = line
    return True


def _set_abb_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None
                  ) -> bool:
    line = lines[idx]
    m = re.search(r"\[\s*\[([^\[\]]*)\]\s*,\s*\[([^\[\]]*)\]\s*,\s*\[([^\[\]]*)\]", line)
    if not m or len(m.group(1).split(",")) != 3 or len(m.group(2).split(",")) != 4:
        return False
    v = pose_to_vendor(T, "abb")
    parts = [(m.start(1), m.end(1), ",".join(fmt_num(x, MM_DECIMALS) for x in v[:3])),
             (m.start(2), m.end(2), ",".join(fmt_num(x, QUAT_DECIMALS) for x in v[3:]))]
    if config is not None:
        parts.append((m.start(3), m.end(3), ",".join(str(x) for x in config.values)))
    for start, end, text in reversed(parts):
        line = line[:start] + text + line[end:]
    lines[idx] = line
    return True


def _set_fanuc_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None
                    ) -> bool:
    v = pose_to_vendor(T, "fanuc")
    values = {k: fmt_num(x, MM_DECIMALS if i < 3 else DEG_DECIMALS)
              for i, (k, x) in enumerate(zip("XYZWPR", v))}
    done = 0
    for k in _gp1(lines, idx):
        line = lines[k]
        for key, text in values.items():
            line, n = re.subn(rf"(\b{key}\s*=\s*){_NUM}", lambda m, t=text: m.group(1) + t, line,
                              count=1)
            done += n
        if config is not None:
            line, n = re.subn(r"(CONFIG\s*:\s*)'[^']*'", lambda m: m.group(1) + config_text(config),
                              line, count=1)
            done += 10 * n
        lines[k] = line
    return done == (16 if config is not None else 6)


def _set_yaskawa_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None
                      ) -> bool:
    m = re.match(r"^(\s*C\d+\s*=\s*)([^,]*(?:,[^,]*){5})(.*)$", lines[idx])
    if not m:
        return False
    v = pose_to_vendor(T, "yaskawa")
    text = ",".join(fmt_num(x, MM_PLACES if i < 3 else DEG_PLACES) for i, x in enumerate(v))
    lines[idx] = m.group(1) + text + m.group(3)
    return True


_POSES = {"kuka": _set_kuka_pose, "abb": _set_abb_pose, "fanuc": _set_fanuc_pose,
          "yaskawa": _set_yaskawa_pose}


def set_pose(vendor: str, lines: list[str], idx: int, T: NDArray[np.float64],
             config: Config | None = None) -> bool:
    """Write the Cartesian values of the point on line ``idx`` (0-based), and its flags.

    Parameters
    ----------
    vendor : {"kuka", "abb", "fanuc", "yaskawa"}
    lines : list of str
        The file's lines, changed in place.
    idx : int
        The line of the point's values (FANUC: its ``P[n]{`` line).
    T : ndarray, shape (4, 4)
        The pose in the point's frame (m).
    config : Config, optional
        Flags to write (KUKA S and T, ABB confdata, FANUC CONFIG); YASKAWA's shared ``RCONF``
        is never written.

    Returns
    -------
    bool
        False when the values are not found there.
    """
    return _POSES[vendor](lines, idx, T, config)
