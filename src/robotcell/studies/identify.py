"""The identification of an arm or positioner from a measurement file, as one call.

:func:`identify_file` reads the measurements, builds or loads the nominal model, identifies (with
a stated J2/J3 coupling or not), cross-validates, compares the observability of the measured
configurations with random ones for the report, computes the joint zero offsets for a controller,
and writes the identified model file, the HTML report and the cell's ``robot.identified``. The
command ``robotcell identify`` prints what it returns.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell
from robotcell.cell.identified import CellRobotFile, adopt_identified, identification_provenance
from robotcell.controllers.registry import CONTROLLERS, get
from robotcell.errors import InputError
from robotcell.identification import identify, read_target_measurements
from robotcell.identification.choice import (
    DEFAULT_FOLDS,
    ValidatedIdentification,
    identify_validated,
)
from robotcell.identification.circles import first_estimate
from robotcell.identification.coupling import coupling_check
from robotcell.identification.measurements import TargetMeasurements
from robotcell.identification.offsets import JointOffset, joint_offsets
from robotcell.identification.options import IdentifyOptions
from robotcell.identification.result import IdentificationResult
from robotcell.identification.validation import CrossValidation, compare_observability
from robotcell.robot.models import load_robot, save_robot

__all__ = ["DEFAULT_FOLDS", "IdentificationRun", "controller_offsets", "identify_file",
           "zero_offset_controllers"]


def controller_offsets(offsets: list[JointOffset], vendor: str) -> dict[str, Any]:
    """Joint zero offsets in the controller's units: KUKA deg (mm), ABB rad (m).

    Parameters
    ----------
    offsets : list of JointOffset
        :func:`~robotcell.identification.offsets.joint_offsets` (rad, m).
    vendor : str
        A registered controller that takes zero offsets (its ``zero_offsets``: KUKA, ABB).

    Returns
    -------
    dict
        ``{"controller": vendor, "axes": [{"axis", "delta", "sigma", "unit", "why"}, ...]}``.

    Raises
    ------
    InputError
        A controller robotcell has no zero offsets for.
    """
    z = get(vendor).zero_offsets
    if z is None:
        raise InputError(f"robotcell has no joint zero offsets for {vendor}; choose one of: "
                         f"{', '.join(zero_offset_controllers())}")
    rows = []
    for o in offsets:
        f = z.length_scale if o.prismatic else z.angle_scale
        unit = z.length_unit if o.prismatic else z.angle_unit
        rows.append({"axis": o.axis, "delta": o.delta * f, "sigma": o.sigma * f, "unit": unit,
                     "why": o.why})
    return {"controller": vendor, "axes": rows}


def zero_offset_controllers() -> list[str]:
    """The registered controllers that take joint zero offsets."""
    return [name for name, c in CONTROLLERS.items() if c.zero_offsets is not None]


@dataclass(frozen=True)
class IdentificationRun:
    """What :func:`identify_file` did.

    Attributes
    ----------
    result : IdentificationResult
        The identification written (the chosen set of free constants).
    cross : CrossValidation or None
        Its cross-validation (None with ``folds=0``): held-out errors of the start model
        (``before``) and of ``result`` (``after``).
    folds : int or None
        Its number of folds.
    choice : ValidatedIdentification or None
        The sets of free constants compared and the one chosen (None with ``folds=0``).
    offsets : dict or None
        :func:`controller_offsets` of the result, when ``offsets_for`` was given.
    written : bool
        Whether the model file (and the cell) was written.
    observability : (float, ndarray) or None
        O1 of the measured configurations and of random sets, when asked for (``report``).
    measurements : TargetMeasurements or None
        The measurements identified, when asked for (``report``).
    """

    result: IdentificationResult
    cross: CrossValidation | None
    folds: int | None
    offsets: dict[str, Any] | None
    written: bool
    observability: tuple[float, NDArray[np.float64]] | None = None
    measurements: TargetMeasurements | None = None
    choice: ValidatedIdentification | None = None

    @property
    def cross_stats(self) -> dict[str, float] | None:
        """Held-out errors (mm) of the cross-validation (:meth:`CrossValidation.stats`)."""
        return None if self.cross is None else self.cross.stats()

    def to_json(self) -> dict[str, Any]:
        """The result's JSON (mm, deg) with the cross-validation and the joint offsets."""
        data = self.result.to_json()
        if self.cross is not None:
            data["cross_validation"] = {"folds": self.folds, **self.cross_stats}
        if self.choice is not None:
            c = self.choice
            data["cross_validation"].update(
                chosen=c.chosen.label, chosen_free=c.chosen.free, why=c.sentence(),
                candidates=[{"label": x.label, "free": x.free, "rms_mm": x.rms * 1e3}
                            for x in c.candidates])
        if self.offsets is not None:
            data["joint_offsets"] = self.offsets
        return data


def identify_file(measurements: str | Path, robot: str | Path | None = None,
                  cell: str | Path | CellRobotFile | None = None, *,
                  folds: int = DEFAULT_FOLDS,
                  report: bool = False, offsets_for: str | None = None,
                  output: str | Path | None = None, force: bool = False,
                  options: IdentifyOptions | None = None, **keywords: Any) -> IdentificationRun:
    """Identify the kinematic model of an arm or positioner from a measurement CSV.

    Parameters
    ----------
    measurements : str or Path
        CSV of joint values and measured targets (docs/identification.md).
    robot : str or Path, optional
        Nominal model (library name or model file). Without it and without ``cell`` the circle
        point analysis builds the start model.
    cell : str, Path or CellRobotFile, optional
        A cell file: its ``robot.model`` is the nominal when ``robot`` is not given, and the
        identified model written to ``output`` becomes its ``robot.identified``. In a cell of
        several robots, ``CellRobotFile(path, robot)`` names the robot whose arm was measured.
    folds : int
        Folds of the cross-validation that chooses the constants to free (at most the rows;
        :func:`~robotcell.identification.identify_validated`); 0: none, every identifiable
        constant is freed unchecked.
    report : bool
        Also compute what the HTML report needs (the observability of the measured
        configurations; the run keeps the measurements), which
        :func:`robotcell.report.identification.write_identification_report` writes.
    offsets_for : str, optional
        A controller of :func:`zero_offset_controllers` (``kuka``, ``abb``).
        Also compute the joint zero offsets in that controller's units.
    output : str or Path, optional
        Identified model file (YAML) to write, unless the verdict is poor and not ``force``.
    force : bool
        Write ``output`` even when the verdict is poor.
    options : IdentifyOptions, optional
        The accuracies (``sigma``, m; ``angle_sigma``, rad), ``scale``, ``compliance``,
        ``group_tol`` (rad; a prismatic joint takes as many mm as that is deg) and a stated
        J2/J3 factor ``coupling`` (``q3_model = J3 + k J2``, FANUC: 1; also the start of the
        circle point analysis), which is checked against the fits without it and with it free
        (:func:`~robotcell.identification.coupling.coupling_check`).
    **keywords
        Fields of :class:`~robotcell.identification.options.IdentifyOptions` that replace those
        of ``options`` (``sigma=2e-5, j23_factor=1.0``).

    Returns
    -------
    IdentificationRun

    Raises
    ------
    InputError
        ``cell`` without ``output``; ``offsets_for`` without a nominal ``robot``; bad measurements;
        ``folds`` below 0 or 1.
    """
    if cell is not None and output is None:
        raise InputError("cell needs output: the identified model file the cell will name")
    if offsets_for is not None and robot is None:
        raise InputError("offsets_for needs robot (the nominal model): the offsets correct the "
                         "nominal model the controller uses")
    if folds < 0 or folds == 1:
        raise InputError(f"folds must be 0 (no cross-validation) or at least 2, got {folds}")
    opts = IdentifyOptions.of(options, **keywords)
    where = cell if isinstance(cell, CellRobotFile) or cell is None else CellRobotFile(cell)
    if robot is not None or cell is not None:
        nominal = (load_robot(robot) if robot is not None
                   else Cell.load(where.path).for_robot(where.robot).nominal_robot)
        meas = read_target_measurements(measurements, nominal.prismatic)
    else:
        nominal, meas = first_estimate(measurements, j23_factor=opts.j23_factor or 0.0,
                                       group_tol=opts.group_tol)
    choice, cross = None, None
    if folds:
        folds = min(folds, meas.n_rows)
        choice = identify_validated(nominal, meas, folds=folds, options=opts)
        result, cross = choice.result, choice.cross
    else:
        result = identify(nominal, meas, options=opts)
    if opts.j23_factor is not None:
        result.coupling_check = coupling_check(nominal, meas, opts.j23_factor, result,
                                               options=opts)
    obs = None
    if report:
        obs = compare_observability(nominal, meas.q, n_targets=meas.n_targets,
                                    pose=meas.rotations is not None, sigma=opts.sigma,
                                    angle_sigma=opts.angle_sigma)
    offsets = (None if offsets_for is None
               else controller_offsets(joint_offsets(result), offsets_for))
    written = output is not None and (result.verdict[0] != "poor" or force)
    if written:
        if cell is None:
            save_robot(result.robot, output)
        else:
            adopt_identified(where.path, result, output,
                             identification_provenance(result, cross), robot=where.robot)
    return IdentificationRun(result, cross, folds or None, offsets, written, obs,
                             meas if report else None, choice)
