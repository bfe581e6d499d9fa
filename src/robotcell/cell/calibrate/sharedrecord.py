"""The record of a shared-positioner fit in a cell file, read without the fit's machinery.

:func:`robotcell.cell.calibrate.sharedpositioner.place_shared_positioner` writes the joint fit of
a positioner two robots calibrated into the cell with a provenance that records its four touch
files; :class:`RecordedShared` reads that record back, so that ``calibrate cell``
(:mod:`robotcell.cell.calibrate.wholerobots`) knows what to repeat without loading the
identification engine unless there is a fit to repeat (docs/calibration.md, "One positioner, two
robots").
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from robotcell.cell.calibrate.common import touch_file_problem
from robotcell.cell.calibrate.robottorobot import RobotTouchFile
from robotcell.cell.model import Cell
from robotcell.cell.parts import Provenance

__all__ = ["FILES", "SOURCE", "RecordedShared"]

#: The provenance source of the items :func:`~robotcell.cell.calibrate.sharedpositioner.place_shared_positioner` writes.
SOURCE = "shared-positioner"
#: The touch files a shared-positioner provenance records, by the key of its options.
FILES = ("reference_plate", "other_plate", "reference_common", "other_common")


@dataclass(frozen=True)
class RecordedShared:
    """A fit of a shared positioner as a cell records it
    (:func:`~robotcell.cell.calibrate.sharedpositioner.place_shared_positioner`), ready to be
    repeated.

    Attributes
    ----------
    common : (RobotTouchFile, RobotTouchFile)
        The reference robot's and the other robot's touches of the common points.
    plate : (str, str)
        Each robot's touch file of its point on the plate.
    provenance : Provenance
        The provenance of the positioner it wrote.
    """

    common: tuple[RobotTouchFile, RobotTouchFile]
    plate: tuple[str, str]
    provenance: Provenance

    @classmethod
    def of(cls, cell: Cell) -> RecordedShared | None:
        """The fit that wrote the cell's positioner; None when another calibration did, or its
        provenance lacks what repeating needs (edited by hand)."""
        pos = cell.turntable
        prov = None if pos is None else pos.provenance
        needed = ("reference", "other", "tool_ref", "tool_other", "sigma_mm",
                  *(f"{k}_file" for k in FILES))
        if (prov is None or prov.source != SOURCE or prov.measurements is None
                or any(k not in prov.options for k in needed)):
            return None
        o, folder = prov.options, Path(prov.measurements).parent
        path = {k: str(folder / str(o[f"{k}_file"])) for k in FILES}
        return cls((RobotTouchFile(str(o["reference"]), path["reference_common"],
                                   str(o["tool_ref"]), float(o.get("track_ref_mm", 0.0)) * 1e-3),
                    RobotTouchFile(str(o["other"]), path["other_common"], str(o["tool_other"]),
                                   float(o.get("track_other_mm", 0.0)) * 1e-3)),
                   (path["reference_plate"], path["other_plate"]), prov)

    @property
    def files(self) -> tuple[str, str, str, str]:
        """The four touch files, in the order of :data:`FILES`."""
        return (*self.plate, self.common[0].path, self.common[1].path)

    def problems(self) -> list[str]:
        """Its touch files that are missing or changed since the fit (none: repeatable)."""
        found = (touch_file_problem("positioner (shared-positioner)", path,
                                    self.provenance.options.get(f"{key}_sha256"))
                 for key, path in zip(FILES, self.files, strict=True))
        return [p for p in found if p is not None]
