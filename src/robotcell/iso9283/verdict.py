"""The verdict of an ISO 9283 test: each figure that has a limit against it (:func:`judge`).

A figure passes when its largest value over the poses (AP_p, RP_l) or paths (AT_p, RT_p) is at
most its limit. The verdict is ``pass`` when every limit given is met, ``fail`` when one is not
(or its figure was not measured), ``none`` when no limit is given. The limit of RP defaults to
the pose repeatability the robot's datasheet states, where its model carries one with its
source (:func:`datasheet_limits`); the others have no default.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from robotcell.errors import InputError
from robotcell.kinematics.arm import Arm

__all__ = ["Limits", "Verdict", "datasheet_limits", "judge"]


@dataclass(frozen=True)
class Limits:
    """Largest acceptable figures (m); None: no limit.

    Attributes
    ----------
    AP, RP : float or None
        Pose accuracy ``AP_p`` and repeatability ``RP_l`` of every pose.
    AT, RT : float or None
        Path accuracy ``AT_p`` and repeatability ``RT_p`` of every path.
    """

    AP: float | None = None
    RP: float | None = None
    AT: float | None = None
    RT: float | None = None

    def __post_init__(self) -> None:
        for name in ("AP", "RP", "AT", "RT"):
            v = getattr(self, name)
            if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"limit_{name.lower()} must be a positive length (m), got {v!r}")

    def to_json(self) -> dict[str, float | None]:
        """The limits in mm (None where not given)."""
        return {f"{k}_mm": None if (v := getattr(self, k)) is None else v * 1e3
                for k in ("AP", "RP", "AT", "RT")}


@dataclass(frozen=True)
class Verdict:
    """``level`` (``pass``, ``fail`` or ``none``) and one reason per limit."""

    level: str
    reasons: list[str]

    def line(self) -> str:
        """The verdict as one line: ``verdict: PASS: AP_p 0.214 mm (P3) <= 0.5 mm; ...``."""
        return f"verdict: {self.level.upper()}: {'; '.join(self.reasons)}"

    def to_json(self) -> dict[str, Any]:
        return {"level": self.level, "reasons": list(self.reasons)}


def judge(figures: Mapping[str, Sequence[tuple[float, str]]], limits: Limits) -> Verdict:
    """The verdict on the figures.

    Parameters
    ----------
    figures : mapping of str to sequence of (float, str)
        ``"AP"``, ``"RP"``, ``"AT"``, ``"RT"`` -> (value in m, pose or path) of every pose or
        path measured.
    limits : Limits

    Returns
    -------
    Verdict
    """
    label = {"AP": "AP_p", "RP": "RP_l", "AT": "AT_p", "RT": "RT_p"}
    reasons, failed = [], False
    for key, name in label.items():
        values = figures.get(key, [])
        limit = getattr(limits, key)
        if limit is None:
            continue
        if not values:
            reasons.append(f"{name} not measured (limit {limit * 1e3:g} mm)")
            failed = True
            continue
        value, where = max(values)
        ok = value <= limit
        failed |= not ok
        reasons.append(f"{name} {value * 1e3:.3f} mm ({where}) "
                       f"{'<=' if ok else '>'} {limit * 1e3:g} mm")
    if not reasons:
        return Verdict("none", ["no limit given for AP_p, RP_l, AT_p or RT_p"])
    return Verdict("fail" if failed else "pass", reasons)


def datasheet_limits(limits: Limits, robot: Arm | None) -> tuple[Limits, str | None]:
    """The limits with RP from the robot's datasheet where none is given.

    Parameters
    ----------
    limits : Limits
    robot : Arm or None
        The arm tested; its ``repeatability`` (m) and ``repeatability_source``, when it has one.

    Returns
    -------
    limits : Limits
        ``limits``, its RP the datasheet's when it had none.
    note : str or None
        Where the RP limit came from, when it came from the datasheet.
    """
    if limits.RP is not None or robot is None or robot.repeatability is None:
        return limits, None
    rp = robot.repeatability
    note = (f"limit of RP_l {rp * 1e3:g} mm: the pose repeatability of the "
            f"{robot.title or robot.name} datasheet ({robot.repeatability_source})")
    return Limits(limits.AP, rp, limits.AT, limits.RT), note
