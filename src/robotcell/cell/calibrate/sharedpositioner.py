"""A 2-axis positioner shared by two robots of a cell: both calibrations compared, all touches
in one fit.

Each robot touches common points (as for the robot-to-robot calibration,
:mod:`robotcell.cell.calibrate.robottorobot`) and its own point on the positioner's plate at
several (tilt, rotate) values, each at one track position, with one of its tools in the cell.
:func:`shared_positioner` calibrates the robot-to-robot pose, the positioner from each robot's
touches in its own base, compares the two
(:func:`robotcell.identification.sharedpositioner.compare_positioner`) and fits every touch
at once (:func:`robotcell.identification.sharedpositioner.shared_positioner`).
:func:`place_shared_positioner` writes that joint fit into a cell: the positioner's chain and
the other robot's base, each with a provenance (source ``shared-positioner``) that records the
four touch files with their checksums, the options and the 1-sigma's parts, so that
``calibrate cell`` repeats it (:func:`repeat_shared`).
Docs: docs/calibration.md, "One positioner, two robots".
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.robottorobot import RobotTouches
from robotcell.calibration.robottorobot_tables import (
    robot_to_robot_tables,
    robot_touches,
    tool_error,
)
from robotcell.calibration.sharedtable import Agreement
from robotcell.calibration.spec import SPECS
from robotcell.calibration.uncertainty import OWN, Estimate, Sources
from robotcell.cell.calibrate.chain import item_sources, written_sources
from robotcell.cell.calibrate.common import sha256_of
from robotcell.cell.calibrate.robottorobot import RobotTouchFile, placed_base, robot_table
from robotcell.cell.calibrate.sharedrecord import FILES, SOURCE, RecordedShared
from robotcell.cell.calibrate.touches import read_touches
from robotcell.cell.model import Cell
from robotcell.cell.parts import Provenance
from robotcell.errors import InputError
from robotcell.identification.positioner import PositionerCalibration, calibrate_positioner
from robotcell.identification.sharedpositioner import (
    PositionerLines,
    compare_positioner,
    lines_chain,
)
from robotcell.identification.sharedpositioner import shared_positioner as joint_fit
from robotcell.kinematics.transforms import invert
from robotcell.robot.robot import Robot

__all__ = ["FILES", "SOURCE", "RecordedShared", "SharedPositioner", "place_shared_positioner",
           "repeat_shared", "shared_positioner"]


@dataclass(frozen=True)
class SharedPositioner:
    """The positioner two robots calibrated, compared and fitted together.

    Attributes
    ----------
    link : CalibrationResult
        The robot-to-robot pose from the common points alone (``T_ref_other``).
    reference, other : CalibrationResult
        Each robot's calibration of the positioner in its own base (``positioner-2axis``, at
        its track position).
    agreement : Agreement
        The two calibrations compared through ``link``.
    joint : CalibrationResult
        All touches in one fit (``T_ref_other``, ``T_ref_B``, ``axis_offset``, ``axis_angle``);
        its JSON holds the comparison as ``agreement``.
    """

    link: CalibrationResult
    reference: CalibrationResult
    other: CalibrationResult
    agreement: Agreement
    joint: CalibrationResult


def _plate_touches(cell: Cell, touches: RobotTouchFile, tool_sigma: float | None,
                   on_note: Callable[[str], None] | None
                   ) -> tuple[np.ndarray, RobotTouches, list[str]]:
    """One robot's touches of its point on the plate: axis values (rad), the touches in its
    base with its tool's error, and their labels."""
    table = robot_table(cell, touches)
    m = read_touches(SPECS["positioner"], table.columns, touches.path, table.robot, on_note)
    if m.track is not None and not np.allclose(m.track, touches.track, atol=1e-6):
        raise InputError(f"{touches.path}: column 'track' differs from the track position "
                         f"{touches.track * 1e3:g} mm of robot {touches.robot!r}; touch the "
                         "plate at the track position of the common points")
    names = ["plate"] * m.n
    if m.joints is None:
        if on_note is not None:
            on_note(f"note: {touches.path}: touches given as x, y, z were computed by the "
                    "controller with its tool, whose error is left out; give joint values "
                    "a1..a6 to include it")
        return m.axes, RobotTouches(m.tcp(), names, robot=touches.robot), m.labels()
    return m.axes, RobotTouches.from_flange(m.flange(), table.tool, names,
                                            tool_sigma=tool_error(touches.robot, tool_sigma),
                                            robot=touches.robot), m.labels()


def _calibrated(cell: Cell, touches: RobotTouchFile, plate: tuple, sigma: float | None
                ) -> PositionerCalibration:
    """The positioner from one robot's touches, in its base at its track position, started
    from the cell's chain."""
    pos = cell.turntable
    assert pos is not None
    T_w_R = cell.for_robot(touches.robot).frame_pose("robot", track=touches.track)
    nominal = pos.chain.with_base(invert(T_w_R) @ pos.chain.base)
    values, t, labels = plate
    return calibrate_positioner(values, t.points, nominal=nominal, sigma=sigma, labels=labels,
                                inputs=t.inputs)


def shared_positioner(cell: Cell, common: tuple[RobotTouchFile, RobotTouchFile],
                      plate: tuple[str, str], *, sigma: float | None = None,
                      tool_sigma: float | None = None,
                      on_note: Callable[[str], None] | None = None) -> SharedPositioner:
    """Two robots' calibrations of the cell's 2-axis positioner, compared and fitted together.

    Parameters
    ----------
    cell : Cell
        A cell of several robots with a positioner of 2 axes.
    common : (RobotTouchFile, RobotTouchFile)
        The reference robot's and the other robot's touches of the common points (their tools
        and track positions hold for the plate touches too).
    plate : (str, str)
        Each robot's touch file of its point on the plate: joint values ``a1..an`` (deg, or
        ``x, y, z`` mm in its base) and the axis values ``e1``, ``e2`` (deg); a column
        ``track``, if any, equal to the robot's track position.
    sigma : float, optional
        Touch accuracy (m, 1-sigma per coordinate).
    tool_sigma : float, optional
        Accuracy of both tools' TCP (m); default an assumed figure the results mark assumed.
    on_note : callable, optional
        Receives notes on the measurements.

    Returns
    -------
    SharedPositioner

    Raises
    ------
    InputError
        A cell without a 2-axis positioner, the same robot twice, a robot or tool the cell
        lacks, or touches the estimators refuse.
    """
    pos = cell.turntable
    if pos is None or pos.n_axes != 2 or pos.parent != "world":
        raise InputError("the cell has no 2-axis positioner in the world that both robots "
                         "share; add a 'positioner' section with parent world")
    ref, oth = common
    if cell.robot_key(ref.robot) == cell.robot_key(oth.robot):
        raise InputError(f"the reference and the other robot are both {ref.robot!r}; name two "
                         "robots of the cell")
    tables = [robot_table(cell, t) for t in common]
    sets = [robot_touches(t, tool_sigma, on_note) for t in tables]
    link = robot_to_robot_tables(tables[0], tables[1], sigma=sigma, tool_sigma=tool_sigma,
                                 on_note=on_note)
    plates = [_plate_touches(cell, replace(t, path=p), tool_sigma, on_note)
              for t, p in zip(common, plate, strict=True)]
    cals = [_calibrated(cell, t, p, sigma) for t, p in zip(common, plates, strict=True)]
    agreement = compare_positioner(cals[0].result, cals[1].result, link,
                                   names=(ref.robot, oth.robot))
    joint = joint_fit(plates[0][1], plates[0][0], plates[1][1], plates[1][0],
                      common=(sets[0], sets[1]), sigma=sigma, start=(cals[0], cals[1]))
    joint = replace(joint, json_fields={**joint.json_fields, "agreement": agreement.to_json()})
    return SharedPositioner(link, cals[0].result, cals[1].result, agreement, joint)


# -- into the cell ------------------------------------------------------------------------------
def _options(done: SharedPositioner, common: tuple[RobotTouchFile, RobotTouchFile],
             plate: tuple[str, str], tool_sigma: float | None) -> dict[str, Any]:
    """What the provenance of the joint fit records, in the units of the command line: the
    robots (``robot``: the reference, whose base the fit is in), tools, track positions, the
    touch files other than ``measurements`` (relative to its folder) and every file's checksum,
    ``sigma_mm``, ``tool_sigma_mm`` (when given) and the 1-sigma's parts of the fit
    (``sigma_parts``: own, recorded, assumed, as the result's JSON gives them, relative to the
    reference robot's base)."""
    ref, oth = common
    folder = Path(plate[0]).resolve().parent
    files = {"reference_plate": plate[0], "other_plate": plate[1],
             "reference_common": ref.path, "other_common": oth.path}
    out: dict[str, Any] = {"robot": ref.robot, "reference": ref.robot, "other": oth.robot,
                           "tool_ref": ref.tool, "tool_other": oth.tool,
                           "track_ref_mm": float(ref.track * 1e3),
                           "track_other_mm": float(oth.track * 1e3),
                           "sigma_mm": float(done.joint.touch_sigma * 1e3)}
    if tool_sigma is not None:
        out["tool_sigma_mm"] = float(tool_sigma * 1e3)
    for key, path in files.items():
        out[f"{key}_file"] = os.path.relpath(Path(path).resolve(), folder)
        out[f"{key}_sha256"] = sha256_of(path)
    parts = done.joint.to_json().get("sigma_parts", {})
    out["sigma_parts"] = {k: {**parts[k], "relative_to": ref.robot}  # "ref": the reference
                          for k in ("T_ref_B", "axis_offset", "axis_angle", "T_ref_other")
                          if k in parts}
    return out


def _chain_in_world(cell: Cell, done: SharedPositioner, reference: RobotTouchFile, ident: str
                    ) -> tuple[Robot, dict[str, np.ndarray]]:
    """The cell's positioner chain moved onto the joint fit's axes (in the world), and its
    error sources over the chain's parameters (:func:`~robotcell.identification.positioner.
    perturbed_chain`; the directions the axes do not fix keep the cell's sources)."""
    j = done.joint
    T_w_R = cell.for_robot(reference.robot).frame_pose("robot", track=reference.track)
    lines = PositionerLines(T_w_R @ np.asarray(j.values["T_ref_B"], dtype=float),
                            float(j.values["axis_offset"]), float(j.values["axis_angle"]))
    assert cell.turntable is not None
    chain, gain = lines_chain(cell.turntable.chain, lines)
    turn = np.eye(8)
    turn[:3, :3] = turn[3:6, 3:6] = T_w_R[:3, :3]    # reference base axes -> world axes
    eight = Sources.stack([j.estimates["T_ref_B"].sources, j.value_sources["axis_offset"],
                           j.value_sources["axis_angle"]]).map(turn)
    determined = np.linalg.svd(gain, full_matrices=False)[0]
    est = Estimate(eight.map(gain), np.zeros((len(gain), 0)), determined)
    return chain, written_sources(est, item_sources(cell, "turntable")[0], ident)


def place_shared_positioner(cell: Cell, done: SharedPositioner,
                            common: tuple[RobotTouchFile, RobotTouchFile],
                            plate: tuple[str, str], *, tool_sigma: float | None = None,
                            time: str | None = None, accept_poor: bool = False) -> Cell:
    """``cell`` with the joint fit of :func:`shared_positioner` written into it (a new cell).

    The cell's positioner chain (as ``calibrate positioner --cell`` wrote it, or the nominal)
    moves onto the fitted axis lines, carried into the world through the reference robot's base
    at its track position, by the smallest change of its root and DH constants (:func:`~robotcell.
    identification.sharedpositioner.lines_chain`: the plate frame on the last axis and the DH
    table's writing stay as the cell has them), and the other robot's base is placed from
    the fitted ``T_ref_other`` (for a robot on a track: at track position 0). Both carry a
    provenance ``shared-positioner`` with the same error sources (the fit's own touch noise,
    named after the reference robot's plate file, and the tools' errors), so their correlation
    is kept; its options record the four touch files with their checksums, the robots, tools,
    track positions, ``sigma_mm``, ``tool_sigma_mm`` and the 1-sigma's parts (``sigma_parts``).
    ``calibrate cell`` repeats it (:class:`RecordedShared`, :func:`repeat_shared`).

    Parameters
    ----------
    cell : Cell
        The cell the calibrations used (not changed).
    done : SharedPositioner
        :func:`shared_positioner` of ``common`` and ``plate`` in ``cell``.
    common : (RobotTouchFile, RobotTouchFile)
        The reference robot's and the other robot's touches of the common points.
    plate : (str, str)
        Each robot's touch file of its point on the plate.
    tool_sigma : float, optional
        The tools' accuracy the fit was given (m); None: the assumed figure.
    time : str, optional
        ISO 8601 time of the provenance; default now.
    accept_poor : bool
        Write a fit whose two calibrations disagree or whose verdict is poor.

    Returns
    -------
    Cell

    Raises
    ------
    InputError
        The two calibrations disagree or the verdict is poor (without ``accept_poor``), or a
        touch file cannot be read; ``cell`` is left as it was.
    """
    if not accept_poor and not done.agreement.agree:
        raise InputError(f"{done.agreement.message}; nothing written (accept_poor=True writes "
                         "the fit anyway)")
    if not accept_poor and done.joint.verdict.level == "poor":
        raise InputError(f"poor calibration, nothing written: "
                         f"{'; '.join(done.joint.verdict.reasons)} (accept_poor=True writes "
                         "the fit anyway)")
    ref, oth = common
    stamp = time or Provenance.now(SOURCE).time
    sha = sha256_of(plate[0])
    ident = f"shared positioner {sha[:12]}"
    j = done.joint
    chain, chain_sources = _chain_in_world(cell, done, ref, ident)
    note = (f"{len(j.residuals)} touches from {Path(plate[0]).name}, {Path(plate[1]).name}, "
            f"{Path(ref.path).name} and {Path(oth.path).name}: robots {ref.robot!r} and "
            f"{oth.robot!r} fitted together")
    prov = Provenance(SOURCE, time=stamp, rms_mm=j.rms * 1e3, note=note, id=ident,
                      measurements=str(Path(plate[0]).resolve()), sha256=sha,
                      options=_options(done, common, plate, tool_sigma),
                      inputs=(f"robots.{ref.robot}",))
    base = j.estimates["T_ref_other"].sources.renamed(OWN, ident)
    new = replace(cell)
    new.update_positioner(replace(prov, sources=chain_sources), chain)
    new.set_robot_base(oth.robot, placed_base(cell, j.values["T_ref_other"], ref, oth),
                       replace(prov, sources=dict(base.factors)))
    return new


# -- repeated by calibrate cell -----------------------------------------------------------------
def repeat_shared(cell: Cell, recorded: RecordedShared, time: str | None = None
                  ) -> tuple[Cell | None, SharedPositioner]:
    """Repeat a recorded shared-positioner fit on ``cell`` as it stands (both robots' tools and
    the reference robot's base as they are now) and write it again.

    Returns
    -------
    cell : Cell or None
        A new cell with the positioner and the other robot's base written again; None when the
        two calibrations now disagree or the verdict is poor (nothing to write).
    done : SharedPositioner
    """
    o = recorded.provenance.options
    tool_sigma = float(o["tool_sigma_mm"]) * 1e-3 if "tool_sigma_mm" in o else None
    done = shared_positioner(cell, recorded.common, recorded.plate,
                             sigma=float(o["sigma_mm"]) * 1e-3, tool_sigma=tool_sigma)
    if not done.agreement.agree or done.joint.verdict.level == "poor":
        return None, done
    return place_shared_positioner(cell, done, recorded.common, recorded.plate,
                                   tool_sigma=tool_sigma, time=time), done
