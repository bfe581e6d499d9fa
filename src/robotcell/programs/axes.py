"""How each program format holds the cell's external axes: the track and the turntable.

A program writes the external axes beside each point under the names of its format; this module
says which name is the cell's track and which the turntable's (or a positioner's) axes, and in
which unit, both ways. Sources: ``docs/programs.md``.

| format | track | turntable / positioner axes |
|---|---|---|
| KUKA | ``E1`` (mm) | the next ``E`` axes (deg): ``E2..`` beside a track, else ``E1..`` |
| ABB | ``eax_a`` (mm) | the next logical axes (deg): ``eax_b..`` beside a track, else ``eax_a..`` |
| FANUC | ``E1`` of group 1 (mm, an integrated rail) | ``J1..`` of group 2 (deg) |
| YASKAWA | base axis ``BC1`` (mm) | station axes ``EC1..`` (encoder pulses) |

KUKA numbers the external axes of the linear unit first (``$ET1_AX={TR_A1 #E1}``) and the
turntable's kinematic after it (``docs/export.md``); ABB maps mechanical units to logical axes
``a..f`` in the system parameters, and robotcell assumes the track on ``a`` and the turntable
after it. YASKAWA jobs hold station axes in pulses only (DX100 manual, "Configuration of Position
Data": "The position of a station axis is represented by a pulse number"), so they need the
station's pulses per degree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell, Positioner
from robotcell.errors import InputError

__all__ = ["ExternalAxes", "external_axes"]

_ABB = ("eax_a", "eax_b", "eax_c", "eax_d", "eax_e", "eax_f")
_DEG = 180.0 / math.pi


@dataclass(frozen=True)
class ExternalAxes:
    """The names and units of a cell's external axes in one program format.

    Attributes
    ----------
    vendor : str
    track : str or None
        Name of the track axis (None: the cell has no track).
    table : tuple of str
        Names of the turntable's axis, or of a positioner's axes (empty: none).
    track_scale : float
        File units per metre of the track value (1000: mm).
    table_scale : tuple of float
        File units per radian of each table axis (degrees, or encoder pulses).
    positioner : bool
        The table axes are a positioner chain (values of shape ``(n,)``), not a turntable.
    unused : tuple of str
        Further names of the format's external axes, written as 0 (KUKA ``E6POS`` holds
        ``E1..E6``) or as ABB's 9E9 (``eax_a..eax_f``).
    """

    vendor: str
    track: str | None
    table: tuple[str, ...]
    track_scale: float
    table_scale: tuple[float, ...]
    positioner: bool = False
    unused: tuple[str, ...] = ()

    def names(self) -> list[str]:
        """Track and table names, in that order."""
        return ([self.track] if self.track else []) + list(self.table)

    def to_file(self, track: float, table: ArrayLike) -> dict[str, float]:
        """External axis values for the file from the cell's track (m) and table (rad).

        Parameters
        ----------
        track : float
            Track value (m; ignored without a track).
        table : array_like, shape () or (n,)
            Turntable angle or positioner axis values (rad; ignored without one).

        Returns
        -------
        dict of str to float
            Values in file units, track first.
        """
        out: dict[str, float] = {}
        if self.track:
            out[self.track] = float(track) * self.track_scale
        th = np.atleast_1d(np.asarray(table, dtype=float))
        for name, scale, v in zip(self.table, self.table_scale, th):
            out[name] = float(v) * scale
        return out

    def held(self, table: ArrayLike) -> NDArray[np.float64]:
        """Table values as the file holds them: YASKAWA station axes in whole encoder pulses,
        the other formats' degrees unchanged (they write 9 decimals).

        Parameters
        ----------
        table : array_like, shape (N,) or (N, n)
            Turntable angles or positioner axis values (rad).

        Returns
        -------
        ndarray
            The same shape (rad).
        """
        th = np.asarray(table, dtype=float)
        if self.vendor != "yaskawa" or not self.table:
            return th
        scale = np.asarray(self.table_scale) if self.positioner else self.table_scale[0]
        return np.round(th * scale) / scale

    def from_file(self, external: dict[str, float]
                  ) -> tuple[float, NDArray[np.float64] | float, list[str]]:
        """The cell's track (m) and table (rad) from a point's external axes.

        Parameters
        ----------
        external : dict of str to float
            As a reader returns them (file units).

        Returns
        -------
        track : float
            0 where the cell has no track or the value is missing.
        table : float or ndarray, shape (n,)
            A turntable angle, or a positioner's axis values (0 where missing).
        problems : list of str
            Axes of the cell the point does not write, and nonzero values of axes the cell
            lacks.
        """
        problems = []
        track = 0.0
        if self.track:
            if self.track in external:
                track = external[self.track] / self.track_scale
            else:
                problems.append(f"{self.track} (the track) is not written")
        values = []
        for name, scale in zip(self.table, self.table_scale):
            if name in external:
                values.append(external[name] / scale)
            else:
                values.append(0.0)
                problems.append(f"{name} (the table) is not written")
        for name, v in external.items():
            if name not in self.names() and v != 0 and abs(v) < 9e8:  # ABB: 9E9 = no axis
                problems.append(f"{name} = {v:g}, but the cell has no such external axis")
        table = np.array(values) if self.positioner else (values[0] if values else 0.0)
        return track, table, problems


def _table_count(cell: Cell) -> tuple[int, bool]:
    """Number of table axes and whether they are a positioner chain."""
    tt = cell.turntable
    if tt is None:
        return 0, False
    return (tt.n_axes, True) if isinstance(tt, Positioner) else (1, False)


def external_axes(cell: Cell, vendor: str, pulses_per_degree: ArrayLike | None = None
                  ) -> ExternalAxes:
    """The names and units of ``cell``'s external axes in format ``vendor``.

    Parameters
    ----------
    cell : Cell
    vendor : {"kuka", "abb", "fanuc", "yaskawa"}
    pulses_per_degree : float or array_like of float, optional
        YASKAWA only: encoder pulses per degree of each station axis (one value for all). Needed
        when the cell has a turntable or positioner.

    Returns
    -------
    ExternalAxes

    Raises
    ------
    InputError
        A YASKAWA program for a cell with a turntable and no ``pulses_per_degree``, or more
        external axes than the format holds.
    """
    n, chain = _table_count(cell)
    has_track = cell.track is not None
    deg = (_DEG,) * n
    if vendor == "kuka":
        names = [f"E{i + 1}" for i in range(6)]
    elif vendor == "abb":
        names = list(_ABB)
    elif vendor == "fanuc":
        return ExternalAxes(vendor, "E1" if has_track else None,
                            tuple(f"GP2:J{i + 1}" for i in range(n)), 1e3, deg, chain)
    elif vendor == "yaskawa":
        if n and pulses_per_degree is None:
            raise InputError("YASKAWA jobs hold station axes in encoder pulses: give "
                             "pulses_per_degree, the pulses per degree of the turntable's axis "
                             "(from the station's parameters)")
        ppd = np.broadcast_to(np.asarray(pulses_per_degree if n else 1.0, dtype=float), (n,))
        if n and not np.all(np.isfinite(ppd) & (ppd > 0)):
            raise InputError(f"pulses_per_degree must be positive numbers, got "
                             f"{pulses_per_degree!r}")
        return ExternalAxes(vendor, "BC1" if has_track else None,
                            tuple(f"EC{i + 1}" for i in range(n)), 1e3,
                            tuple(float(p) * _DEG for p in ppd), chain)
    else:
        raise InputError(f"unknown program format {vendor!r}")
    k = int(has_track)
    if k + n > len(names):
        raise InputError(f"{vendor} programs hold {len(names)} external axes; the cell has "
                         f"{k + n}")
    return ExternalAxes(vendor, names[0] if has_track else None, tuple(names[k:k + n]), 1e3, deg,
                        chain, tuple(names[k + n:]))
