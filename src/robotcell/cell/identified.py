"""Putting an identified arm into a cell file: the model file and ``robot.identified``, together.

``robotcell identify ... -o ARM.yaml --cell CELL.yaml`` writes the identified model file and sets
the cell's ``robot.identified`` to it, with the identification's provenance (time, RMS of the
residuals, held-out error of the cross-validation). Both files change or neither: everything is
checked first (the model is an identification of the cell's arm, both destinations can be
written), then the model file is written atomically, then the cell file is updated (under its
lock, atomically, with a numbered backup); if that fails the model file is put back as it was.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from robotcell.cell.model import Cell
from robotcell.cell.parts import Provenance
from robotcell.cell.schema import cell_to_dict
from robotcell.cell.update import update_cell_file
from robotcell.errors import InputError
from robotcell.identification.result import IdentificationResult
from robotcell.identification.validation import CrossValidation
from robotcell.io.fileio import atomic_write, check_destination, read_text
from robotcell.robot.models import save_robot

__all__ = ["CellRobotFile", "adopt_identified", "identification_provenance"]


@dataclass(frozen=True)
class CellRobotFile:
    """One robot of a cell file: where an identified arm goes.

    Attributes
    ----------
    path : str or Path
        The cell file.
    robot : str, optional
        In a cell of several robots, the robot (a key of its ``robots``); None: the only robot.
    """

    path: str | Path
    robot: str | None = None


def identification_provenance(result: IdentificationResult,
                              cross: CrossValidation | None = None) -> Provenance:
    """The provenance of an identified arm: now, its RMS, rows, and the held-out error.

    Parameters
    ----------
    result : IdentificationResult
    cross : CrossValidation, optional
        A cross-validation of the same measurements; its held-out RMS goes into the note.

    Returns
    -------
    Provenance
        ``source: identify``, ``rms_mm`` the identified model's residual RMS (mm).
    """
    note = (f"{len(result.labels)} rows, nominal {result.nominal.name}, RMS before "
            f"{result.rms_before * 1e3:.4f} mm, verdict {result.verdict[0]}")
    if cross is not None:
        s = cross.stats()
        note += (f"; held-out RMS {s['after_rms_mm']:.4f} mm (nominal {s['before_rms_mm']:.4f} mm, "
                 f"{cross.folds}-fold cross-validation)")
    return Provenance.now("identify", rms_mm=round(result.rms_after * 1e3, 6), note=note)


def adopt_identified(cell_path: str | Path, result: IdentificationResult, model_path: str | Path,
                     provenance: Provenance, on_note: Callable[[str], None] | None = None,
                     robot: str | None = None) -> Cell:
    """Write the identified model file and make it the arm of a cell file, both or neither.

    The cell file is changed as one locked step (:func:`robotcell.cell.update.update_cell_file`):
    an update of it by another process at the same time is kept.

    Parameters
    ----------
    cell_path : str or Path
        The cell file; its ``robot.identified`` is set (relative to it) with ``provenance``.
    result : IdentificationResult
        Its ``robot`` is written to ``model_path``.
    model_path : str or Path
        The identified model file (YAML).
    provenance : Provenance
        See :func:`identification_provenance`.
    on_note : callable, optional
        Receives the notes of the cell file's update (a wait for another update).
    robot : str, optional
        In a cell of several robots, the robot whose arm was identified (a key of its
        ``robots``); None: the only robot.

    Returns
    -------
    Cell
        The cell as saved.

    Raises
    ------
    InputError
        The cell file cannot be read, a robot the cell lacks, the identified model is not of
        the cell's arm (the nominal the identification started from must be the robot's
        ``model``), or a file cannot be written: nothing is changed then.
    """
    check_destination(model_path)
    check_destination(cell_path)
    old = read_text(model_path, "model file") if Path(model_path).is_file() else None
    written: list[bool] = []

    def adopt(cell: Cell) -> tuple[Cell, None]:
        try:
            key = cell.robot_key(robot)
        except InputError as exc:
            raise InputError(f"{cell_path}: {exc}") from None
        view = cell.for_robot(key)
        try:
            view.set_identified(result.robot, str(Path(model_path).resolve()), provenance)
        except InputError as exc:
            raise InputError(f"{cell_path}: {exc} (the robot's model is "
                             f"{view.robot_model})") from None
        cell = cell.with_view(view, key)
        cell_to_dict(cell, Path(cell_path).resolve().parent)  # every value writable first
        if not written:  # the same model for every version of the cell
            save_robot(result.robot, model_path)
            written.append(True)
        return cell, None

    try:
        done = update_cell_file(cell_path, adopt, on_note=on_note)
    except BaseException:
        if written and old is None:
            Path(model_path).unlink(missing_ok=True)
        elif written:
            atomic_write(model_path, old)
        raise
    return done.cell
