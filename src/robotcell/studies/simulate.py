"""Simulated touch-up measurements of a virtual cell, for rehearsing a calibration procedure.

:func:`simulate` places the touches of a procedure in a virtual cell (the truth) with a
touch-up error, through the procedure's own placement (its ``simulate`` in
:mod:`robotcell.cell.calibrate.procedures`, on :mod:`robotcell.cell.calibrate.simulation`),
and returns them as :class:`Touches`, which write the measurement CSV that
``robotcell calibrate PROCEDURE`` reads (see ``docs/simulate.md``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robotcell.cell import Cell
from robotcell.cell.calibrate.registry import having
from robotcell.cell.calibrate.simulation import MAX_TOUCHES, Touches
from robotcell.errors import InputError

__all__ = ["MAX_TOUCHES", "PROCEDURES", "Touches", "check_counts", "simulate"]

#: Procedures that can be simulated (those of the registry with a ``simulate``), with what they
#: calibrate.
PROCEDURES = having(lambda p: p.summary if p.simulate is not None else None)


def _rng(seed: int | np.random.Generator | None) -> np.random.Generator:
    if isinstance(seed, np.random.Generator):
        return seed
    if seed is not None and not (isinstance(seed, (int, np.integer)) and seed >= 0):
        raise InputError(f"seed must be a whole number >= 0, got {seed}")
    return np.random.default_rng(seed)


def check_counts(design: dict[str, Any]) -> None:
    """Refuse ``touches``, ``positions`` or ``repeats`` above :data:`MAX_TOUCHES` up front.

    Raises
    ------
    InputError
        A count that would place more touches than a simulation places.
    """
    for key in ("touches", "positions", "repeats"):
        if isinstance(design.get(key), (int, np.integer)) and design[key] > MAX_TOUCHES:
            raise InputError(f"{key} {design[key]}: a simulation places at most {MAX_TOUCHES} "
                             "touches")


def _check_noise(noise: float) -> float:
    if not (math.isfinite(noise) and noise >= 0):
        raise InputError(f"noise must be a finite number >= 0 (m), got {noise}")
    return float(noise)


_SIMULATORS = having(lambda p: p.simulate)


def simulate(cell: Cell, procedure: str, *, noise: float = 1e-4,
             seed: int | np.random.Generator | None = None, tool: str | None = None,
             track: float | None = None, **design: Any) -> Touches:
    """Simulate the touches of a calibration procedure in a virtual cell.

    Parameters
    ----------
    cell : Cell
        The virtual cell: its values are the truth the touches are made in.
    procedure : str
        A procedure of :data:`PROCEDURES`: ``"tcp"``, ``"frame"``, ``"track"``,
        ``"turntable"``, ``"workpiece"``, ``"positioner"``, or one registered
        (:func:`robotcell.cell.calibrate.register`).
    noise : float
        Touch-up error, 1-sigma per coordinate (m); 0 for exact touches.
    seed : int or numpy.random.Generator, optional
        Seed of the touch-up errors.
    tool : str, optional
        Tool of the cell that touches (for ``tcp``: the tool being calibrated); needed when the
        cell has more than one.
    track : float, optional
        Track position of the robot (m) for procedures other than ``track``; default: chosen.
    **design
        The touch design, per procedure (lengths in m, angles in rad):

        - ``tcp``: ``touches`` (4), ``tilt`` (30 deg, of the tool from its mean orientation),
          ``point`` (reference tip in the robot base, (1.1, 0, 0.25)), ``orientation`` (True:
          ABC 2-point touches too), ``distance`` (0.1, of the reference point from the TCP in
          the ABC 2-point touches);
        - ``frame``: ``frame`` (name), ``size`` (0.2, distance of the +X and XY points from the
          origin), ``repeats`` (2 touches per point);
        - ``track``: ``references`` ((K, 3) in L; default two points, one on each side, a
          quarter of the travel from each end), ``positions`` (4 per point), ``travel`` (1.0,
          spread of the track positions per point);
        - ``turntable``: ``touches`` (6), ``angles`` (default evenly around the turn),
          ``radius`` (0.3) and ``height`` (0.05) of the touched point on ``X_B``;
        - ``workpiece``: ``frame`` (name), ``size`` (0.15), ``repeats`` (2), ``angles``;
        - ``positioner`` (2 axes): every combination of ``tilts`` (default -30, 0, 30 deg,
          clipped to the limits) and ``rotates`` (default 0, 90, 180, 270 deg, clipped) of the
          point ``(radius, 0, height)`` (0.2, 0.0) in the plate frame P; ``table`` holds the
          axis values, shape (N, 2).

    Returns
    -------
    Touches

    Raises
    ------
    InputError
        Unknown procedure, tool, frame or design option; a cell without the track or turntable
        the procedure needs; touches that no configuration reaches within the limits.
    """
    if procedure not in _SIMULATORS:
        raise InputError(f"unknown procedure {procedure!r}; choose from {', '.join(PROCEDURES)}")
    noise = _check_noise(noise)
    check_counts(design)
    try:
        return _SIMULATORS[procedure](cell, _rng(seed), noise, tool, track, **design)
    except TypeError as exc:
        if "unexpected keyword" not in str(exc):
            raise
        raise InputError(f"{procedure}: {str(exc).split(') ', 1)[-1]}") from None
