"""The demo walk-through: commission a virtual cell from touch-up points to controller data.

A KUKA KR 16 on a 6 m linear track beside a turntable, with a welding torch and a workpiece
clamped on the table (:func:`robotcell.studies.demo.demo_cells`). The *true* cell (what the
virtual hardware really is) differs from the *nominal* cell (what the drawings say) by the errors a real cell has: a tool a few millimetres
off its CAD value, a robot base not quite aligned with its track, a turntable placed centimetres
from its layout position, a workpiece clamped off its nominal place. The demo

1. writes the nominal cell file and simulates every touch-up procedure in the true cell
   (joint values within every limit, touch-up error ``noise``);
2. calibrates the cell in order, each step with the cell as calibrated so far, by the library
   calls of :mod:`robotcell.cell.calibrate` that the commands a technician types (``robotcell calibrate
   tcp``, ``track``, ``turntable``, ``workpiece`` with ``--cell``) make, printing each command;
   the library never drives the command line, which keeps the import direction cli -> library;
3. compares every calibrated value with the truth, in units of its reported 1-sigma;
4. writes an HTML report per calibration and the controller exports (KUKA, ABB, FANUC,
   YASKAWA);
5. writes a KUKA program of a seam on the workpiece through the calibrated cell, the track
   following the seam, as ``robotcell program write`` does (``program/seam.src``);
6. writes the interactive 3D views of the calibrated cell (``cell.html``) and of the program,
   the arm at each of its points (``program.html``, as ``robotcell view --program`` does).
7. identifies a virtual arm that is not quite its drawing from simulated laser-tracker data and
   filters a path through it (:mod:`robotcell.demo.accuracy`), printing how far the real
   arm misses the path without filtering and with it;
8. plans the ISO 9283 acceptance test in the calibrated cell, simulates the tracker's log with
   the controller computing in the nominal and in the calibrated cell, and prints both verdicts
   (:mod:`robotcell.demo.acceptance`; the report ``iso9283.html``).
"""

from __future__ import annotations

import json
import math
import shlex
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.sigmaparts import PARTS, sigma_basis
from robotcell.cell import Cell, Provenance
from robotcell.cell import calibrate as cellcal
from robotcell.cell.history import backups
from robotcell.demo.acceptance import acceptance_step
from robotcell.demo.accuracy import accuracy_step
from robotcell.errors import InputError, RobotcellError
from robotcell.export import EXPORT_FORMATS, export_cell
from robotcell.io.tables import read_csv, write_csv
from robotcell.kinematics.transforms import make_pose, rot_y
from robotcell.programs import write_program
from robotcell.report import verdict, write_report
from robotcell.studies.demo import DEMO_NOISE, demo_cells, seam_rows
from robotcell.studies.plan import pose_error
from robotcell.studies.simulate import simulate
from robotcell.view.cellscene import cell_figure
from robotcell.view.plot import write_html
from robotcell.view.program import write_program_view

__all__ = ["DEMO_NOISE", "EXPORT_FILES", "VIEW_TABLE", "Comparison", "comparison_table",
           "export_file", "reported_sigma", "run_demo"]


def export_file(fmt: str) -> str:
    """The name the demo gives the export of a controller: ``kuka_config.dat``, ..."""
    return f"{fmt}_{EXPORT_FORMATS[fmt].export_name}"


#: Export file names of the controllers robotcell registers itself.
EXPORT_FILES = {fmt: export_file(fmt) for fmt in EXPORT_FORMATS}


@dataclass
class Comparison:
    """A calibrated pose beside the truth.

    Attributes
    ----------
    item : str
        What was calibrated (``tool torch``, ``track KL1500``, ...).
    calibrated, truth : ndarray, shape (4, 4)
        The poses (m).
    position_error : float
        Distance between the calibrated and the true origin (m).
    rotation_error : float
        Angle between the calibrated and the true orientation (rad).
    position_sigma : float
        Length of the reported 1-sigma position vector (m).
    rotation_sigma : float
        Length of the reported 1-sigma rotation vector (rad).
    basis : str
        What the reported 1-sigma is relative to and made of
        (:func:`~robotcell.calibration.sigmaparts.sigma_basis`).
    """

    item: str
    calibrated: NDArray[np.float64]
    truth: NDArray[np.float64]
    position_error: float
    rotation_error: float
    position_sigma: float
    rotation_sigma: float
    basis: str = ""


def reported_sigma(result: dict[str, Any], key: str) -> tuple[float, float]:
    """Lengths of the 1-sigma position (m) and rotation (rad) vectors a result's JSON reports
    for pose ``key`` (NaN where it reports none)."""
    s = result.get("sigma") or {}
    p = s.get(key + "_position_mm")
    r = s.get(key + "_rotation_deg")
    return (float(np.linalg.norm(p)) * 1e-3 if p is not None else math.nan,
            math.radians(float(np.linalg.norm(r))) if r is not None else math.nan)


def _basis(result: dict[str, Any], key: str) -> str:
    """What the 1-sigma of ``key`` in a result's JSON is relative to and made of."""
    parts = (result.get("sigma_parts") or {}).get(key) or {}
    return sigma_basis((result.get("sigma_relative_to") or {}).get(key, key.split("_")[1]),
                       [p for p in PARTS if p in parts])


def run_demo(folder: str | Path, noise: float = DEMO_NOISE, seed: int = 1,
             echo: Callable[[str], None] = print) -> list[Comparison]:
    """Run the demo, writing every file into ``folder``.

    Parameters
    ----------
    folder : str or Path
        Output folder (created; existing demo files are overwritten).
    noise : float
        Touch-up error (m, 1-sigma per coordinate).
    seed : int
        Seed of the touch-up errors.
    echo : callable
        Receives each line of the narrative.

    Returns
    -------
    list of Comparison
        Tool, track, turntable and workpiece against the truth.
    """
    t_start = time.perf_counter()
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    truth, nominal = demo_cells()
    cell_file = out / "cell.yaml"
    truth_file = out / "truth.yaml"
    for stale in (cell_file, truth_file, *(b for _, b in backups(cell_file)),
                  *(b for _, b in backups(truth_file))):  # a run before in the same folder
        stale.unlink(missing_ok=True)
    nominal.save(cell_file)
    truth.save(truth_file)
    echo(f"virtual cell: KUKA KR 16 on a 6 m track (KL1500) beside a turntable (DKP_400), "
         f"tool 'torch', workpiece 'part'\n  nominal cell (the drawings): {cell_file}\n"
         f"  true cell (the virtual hardware): {truth_file}\n"
         f"  touch-up error {noise * 1e3:g} mm (1-sigma per coordinate), simulated and stated "
         f"to every calibration (--sigma {noise * 1e3:g}), seed {seed}\n")
    rng = np.random.default_rng(seed)
    # procedure, options of the command, keywords of the library call, of the simulation
    steps: list[tuple[str, list[str], dict[str, Any], dict[str, Any]]] = [
        # Enough touches for the verdict to see a wrong one (docs/calibration.md, "Verdict").
        ("tcp", ["--name", "torch"], {"name": "torch"}, {"tool": "torch", "touches": 6}),
        ("track", ["--tool", "torch"], {"tool": "torch"}, {"tool": "torch"}),
        ("turntable", ["--tool", "torch"], {"tool": "torch"}, {"tool": "torch"}),
        ("workpiece", ["--tool", "torch", "--name", "part", "--turntable", "turntable.json"],
         {"tool": "torch", "name": "part"}, {"tool": "torch", "frame": "part", "repeats": 3}),
    ]
    results: dict[str, dict[str, Any]] = {}
    cell = Cell.load(cell_file)
    turntable: cellcal.TurntablePose | None = None
    for procedure, extra, kw, design in steps:
        touches = simulate(truth, procedure, noise=noise, seed=rng, **design)
        csv_path = out / f"{procedure}.csv"
        touches.write_csv(csv_path)
        args = (["calibrate", procedure, str(csv_path), "--cell", str(cell_file), "--json",
                 "--sigma", f"{noise * 1e3:g}"]
                + [str(out / a) if a.endswith(".json") else a for a in extra] + touches.options)
        echo(f"{procedure}: simulated {len(touches.q)} touches -> {csv_path.name}")
        echo("  $ robotcell " + shlex.join(args))
        if procedure == "workpiece":
            kw["turntable"] = turntable
        calibrate = cellcal.procedure(procedure).calibrate
        done = calibrate(cell, read_csv(csv_path), source=str(csv_path), cell_label=str(cell_file),
                         file=csv_path, sigma=noise, **kw, **touches.keywords())
        verdict = done.result.verdict
        if verdict.level == "poor":  # the command refuses to write it (exit 3); so does the demo
            raise InputError(f"{procedure}: poor calibration, nothing written: "
                             f"{'; '.join(verdict.reasons)}; try a smaller noise")
        if procedure == "turntable":
            turntable = cellcal.TurntablePose.from_result(done.result, str(out / "turntable.json"))
        done.cell.save(cell_file)
        cell = Cell.load(cell_file)  # the next command reads the file, rounded as written
        results[procedure] = done.result.to_json()
        (out / f"{procedure}.json").write_text(json.dumps(results[procedure], indent=2) + "\n",
                                               encoding="utf-8")
        r = results[procedure]
        echo(f"  RMS {r['rms_mm']:.3f} mm, max {r['max_mm']:.3f} mm, condition "
             f"{r['condition']:.1f}; cell file updated\n  {verdict.line()}")
    calibrated = Cell.load(cell_file)  # as the file holds it (rounded to 1e-10 mm, deg)
    comparisons = _compare(calibrated, truth, results)
    echo("\ncalibrated vs true cell (error, and error / reported 1-sigma):")
    echo(comparison_table(comparisons))
    echo("each reported 1-sigma:\n" + "\n".join(f"  {c.item}: {c.basis}" for c in comparisons))
    _write_outputs(out, calibrated, results, echo)
    accuracy_step(out, seed, echo)
    acceptance_step(out, truth, nominal, calibrated, seed, echo)
    echo(f"\ndone in {time.perf_counter() - t_start:.1f} s; everything is in {out}/")
    return comparisons


def _compare(calibrated: Cell, truth: Cell,
             results: dict[str, dict[str, Any]]) -> list[Comparison]:
    assert calibrated.track and truth.track and calibrated.turntable and truth.turntable
    rows = [
        ("tool torch", calibrated.tools["torch"].T_F_TCP, truth.tools["torch"].T_F_TCP,
         results["tcp"], "T_F_TCP"),
        ("track KL1500 (T_L_R0)", calibrated.track.T_L_R0, truth.track.T_L_R0, results["track"],
         "T_L_R"),
        ("turntable DKP_400 (T_world_B)", calibrated.turntable.T_parent_B,
         truth.turntable.T_parent_B, results["turntable"], "T_world_B"),
        ("workpiece part (T_B_W)", calibrated.frames["part"].pose, truth.frames["part"].pose,
         results["workpiece"], "T_B_W"),
    ]
    out = []
    for item, est, true, res, key in rows:
        dp, dr = pose_error(est, true)
        sp, sr = reported_sigma(res, key)
        out.append(Comparison(item, est, true, dp, dr, sp, sr, _basis(res, key)))
    return out


def comparison_table(rows: list[Comparison]) -> str:
    """The calibrated and the true pose of each :class:`Comparison` (KUKA X, Y, Z mm, A, B, C
    deg) with the errors in mm, deg and units of the reported 1-sigma."""
    from robotcell.io.poseformats import pose_to_vendor
    from robotcell.io.tables import format_table

    body = []
    for c in rows:
        est = pose_to_vendor(c.calibrated, "kuka")
        tru = pose_to_vendor(c.truth, "kuka")
        body.append([c.item, "calibrated", *(f"{v:.3f}" for v in est), "", ""])
        dp = f"{c.position_error * 1e3:.3f} mm = {c.position_error / c.position_sigma:.1f} sigma"
        dr = (f"{math.degrees(c.rotation_error):.4f} deg = "
              f"{c.rotation_error / c.rotation_sigma:.1f} sigma")
        body.append(["", "true", *(f"{v:.3f}" for v in tru), dp, dr])
    return format_table(["item", "", "X mm", "Y mm", "Z mm", "A deg", "B deg", "C deg",
                         "position error", "rotation error"], body)


def _write_outputs(out: Path, cell: Cell, results: dict[str, dict[str, Any]],
                   echo: Callable[[str], None]) -> None:
    echo("\nreports:")
    for procedure, res in results.items():
        page = write_report(res, out / f"report_{procedure}.html")[0]
        grade, _ = verdict(res)
        echo(f"  {page.name}: {grade.upper()}")
    echo("controller exports (paste into the controller):")
    for fmt in EXPORT_FORMATS:
        try:
            text = export_cell(cell, fmt)
        except RobotcellError as exc:
            echo(f"  {fmt}: not written: {exc}")
            continue
        path = out / export_file(fmt)
        path.write_text(text, encoding="utf-8")
        echo(f"  {path.name}")
    page = _write_view(out, cell)
    echo(f"3D view of the calibrated cell (open it in a browser): {page.name}")
    prov = [f"{name}: {p.source} (rms {p.rms_mm:.3f} mm)" for name, p in _provenances(cell)]
    echo("cell file provenance: " + "; ".join(prov))
    seam = out / "seam.csv"
    write_csv(seam, ["x", "y", "z", "a", "b", "c", "table"], seam_rows(), 3)
    echo("robot program (a seam on the part, through the calibrated cell):")
    echo("  $ robotcell program write seam.csv --cell cell.yaml --tool torch --frame part "
         "--format kuka -o program")
    result = write_program(seam, cell, "torch", "part", "kuka", out / "program", name="seam",
                           inputs=(out / "cell.yaml",))
    echo(f"  {', '.join(Path(f).relative_to(out).as_posix() for f in result.files)}: "
         f"{len(result.programs[0].points)} points, track from {result.track[0] * 1e3:.0f} to "
         f"{result.track[-1] * 1e3:.0f} mm")
    echo("  $ robotcell view cell.yaml --program program/seam.src -o program.html")
    made = write_program_view(cell, result.files[0], out / "program.html")
    echo(f"  {made.path.name}: the 3D view of the program, the arm at each of its "
         f"{len(made.report.points)} points (open it in a browser)")


#: Table angle of the demo's 3D view (rad).
VIEW_TABLE = math.radians(30.0)


def _write_view(out: Path, cell: Cell) -> Path:
    """``cell.html``: the cell with the torch 50 mm above the part's origin, pointing down, at
    table angle :data:`VIEW_TABLE` (the first valid IK solution; the track chosen by the IK)."""
    target = make_pose(rot_y(math.pi), [0.0, 0.0, 0.05])
    sol = cell.ik(target, frame="part", tool="torch", table=VIEW_TABLE)
    q = sol.q[sol.valid][0]
    fig = cell_figure(cell, q, float(sol.track), VIEW_TABLE)
    return write_html(fig, out / "cell.html", title=f"{cell.name}: robotcell view")


def _provenances(cell: Cell) -> list[tuple[str, Provenance]]:
    out: list[tuple[str, Provenance]] = [(f"tool {k}", t.provenance) for k, t in cell.tools.items()]
    if cell.track is not None:
        out.append((f"track {cell.track.name}", cell.track.provenance))
    if cell.turntable is not None:
        out.append((f"turntable {cell.turntable.name}", cell.turntable.provenance))
    out += [(f"frame {k}", f.provenance) for k, f in cell.frames.items()]
    return [(n, p) for n, p in out if p.rms_mm is not None]
