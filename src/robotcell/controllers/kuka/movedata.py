"""The path speed and the approximation distance of KRL motions, in program order.

A KUKA program sets ``$VEL.CP`` (m/s) and ``$APO.CDIS`` (mm) directly, or through the calls its
inline forms write, which KSS's ``bas.src`` (R1/System, in every controller backup) defines:

- ``BAS(#VEL_CP, v)`` sets ``$VEL.CP`` to v; ``BAS(#CP_DAT)`` sets ``$VEL.CP`` to
  ``LDAT_ACT.VEL`` and ``$APO.CDIS`` to ``LDAT_ACT.APO_DIST``; ``BAS(#CP_PARAMS, v)`` sets
  ``$APO.CDIS`` to ``LDAT_ACT.APO_DIST`` and ``$VEL.CP`` to v (KSS 8);
- ``BAS(#PTP_DAT)`` and ``BAS(#PTP_PARAMS, v)`` set ``$APO.CDIS`` to ``PDAT_ACT.APO_DIST`` when
  ``PDAT_ACT.APO_MODE`` is ``#CDIS`` (otherwise ``$APO.CPTP``, a percentage, not a distance);
- in a spline motion's ``WITH`` clause, ``$VEL = SVEL_CP(v, , LCPDAT1)`` moves at v m/s,
  ``$APO = SAPO(LCPDAT1)`` approximates at ``LCPDAT1.APO_DIST`` and ``$APO =
  SAPO_PTP(PDAT1)`` at ``PDAT1.APO_DIST`` unless its ``APO_MODE`` is ``#CPTP`` (then a
  percentage of the axis angles: no distance).

A value the program computes (a variable, an expression) is one of run time: not known.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from robotcell.controllers.model import Ref
from robotcell.controllers.text import Lines, split

__all__ = ["DISTANCE_APPROX", "MoveData", "Settings", "zone"]

#: A number as KRL writes one (``2``, ``0.55``, ``-1.5E-3``); anything else is of run time.
_NUMBER_RE = re.compile(r"^[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")
#: The approximation keywords that round a motion's corner at ``$APO.CDIS``.
DISTANCE_APPROX = ("C_DIS", "C_SPL")


@dataclass
class Settings:
    """What one motion moves with.

    Attributes
    ----------
    tool, base : Ref or str
        The tool and base, or why they are not known (words).
    external : str or None
        Why its Cartesian point is not checked under an external TCP, or None.
    speed : float or None
        ``$VEL.CP`` (m/s), None where the program does not give it as a number.
    cdis : float or None
        ``$APO.CDIS`` (m), None likewise.
    """

    tool: Ref | str
    base: Ref | str
    external: str | None
    speed: float | None
    cdis: float | None


class MoveData:
    """``$VEL.CP``, ``$APO.CDIS``, ``LDAT_ACT`` and ``PDAT_ACT`` as the program sets them.

    Parameters
    ----------
    lines : Lines
        The ``.src``, for the messages of numbers that are none.
    data : dict of str to dict of str to str
        The LDATs and PDATs of the ``.dat`` by name (upper case): their fields.
    """

    def __init__(self, lines: Lines, data: dict[str, dict[str, str]]) -> None:
        self.lines, self.data = lines, data
        self.speed: float | None = None
        self.cdis: float | None = None
        self.ldat: dict[str, str] = {}
        self.pdat: dict[str, str] = {}

    def number(self, text: str | None, lineno: int, scale: float = 1.0) -> float | None:
        """``text`` as a number times ``scale``, None if it is no literal number."""
        if text is None or not _NUMBER_RE.match(text.strip()):
            return None
        return self.lines.number(text, lineno) * scale

    def act(self, which: str, name: str) -> None:
        """``LDAT_ACT=name`` or ``PDAT_ACT=name`` (a name the ``.dat`` does not hold: unknown)."""
        fields = self.data.get(name.upper(), {})
        if which.upper() == "LDAT_ACT":
            self.ldat = fields
        else:
            self.pdat = fields

    def ptp_cdis(self, lineno: int) -> float | None:
        """``$APO.CDIS`` (m) after ``BAS(#PTP_DAT)``: ``PDAT_ACT.APO_DIST`` under ``APO_MODE
        #CDIS``, else as it was (the call then sets ``$APO.CPTP``)."""
        if self.pdat.get("APO_MODE", "").strip().upper() != "#CDIS":
            return self.cdis
        return self.number(self.pdat.get("APO_DIST"), lineno, 1e-3)

    def bas(self, command: str, arg: str, lineno: int) -> None:
        """``BAS(#command, arg)``: the speed and approximation distance it sets, if any."""
        if command == "VEL_CP":
            self.speed = self.number(arg, lineno)
        elif command in ("CP_DAT", "CP_PARAMS"):
            self.cdis = self.number(self.ldat.get("APO_DIST"), lineno, 1e-3)
            self.speed = self.number(arg if command == "CP_PARAMS" else self.ldat.get("VEL"),
                                     lineno)
        elif command in ("PTP_DAT", "PTP_PARAMS"):
            self.cdis = self.ptp_cdis(lineno)

    def with_item(self, key: str, value: str, settings: Settings, lineno: int) -> None:
        """Apply ``key = value`` of a ``WITH`` clause to ``settings`` if it sets the speed or
        the approximation distance (``$VEL_AXIS[1] = ..``, ``$LOAD = ..``: left as they are)."""
        call = re.match(r"^(\w+)\s*\((.*)\)$", value)
        fn, args = (call.group(1).upper(), split(call.group(2))) if call else ("", [])
        if key == "$VEL.CP":
            settings.speed = self.number(value, lineno)
        elif key == "$VEL":
            settings.speed = self.number(args[0], lineno) if fn == "SVEL_CP" else None
        elif key == "$APO.CDIS":
            settings.cdis = self.number(value, lineno, 1e-3)
        elif key == "$APO" and fn in ("SAPO", "SAPO_PTP"):
            fields = self.data.get(args[0].upper(), {})
            cptp = fn == "SAPO_PTP" and fields.get("APO_MODE", "").strip().upper() == "#CPTP"
            settings.cdis = None if cptp else self.number(fields.get("APO_DIST"), lineno, 1e-3)
        elif key == "$APO":
            settings.cdis = None


def zone(approx: str | None, cdis: float | None) -> float | None:
    """The corner distance (m) of a motion: 0 for an exact stop (no approximation keyword),
    ``$APO.CDIS`` for ``C_DIS`` and ``C_SPL``, None for ``C_PTP``, ``C_ORI``, ``C_VEL`` (a
    percentage or an angle, not a distance)."""
    if approx is None:
        return 0.0
    return cdis if approx.upper() in DISTANCE_APPROX else None
