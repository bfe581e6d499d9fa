"""The two-robot demo: commission a welding cell of two robots and a shared positioner.

A KUKA KR 16 on a linear track and an ABB IRB 2400 on the floor share a 2-axis tilt-rotate
positioner (the cell ``two_robots_cell.yaml`` of this package, the same as
``examples/cell_two_robots_positioner.yaml``). The *true* cell differs from that nominal cell by
known errors: both torches a millimetre or two off their CAD values, the KUKA's base not quite
aligned on its carriage, the ABB's base a few millimetres and tenths of a degree from its layout
place, the positioner's root a few millimetres and tenths of a degree off. The demo

1. writes the nominal cell file and the true one, and simulates every touch-up in the true cell
   (joint values within every limit, touch-up error ``noise``);
2. calibrates each robot's torch (``robotcell calibrate tcp --robot-name NAME``: the robot's
   view of the cell, :meth:`robotcell.cell.Cell.for_robot`, written back under that robot),
   then the KUKA's track (``robotcell calibrate track --robot-name kuka``);
3. places the ABB in the KUKA's base from both robots touching common points with their
   calibrated torches (``robotcell calibrate robot-to-robot``:
   :func:`robotcell.cell.calibrate.robottorobot.calibrate_robot_to_robot` and
   :func:`~robotcell.cell.calibrate.robottorobot.place_robot`);
4. calibrates the shared positioner with the KUKA (``robotcell calibrate positioner
   --robot-name kuka``), at the track position of its common points;
5. has the ABB touch the positioner too, compares its calibration with the KUKA's through the
   robot-to-robot pose and fits all touches of both robots at once (``robotcell calibrate
   shared-positioner``: :func:`robotcell.cell.calibrate.sharedpositioner.shared_positioner`);
6. prints every calibrated value beside the truth, in mm and deg and in units of its reported
   1-sigma (the :class:`robotcell.demo.walkthrough.Comparison` table of the one-robot demo), the
   joint fit's too, and writes an HTML report per calibration and the 3D view of the calibrated
   cell with both robots (``cell.html``).
"""

from __future__ import annotations

import json
import shlex
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.sharedtable import Agreement
from robotcell.cell import Cell, Positioner, Provenance
from robotcell.cell import calibrate as cellcal
from robotcell.cell.calibrate.robottorobot import (
    RobotTouchFile,
    calibrate_robot_to_robot,
    place_robot,
)
from robotcell.cell.calibrate.sharedpositioner import SharedPositioner, shared_positioner
from robotcell.cell.history import backups
from robotcell.demo.walkthrough import Comparison, comparison_table, reported_sigma
from robotcell.errors import InputError
from robotcell.identification.sharedpositioner import PositionerLines, chain_lines
from robotcell.io.poseformats import pose_from_vendor
from robotcell.io.tables import read_csv
from robotcell.kinematics.transforms import invert, make_pose, rot_z, transform_points
from robotcell.report import verdict, write_report
from robotcell.studies.demo import DEMO_NOISE
from robotcell.studies.plan import pose_error
from robotcell.studies.robottorobot import (
    SimulatedRobot,
    default_points,
    simulate_robot_to_robot,
    table_text,
)
from robotcell.studies.simulate import simulate
from robotcell.view.cellscene import write_cell_view

__all__ = ["run_two_robot_demo"]

#: The reference robot (on the track), the robot it places, the tool both touch with.
REFERENCE, OTHER, TOOL = "kuka", "abb", "torch"

#: The KUKA's track position while it touches the common points (m).
REFERENCE_TRACK = 1.0


def _pose(x: float, y: float, z: float, a: float, b: float, c: float) -> np.ndarray:
    """Pose from KUKA X, Y, Z (mm), A, B, C (deg)."""
    return pose_from_vendor([x, y, z, a, b, c], "kuka")


def _cells(cell_file: Path) -> tuple[Cell, Cell]:
    """Write the nominal cell file; return the true cell and the nominal one."""
    text = resources.files("robotcell.demo").joinpath("two_robots_cell.yaml").read_text("utf-8")
    cell_file.write_text(text, encoding="utf-8")
    nominal = Cell.load(cell_file)
    truth = Cell.load(cell_file)
    true = Provenance("nominal")
    truth.set_tool(TOOL, _pose(313.7, -2.3, 94.1, 0.5, 45.3, -0.4), true, robot=REFERENCE)
    truth.set_tool(TOOL, _pose(298.9, 1.4, 91.2, -0.3, 44.6, 0.5), true, robot=OTHER)
    base = truth.robots[OTHER].T_world_R @ _pose(4.2, -3.1, 1.8, 0.35, -0.1, 0.15)
    truth.set_robot_base(OTHER, base, true)
    track = truth.robots[REFERENCE].track
    assert track is not None
    track.T_L_R0 = track.T_L_R0 @ _pose(0.8, -1.1, 0.6, 0.05, -0.03, 0.02)
    pos = truth.turntable
    assert pos is not None
    chain = replace(pos.chain, base=pos.chain.base @ _pose(3.1, -2.4, 1.6, 0.3, 0.2, -0.25))
    truth.turntable = replace(pos, chain=chain)
    return truth, nominal


@dataclass
class _Run:
    """What every step of the demo shares."""

    out: Path
    cell_file: Path
    truth: Cell
    noise: float
    rng: np.random.Generator
    echo: Callable[[str], None]

    def command(self, args: list[str]) -> None:
        """Print the command a technician types for the step."""
        self.echo("  $ robotcell " + shlex.join(args))

    def keep(self, name: str, result: CalibrationResult, cell: Cell) -> dict[str, Any]:
        """Refuse a poor result as the command does; save the cell and the result's JSON."""
        grade = result.verdict
        if grade.level == "poor":
            raise InputError(f"{name}: poor calibration, nothing written: "
                             f"{'; '.join(grade.reasons)}; try a smaller noise")
        cell.save(self.cell_file)
        data = result.to_json()
        (self.out / f"{name}.json").write_text(json.dumps(data, indent=2) + "\n",
                                               encoding="utf-8")
        self.echo(f"  RMS {data['rms_mm']:.3f} mm, max {data['max_mm']:.3f} mm, condition "
                  f"{data['condition']:.1f}; cell file updated\n  {grade.line()}")
        return data


def _calibrate(run: _Run, robot: str, procedure: str, extra: list[str],
               design: dict[str, Any]) -> dict[str, Any]:
    """One procedure of one robot, simulated in the truth and calibrated into the cell file
    through that robot's view (``robotcell calibrate PROCEDURE --robot-name ROBOT``)."""
    name = f"{procedure}_{robot}"
    touches = simulate(run.truth.for_robot(robot), procedure, noise=run.noise, seed=run.rng,
                       tool=TOOL, **design)
    csv_path = run.out / f"{name}.csv"
    touches.write_csv(csv_path)
    run.echo(f"{procedure} ({robot}): simulated {len(touches.q)} touches -> {csv_path.name}")
    run.command(["calibrate", procedure, str(csv_path), "--cell", str(run.cell_file),
                 "--robot-name", robot, "--json", "--sigma", f"{run.noise * 1e3:g}", *extra,
                 *touches.options])
    cell = Cell.load(run.cell_file)  # the command reads the file, rounded as written
    kw = {"name": TOOL} if procedure == "tcp" else {"tool": TOOL}
    done = cellcal.procedure(procedure).calibrate(
        cell.for_robot(robot), read_csv(csv_path), source=str(csv_path),
        cell_label=str(run.cell_file), file=csv_path, sigma=run.noise, **kw,
        **touches.keywords())
    return run.keep(name, done.result, cell.with_view(done.cell, robot))


def _robot_to_robot(run: _Run, tool_sigma: float) -> dict[str, Any]:
    """Both robots touch common points with their torches; the ABB is placed in the KUKA's base."""
    T_w_ref = run.truth.for_robot(REFERENCE).frame_pose("robot", track=REFERENCE_TRACK)
    T_w_other = run.truth.for_robot(OTHER).frame_pose("robot", track=0.0)
    points = transform_points(T_w_ref, default_points(invert(T_w_ref) @ T_w_other))  # world
    robots = [SimulatedRobot(run.truth.for_robot(r).robot, T,
                             run.truth.robots[r].tools[TOOL].T_F_TCP, r)
              for r, T in ((REFERENCE, T_w_ref), (OTHER, T_w_other))]
    tables = simulate_robot_to_robot(robots, points, noise=run.noise, rng=run.rng, repeats=2)
    files = [run.out / f"robot_to_robot_{r}.csv" for r in (REFERENCE, OTHER)]
    for path, table in zip(files, tables, strict=True):
        path.write_text(table_text(table), encoding="utf-8")
    run.echo(f"robot-to-robot: simulated {len(points)} common points touched twice by each robot "
             f"-> {files[0].name}, {files[1].name}")
    run.command(["calibrate", "robot-to-robot", str(files[0]), str(files[1]), "--cell",
                 str(run.cell_file), "--robot", OTHER, "--reference", REFERENCE, "--tool-ref",
                 TOOL, "--tool-other", TOOL, "--track-ref", f"{REFERENCE_TRACK * 1e3:g}",
                 "--sigma", f"{run.noise * 1e3:g}", "--tool-sigma", f"{tool_sigma * 1e3:.3g}",
                 "--json"])
    cell = Cell.load(run.cell_file)
    ref = RobotTouchFile(REFERENCE, str(files[0]), TOOL, REFERENCE_TRACK)
    oth = RobotTouchFile(OTHER, str(files[1]), TOOL)
    result = calibrate_robot_to_robot(cell, ref, oth, sigma=run.noise, tool_sigma=tool_sigma)
    return run.keep("robot_to_robot", result,
                    place_robot(cell, result, ref, oth, tool_sigma=tool_sigma))


def _tool_sigma(result: dict[str, Any]) -> float:
    """The largest 1-sigma per coordinate of a TCP calibration's position (m), to 3 digits as
    the command's ``--tool-sigma`` gives it."""
    return float(f"{np.max(result['sigma']['T_F_TCP_position_mm']):.3g}") * 1e-3


def run_two_robot_demo(folder: str | Path, noise: float = DEMO_NOISE, seed: int = 1,
                       echo: Callable[[str], None] = print) -> list[Comparison]:
    """Run the two-robot demo, writing every file into ``folder``.

    Parameters
    ----------
    folder : str or Path
        Output folder (created; existing demo files are overwritten).
    noise : float
        Touch-up error (m, 1-sigma per coordinate), of every touch of both robots.
    seed : int
        Seed of the touch-up errors.
    echo : callable
        Receives each line of the narrative.

    Returns
    -------
    list of Comparison
        Both torches, the track, the ABB's base and the positioner's root against the truth,
        then the ABB's base and the positioner's root of the fit of both robots' touches.
    """
    t_start = time.perf_counter()
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    cell_file, truth_file = out / "cell.yaml", out / "truth.yaml"
    for stale in (cell_file, truth_file, *(b for _, b in backups(cell_file)),
                  *(b for _, b in backups(truth_file))):  # a run before in the same folder
        stale.unlink(missing_ok=True)
    truth, _ = _cells(cell_file)
    truth.save(truth_file)
    echo(f"virtual cell: a KUKA KR 16 on a 3 m track (KL1500) and an ABB IRB 2400 sharing a "
         f"2-axis positioner (DKP_2), each with its tool 'torch'\n"
         f"  nominal cell (the drawings): {cell_file}\n"
         f"  true cell (the virtual hardware): {truth_file}\n"
         f"  touch-up error {noise * 1e3:g} mm (1-sigma per coordinate), simulated and stated "
         f"to every calibration (--sigma {noise * 1e3:g}), seed {seed}\n")
    run = _Run(out, cell_file, truth, noise, np.random.default_rng(seed), echo)
    results = {f"tcp_{r}": _calibrate(run, r, "tcp", ["--name", TOOL], {"touches": 6})
               for r in (REFERENCE, OTHER)}
    results["track_kuka"] = _calibrate(run, REFERENCE, "track", ["--tool", TOOL], {})
    results["robot_to_robot"] = _robot_to_robot(
        run, max(_tool_sigma(results[f"tcp_{r}"]) for r in (REFERENCE, OTHER)))
    results["positioner_kuka"] = _calibrate(run, REFERENCE, "positioner", ["--tool", TOOL],
                                            {"track": REFERENCE_TRACK})
    shared = _shared_positioner(run, max(_tool_sigma(results[f"tcp_{r}"])
                                         for r in (REFERENCE, OTHER)))
    results["shared_positioner"] = shared.joint.to_json()
    calibrated = Cell.load(cell_file)
    comparisons = _compare(calibrated, truth, results) + _joint_rows(truth, shared)
    echo("\ncalibrated vs true cell (error, and error / reported 1-sigma):")
    echo(comparison_table(comparisons))
    _write_outputs(out, calibrated, results, echo)
    echo(f"\ndone in {time.perf_counter() - t_start:.1f} s; everything is in {out}/")
    return comparisons


def _compare(calibrated: Cell, truth: Cell,
             results: dict[str, dict[str, Any]]) -> list[Comparison]:
    """Each calibrated pose beside the truth, with the 1-sigma its calibration reported."""
    assert calibrated.turntable is not None and truth.turntable is not None
    rows = [(f"tool {TOOL} of {r}", calibrated.robots[r].tools[TOOL].T_F_TCP,
             truth.robots[r].tools[TOOL].T_F_TCP, results[f"tcp_{r}"], "T_F_TCP")
            for r in (REFERENCE, OTHER)]
    track, true_track = calibrated.robots[REFERENCE].track, truth.robots[REFERENCE].track
    assert track is not None and true_track is not None
    rows.append(("track KL1500 of kuka (T_L_R0)", track.T_L_R0, true_track.T_L_R0,
                 results["track_kuka"], "T_L_R"))
    rows.append((f"base of {OTHER} in {REFERENCE} (T_ref_other)", _in_reference(calibrated),
                 _in_reference(truth), results["robot_to_robot"], "T_ref_other"))
    rows.append(("positioner DKP_2 root (T_world_B)", calibrated.turntable.T_parent_root,
                 _root_as(truth.turntable, calibrated.turntable), results["positioner_kuka"],
                 "T_world_B"))
    out = []
    for item, est, true, res, key in rows:
        dp, dr = pose_error(est, true)
        sp, sr = reported_sigma(res, key)
        out.append(Comparison(item, est, true, dp, dr, sp, sr))
    return out


def _in_reference(cell: Cell) -> np.ndarray:
    """``T_Rref_Rother`` at the track positions of the robots' touches (m)."""
    return (invert(cell.for_robot(REFERENCE).frame_pose("robot", track=REFERENCE_TRACK))
            @ cell.for_robot(OTHER).frame_pose("robot", track=0.0))


def _shared_positioner(run: _Run, tool_sigma: float) -> SharedPositioner:
    """The ABB touches its own point on the plate; its calibration of the positioner is
    compared with the KUKA's, and all touches of both robots are fitted at once."""
    touches = simulate(run.truth.for_robot(OTHER), "positioner", noise=run.noise, seed=run.rng,
                       tool=TOOL, radius=0.15)
    plate = (run.out / f"positioner_{REFERENCE}.csv", run.out / f"positioner_{OTHER}.csv")
    touches.write_csv(plate[1])
    common = [run.out / f"robot_to_robot_{r}.csv" for r in (REFERENCE, OTHER)]
    run.echo(f"\nshared positioner ({OTHER}): simulated {len(touches.q)} touches of another "
             f"point on the plate -> {plate[1].name}; compared with {REFERENCE}'s calibration "
             "through the robot-to-robot pose, and all touches of both robots in one fit")
    run.command(["calibrate", "shared-positioner", str(plate[0]), str(plate[1]), "--common",
                 str(common[0]), str(common[1]), "--cell", str(run.cell_file), "--robot", OTHER,
                 "--reference", REFERENCE, "--tool-ref", TOOL, "--tool-other", TOOL,
                 "--track-ref", f"{REFERENCE_TRACK * 1e3:g}", "--sigma",
                 f"{run.noise * 1e3:g}", "--tool-sigma", f"{tool_sigma * 1e3:.3g}"])
    shared = shared_positioner(
        Cell.load(run.cell_file), (RobotTouchFile(REFERENCE, str(common[0]), TOOL,
                                                  REFERENCE_TRACK),
                                   RobotTouchFile(OTHER, str(common[1]), TOOL)),
        (str(plate[0]), str(plate[1])), sigma=run.noise, tool_sigma=tool_sigma)
    run.echo("  " + shared.agreement.message)
    run.echo(_agreement_table(shared.agreement))
    data = shared.joint.to_json()
    run.echo(f"  all touches in one fit: RMS {data['rms_mm']:.3f} mm, max {data['max_mm']:.3f} "
             f"mm, condition {data['condition']:.1f}\n  {shared.joint.verdict.line()}")
    if shared.joint.verdict.level == "poor":
        raise InputError(f"shared positioner: poor calibration: "
                         f"{'; '.join(shared.joint.verdict.reasons)}; try a smaller noise")
    return shared


def _agreement_table(agreement: Agreement) -> str:
    """Each compared component: the difference, its 1-sigma and their ratio."""
    from robotcell.io.tables import format_table

    rows = []
    for name, d, s, length in zip(agreement.components, agreement.difference, agreement.sigma,
                                  agreement.lengths, strict=True):
        unit, scale = ("mm", 1e3) if length else ("deg", 180.0 / np.pi)
        rows.append([name, f"{d * scale:.3f} {unit}", f"{s * scale:.3f} {unit}",
                     f"{d / s:.1f}"])
    return format_table([f"{REFERENCE} minus {OTHER}", "difference", "1-sigma", "in sigma"], rows)


def _joint_rows(truth: Cell, shared: SharedPositioner) -> list[Comparison]:
    """The fit of all touches beside the truth: the ABB's base and the positioner's root (its
    axis lines) in the KUKA's base."""
    assert truth.turntable is not None
    joint, data = shared.joint, shared.joint.to_json()
    T_B = np.asarray(joint.values["T_ref_B"], dtype=float)
    T_w_R = truth.for_robot(REFERENCE).frame_pose("robot", track=REFERENCE_TRACK)
    chain = truth.turntable.chain
    true_B = chain_lines(chain.with_base(invert(T_w_R) @ chain.base),
                         PositionerLines(T_B, 0.0, 0.0)).T_B
    rows = [(f"base of {OTHER} in {REFERENCE}, all touches (T_ref_other)",
             joint.values["T_ref_other"], _in_reference(truth), "T_ref_other"),
            (f"positioner axes in {REFERENCE}, all touches (T_ref_B)", T_B, true_B, "T_ref_B")]
    out = []
    for item, est, true, key in rows:
        dp, dr = pose_error(est, true)
        sp, sr = reported_sigma(data, key)
        out.append(Comparison(item, est, true, dp, dr, sp, sr))
    return out


def _root_as(truth: Positioner, calibrated: Positioner) -> np.ndarray:
    """The true root written with the calibrated tilt zero (m).

    A positioner's root turned about its tilt axis with the tilt zero turned back is the same
    positioner; the calibration writes the one nearest the nominal, so the truth is compared in
    that writing: ``T_root Rz(theta_true - theta_calibrated)``.
    """
    turn = truth.chain.joints[0].theta - calibrated.chain.joints[0].theta
    return truth.T_parent_root @ make_pose(rot_z(turn), np.zeros(3))


def _write_outputs(out: Path, cell: Cell, results: dict[str, dict[str, Any]],
                   echo: Callable[[str], None]) -> None:
    """The HTML report of every calibration and the 3D view of the calibrated cell."""
    echo("\nreports:")
    for name, res in results.items():
        page = write_report(res, out / f"report_{name}.html")[0]
        grade, _ = verdict(res)
        echo(f"  {page.name}: {grade.upper()}")
    echo(f"  $ robotcell view {out / 'cell.yaml'} --table 20,30 -o {out / 'cell.html'}")
    page = write_cell_view(cell, out / "cell.html", table=np.radians([20.0, 30.0]))
    echo(f"3D view of the calibrated cell, both robots and the positioner (open it in a "
         f"browser): {page.name}")
