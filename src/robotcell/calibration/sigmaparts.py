"""What a reported 1-sigma is made of: its own touches, recorded inputs and assumed inputs.

The 1-sigma of a calibrated pose ``T_a_b`` is relative to frame ``a`` and sums independent error
sources (:class:`~robotcell.calibration.uncertainty.Sources`). They fall in three parts:

``own``
    The touch noise of this calibration (:data:`~robotcell.calibration.uncertainty.OWN`): what
    its touches determine, relative to the robot (or the parent) they were taken from.
``recorded``
    Inherited from earlier calibrations whose uncertainty the cell records (a calibrated tool,
    track or turntable).
``assumed``
    Inherited from items with no recorded uncertainty, taken at an assumed nominal accuracy
    (sources named ``"ITEM nominal"``, see :mod:`robotcell.cell.calibrate.chain`): a figure
    nobody measured, which must not read as a measured one.

The parts add in quadrature to the total. A scalar or vector result (a track's scale, a
turntable's radius, axis and tilt) splits the same way (:func:`value_parts`).

Every printed 1-sigma names what it is relative to and what it holds, in the words of
:func:`sigma_basis`; the JSON gives the frame as ``sigma_relative_to``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.uncertainty import OWN, Sources

__all__ = ["ASSUMED_SUFFIX", "DECIMALS", "FRAMES", "PARTS", "frame_text", "numbers", "part_lines",
           "pose_parts", "sigma_basis", "value_parts"]

#: The name ending of a source taken at an assumed (nominal) accuracy.
ASSUMED_SUFFIX = " nominal"

#: The parts of a 1-sigma, in the order they are reported, with what each is relative to.
PARTS = {"own": "its own touches, relative to what touched (the robot or parent)",
         "recorded": "inherited from calibrated items (recorded uncertainty)",
         "assumed": "inherited from items with no recorded uncertainty (ASSUMED accuracy)"}


#: What a 1-sigma can be relative to: the frame ``a`` of a pose ``T_a_b`` (or the frame a value
#: is expressed in), in words. Any other frame is ``frame 'NAME'``.
FRAMES = {"F": "the flange", "R": "the robot base", "world": "frame 'world'",
          "L": "the track frame L", "B": "the turntable frame B",
          "P": "the positioner's plate P", "device": "the measuring device's frame"}

#: How each inherited part is named in :func:`sigma_basis`.
_INHERITED = {"recorded": "recorded", "assumed": "ASSUMED"}


#: Decimals of a printed 1-sigma by unit.
DECIMALS = {"mm": 3, "deg": 4, "": 6}


def numbers(values: Any, decimals: int) -> str:
    """Comma-separated fixed-decimal numbers, without a minus sign on values that round to zero
    (None, a JSON null, prints as nan)."""
    a = np.atleast_1d(np.asarray(values, dtype=object))
    arr = np.round(np.where(np.equal(a, None), np.nan, a).astype(float), decimals) + 0.0
    return ", ".join(f"{c:.{decimals}f}" for c in arr)


def frame_text(frame: str) -> str:
    """A frame in words: ``"F"`` -> ``"the flange"``, ``"world"`` -> ``"frame 'world'"``."""
    return FRAMES.get(frame, f"frame {frame!r}")


def sigma_basis(relative_to: str, parts: Iterable[str] = ("own",),
                own: str = "its own touches") -> str:
    """What a 1-sigma is relative to and made of, as every report, JSON and page says it.

    Parameters
    ----------
    relative_to : str
        The frame it is relative to (a key of :data:`FRAMES` or a frame's name).
    parts : iterable of str
        The parts it holds (:data:`PARTS`); ``"own"`` alone, the default, when only the
        result's own measurements determine it. An unknown split is given as ``()``.
    own : str
        What determines its own part (``"its own touches"``, ``"the arm's identification"``).

    Returns
    -------
    str
        E.g. ``"relative to the flange, from its own touches only"`` or ``"relative to frame
        'world', from its own touches and inherited errors (recorded, ASSUMED)"``.
    """
    where = f"relative to {frame_text(relative_to)}"
    parts = list(parts)
    inherited = [_INHERITED[p] for p in _INHERITED if p in parts]
    if not parts:
        return f"{where}, from {own} and the errors it inherits"
    if not inherited:
        return f"{where}, from {own} only"
    return f"{where}, from {own} and inherited errors ({', '.join(inherited)})"


def _part(name: str) -> str:
    if name == OWN:
        return "own"
    return "assumed" if name.endswith(ASSUMED_SUFFIX) else "recorded"


def pose_parts(sources: Sources) -> dict[str, dict[str, Any]]:
    """The 1-sigma of a pose's parameters split into :data:`PARTS`.

    Parameters
    ----------
    sources : Sources
        Error sources of the pose parameters: origin in m, rotation vector in rad (the first 6;
        a track's scale after them is left out).

    Returns
    -------
    dict
        Per part present (``own``, ``recorded``, ``assumed``): ``position_mm`` (3,),
        ``rotation_deg`` (3,) and ``sources`` (the items, e.g. ``["track"]``; empty for own).
    """
    return {part: {"position_mm": p["sigma"][:3] * 1e3, "rotation_deg": np.degrees(p["sigma"][3:6]),
                   "sources": p["sources"]}
            for part, p in value_parts(sources.select(np.arange(6))).items()}


def value_parts(sources: Sources) -> dict[str, dict[str, Any]]:
    """The 1-sigma of a value (a scalar or vector, SI) split into :data:`PARTS`.

    Parameters
    ----------
    sources : Sources
        Error sources of the value's k elements (SI: m, rad or unitless).

    Returns
    -------
    dict
        Per part present (``own``, ``recorded``, ``assumed``): ``sigma`` (k,), SI, and
        ``sources`` (the items; empty for own).
    """
    groups: dict[str, dict[str, NDArray[np.float64]]] = {}
    for name, f in sources.factors.items():
        groups.setdefault(_part(name), {})[name] = f
    return {part: {"sigma": Sources(sources.size, groups[part]).sigma,
                   "sources": [] if part == "own" else
                   [n.removesuffix(ASSUMED_SUFFIX) for n in groups[part]]}
            for part in PARTS if part in groups}


def part_lines(parts: Mapping[str, Any]) -> list[str]:
    """The parts of one quantity's 1-sigma as text, as the terminal and the HTML page print them.

    Parameters
    ----------
    parts : mapping
        The quantity's entry of a result's JSON ``sigma_parts``: per part ``position_mm`` and
        ``rotation_deg`` (a pose) or ``sigma`` in ``unit`` (a value), and ``sources``.

    Returns
    -------
    list of str
        A heading (``its parts (mm, adding in quadrature):``), then one line per part present,
        e.g. ``"inherited from items with no recorded uncertainty (ASSUMED accuracy) [track]:
        14.559, 2.837, 14.030 / 0.5008, 0.5007, 0.5013"``.
    """
    present = [p for p in parts.values() if isinstance(p, Mapping)]
    pose = any("rotation_deg" in p for p in present)
    unit = str(parts.get("unit", ""))
    what = (("position mm / " if any("position_mm" in p for p in present) else "")
            + "rotation deg" if pose else unit or "unitless")
    lines = [f"its parts ({what}, adding in quadrature):"]
    for part, what in PARTS.items():
        p = parts.get(part)
        if not isinstance(p, Mapping):
            continue
        names = f" [{', '.join(str(n) for n in p['sources'])}]" if p.get("sources") else ""
        if pose:
            text = ((numbers(p["position_mm"], 3) + " / " if "position_mm" in p else "")
                    + numbers(p.get("rotation_deg"), 4))
        else:
            text = numbers(p.get("sigma"), DECIMALS.get(unit, 6))
        lines.append(f"{what}{names}: {text}")
    return lines
