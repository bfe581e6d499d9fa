"""External axes in a program: the names and units under which a controller writes the cell's
track and turntable (or positioner) axes beside each point, both ways.

Each controller says which name is the track and which the table's axes, and in which unit
(its :meth:`~robotcell.controllers.base.Controller.external_axes`; the table of the four is in
``docs/programs.md``). :class:`ExternalAxes` converts between the cell's values (m, rad) and the
file's; :func:`numbered_axes` serves a controller that numbers its external axes in one row,
the track first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell, Positioner
from robotcell.errors import InputError

__all__ = ["DEG", "ExternalAxes", "numbered_axes", "table_count"]

#: Degrees per radian: the file unit of a table axis written in degrees.
DEG = 180.0 / math.pi


@dataclass(frozen=True)
class ExternalAxes:
    """The names and units of a cell's external axes in one program format.

    Attributes
    ----------
    vendor : str
        The controller's name.
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
    whole_units : bool
        The file holds the table's values in whole file units (YASKAWA station axes in encoder
        pulses), so a value is rounded to one before the point is solved.
    decimals : int or None
        The file holds the table's values to this many decimals of its unit (FANUC: 3), so a
        value is rounded to them before the point is solved.
    table_optional : bool
        A program may leave the table's axes out (a YASKAWA job that moves the robot's group
        alone): the table is then taken at 0, not named as missing.
    unit_needed : str or None
        Why the table's values cannot be converted (a unit the call must give, YASKAWA's
        pulses per degree): raised as soon as a table value is converted.
    """

    vendor: str
    track: str | None
    table: tuple[str, ...]
    track_scale: float
    table_scale: tuple[float, ...]
    positioner: bool = False
    unused: tuple[str, ...] = ()
    whole_units: bool = False
    decimals: int | None = None
    table_optional: bool = False
    unit_needed: str | None = None

    def _convertible(self) -> None:
        """Raise :attr:`unit_needed` when the table's values cannot be converted."""
        if self.table and self.unit_needed:
            raise InputError(self.unit_needed)

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

        Raises
        ------
        InputError
            The table's values cannot be converted (:attr:`unit_needed`).
        """
        self._convertible()
        out: dict[str, float] = {}
        if self.track:
            out[self.track] = float(track) * self.track_scale
        th = np.atleast_1d(np.asarray(table, dtype=float))
        for name, scale, v in zip(self.table, self.table_scale, th):
            out[name] = float(v) * scale
        return out

    def held(self, table: ArrayLike) -> NDArray[np.float64]:
        """Table values as the file holds them: rounded to whole file units where
        :attr:`whole_units` (YASKAWA encoder pulses), to :attr:`decimals` (FANUC degrees), else
        unchanged (degrees, written with 9 decimals).

        Parameters
        ----------
        table : array_like, shape (N,) or (N, n)
            Turntable angles or positioner axis values (rad).

        Returns
        -------
        ndarray
            The same shape (rad).

        Raises
        ------
        InputError
            The table's values cannot be converted (:attr:`unit_needed`).
        """
        th = np.asarray(table, dtype=float)
        self._convertible()
        if not self.table or (not self.whole_units and self.decimals is None):
            return th
        scale = np.asarray(self.table_scale) if self.positioner else self.table_scale[0]
        return np.round(th * scale, 0 if self.whole_units else self.decimals) / scale

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
            Axes of the cell the point does not write (the table's axes not, where
            :attr:`table_optional` and the point writes none of them), and nonzero values of
            axes the cell lacks.

        Raises
        ------
        InputError
            A table value that cannot be converted (:attr:`unit_needed`).
        """
        problems = []
        track = 0.0
        if self.track:
            if self.track in external:
                track = external[self.track] / self.track_scale
            else:
                problems.append(f"{self.track} (the track) is not written")
        values = []
        written = not external.keys().isdisjoint(self.table)
        if written:
            self._convertible()
        for name, scale in zip(self.table, self.table_scale):
            if name in external:
                values.append(external[name] / scale)
            else:
                values.append(0.0)
                if written or not self.table_optional:
                    problems.append(f"{name} (the table) is not written")
        known = self.names()
        for name, v in external.items():
            if name not in known and v != 0 and abs(v) < 9e8:  # ABB: 9E9 = no axis
                problems.append(f"{name} = {v:g}, but the cell has no such external axis")
        table = np.array(values) if self.positioner else (values[0] if values else 0.0)
        return track, table, problems


    def from_files(self, externals: list[dict[str, float]]
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64], list[list[str]]]:
        """:meth:`from_file` of many points: the points of a program write the same axes, and
        are converted in one batch.

        Parameters
        ----------
        externals : list of dict of str to float
            Each point's external axes, as a reader returns them (file units).

        Returns
        -------
        track : ndarray, shape (N,)
        table : ndarray, shape (N,) or (N, n)
        problems : list of list of str
            Each point's, as :meth:`from_file` gives them.

        Raises
        ------
        InputError
            A table value that cannot be converted (:attr:`unit_needed`).
        """
        n = len(externals)
        keys = externals[0].keys() if n else {}.keys()
        if any(e.keys() != keys for e in externals):
            rows = [self.from_file(e) for e in externals]
            return (np.array([r[0] for r in rows], dtype=float),
                    np.array([r[1] for r in rows], dtype=float), [r[2] for r in rows])
        names = list(keys)
        values = np.array([[e[k] for k in names] for e in externals], dtype=float).reshape(
            n, len(names))
        col = dict(zip(names, values.T))
        common = {k: 0.0 for k in names}
        _, _, missing = self.from_file(common)  # what no point writes
        track = col[self.track] / self.track_scale if self.track in col else np.zeros(n)
        table = np.column_stack([col[k] / sc if k in col else np.zeros(n)
                                 for k, sc in zip(self.table, self.table_scale)]) \
            if self.table else np.zeros((n, 0))
        problems = [list(missing) for _ in range(n)]
        known = self.names()
        for k in names:
            if k in known:
                continue
            v = col[k]
            for i in np.flatnonzero((v != 0) & (np.abs(v) < 9e8)):
                problems[i].append(f"{k} = {v[i]:g}, but the cell has no such external axis")
        if not self.positioner:
            table = table[:, 0] if self.table else np.zeros(n)
        return track, table, problems

def table_count(cell: Cell) -> tuple[int, bool]:
    """Number of table axes of ``cell`` and whether they are a positioner chain."""
    tt = cell.turntable
    if tt is None:
        return 0, False
    return (tt.n_axes, True) if isinstance(tt, Positioner) else (1, False)


def numbered_axes(cell: Cell, vendor: str, names: tuple[str, ...]) -> ExternalAxes:
    """External axes written under one row of names: the track (mm) first, then the table's
    axes (deg), the rest unused.

    Parameters
    ----------
    cell : Cell
    vendor : str
        The controller's name.
    names : tuple of str
        Every external axis name of the format, in order (KUKA ``E1..E6``).

    Returns
    -------
    ExternalAxes

    Raises
    ------
    InputError
        The cell has more external axes than ``names``.
    """
    n, chain = table_count(cell)
    k = int(cell.track is not None)
    if k + n > len(names):
        raise InputError(f"{vendor} programs hold {len(names)} external axes; the cell has "
                         f"{k + n}")
    return ExternalAxes(vendor, names[0] if k else None, tuple(names[k:k + n]), 1e3, (DEG,) * n,
                        chain, tuple(names[k + n:]))
