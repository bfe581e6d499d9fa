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

The parts add in quadrature to the total.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.uncertainty import OWN, Sources

__all__ = ["ASSUMED_SUFFIX", "PARTS", "pose_parts"]

#: The name ending of a source taken at an assumed (nominal) accuracy.
ASSUMED_SUFFIX = " nominal"

#: The parts of a 1-sigma, in the order they are reported, with what each is relative to.
PARTS = {"own": "its own touches, relative to what touched (the robot or parent)",
         "recorded": "inherited from calibrated items (recorded uncertainty)",
         "assumed": "inherited from items with no recorded uncertainty (ASSUMED accuracy)"}


def _part(name: str) -> str:
    if name == OWN:
        return "own"
    return "assumed" if name.endswith(ASSUMED_SUFFIX) else "recorded"


def pose_parts(sources: Sources) -> dict[str, dict[str, Any]]:
    """The 1-sigma of a pose's parameters split into :data:`PARTS`.

    Parameters
    ----------
    sources : Sources
        Error sources of the 6 pose parameters (origin in m, rotation vector in rad).

    Returns
    -------
    dict
        Per part present (``own``, ``recorded``, ``assumed``): ``position_mm`` (3,),
        ``rotation_deg`` (3,) and ``sources`` (the items, e.g. ``["track"]``; empty for own).
    """
    groups: dict[str, dict[str, NDArray[np.float64]]] = {}
    for name, f in sources.factors.items():
        groups.setdefault(_part(name), {})[name] = f
    out: dict[str, dict[str, Any]] = {}
    for part in PARTS:
        if part not in groups:
            continue
        sigma = Sources(sources.size, groups[part]).sigma[:6]
        items = [] if part == "own" else [n.removesuffix(ASSUMED_SUFFIX) for n in groups[part]]
        out[part] = {"position_mm": sigma[:3] * 1e3, "rotation_deg": np.degrees(sigma[3:6]),
                     "sources": items}
    return out
