"""What every calibration into a cell is told besides its measurements and its own options.

Who touched (``robot``, ``tool``) and how well (``sigma``), how its messages and its provenance
name things (``source``, ``cell_label``, ``time``), where its notes go (``on_note``), which touch
file it records (``file``) and how accurate the items without a recorded uncertainty are
(``nominal``): one :class:`CalibrationContext`, which each procedure's call takes as
``context=``, or field by field as keywords.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any

from numpy.typing import ArrayLike

from robotcell.cell import Cell
from robotcell.cell.calibrate.chain import NOMINAL_ACCURACY, NominalAccuracy
from robotcell.errors import InputError
from robotcell.robot.robot import Robot

__all__ = ["CalibrationContext"]


@dataclass(frozen=True)
class CalibrationContext:
    """The keywords every calibration into a cell shares.

    Attributes
    ----------
    robot : Robot, optional
        Robot model for joint values when no cell is given (a cell gives its own).
    tool : str or array_like of shape (4, 4), optional
        Tool that touched: a tool of the cell by name, or ``T_F_TCP`` (m); default the robot
        model's tool. Its uncertainty (recorded in the cell, else the nominal accuracy) and the
        track's, for touches mapped to the world, are part of the result's. The tcp procedure,
        whose touches are flange poses, takes none.
    sigma : float, optional
        Touch-up accuracy, 1-sigma per coordinate (m), which the uncertainties rest on; default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    source : str, optional
        Name of the measurements in messages and the provenance note.
    cell_label : str, optional
        Name of the cell in messages (e.g. its file); default ``cell 'NAME'``.
    time : str, optional
        ISO 8601 time of the provenance; default now.
    on_note : callable, optional
        Receives each note on the measurements as it arises (e.g. to print it on stderr).
    file : str or Path, optional
        The touch file a table was read from; it is recorded in the provenance with its
        checksum (``measurements`` given as a path is recorded without it).
    nominal : NominalAccuracy
        Accuracy of the cell items the touches rest on that have no recorded uncertainty.
    """

    robot: Robot | None = None
    tool: str | ArrayLike | None = None
    sigma: float | None = None
    source: str | None = None
    cell_label: str | None = None
    time: str | None = None
    on_note: Callable[[str], None] | None = None
    file: str | Path | None = None
    nominal: NominalAccuracy = NOMINAL_ACCURACY

    @classmethod
    def of(cls, context: CalibrationContext | None = None, **keywords: Any
           ) -> CalibrationContext:
        """``context`` (default: every field at its default) with the fields in ``keywords``.

        Raises
        ------
        TypeError
            A keyword that is no field, as for a call with an unknown keyword.
        """
        unknown = sorted(set(keywords) - {f.name for f in fields(cls)})
        if unknown:
            raise TypeError(f"unexpected keyword argument {unknown[0]!r} (a calibration takes "
                            f"{', '.join(f.name for f in fields(cls))} besides its own options)")
        base = cls() if context is None else context
        return replace(base, **keywords) if keywords else base

    def label(self, cell: Cell | None) -> str:
        """The cell as messages name it: :attr:`cell_label`, else ``cell 'NAME'``."""
        return self.cell_label or (f"cell {cell.name!r}" if cell is not None else "the cell")

    def arm(self, cell: Cell | None) -> Robot | None:
        """The robot that touched: the cell's, else :attr:`robot`.

        Raises
        ------
        InputError
            Both a cell and a robot are given.
        """
        if cell is not None and self.robot is not None:
            raise InputError("the robot is the cell's: give a cell or a robot, not both")
        return cell.robot if cell is not None else self.robot
