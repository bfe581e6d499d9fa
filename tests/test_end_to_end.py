"""End to end: simulate -> calibrate (--cell) -> export -> parse back recovers the virtual cell.

Two cells: the demo's KR 16 on a linear track beside a turntable (run through ``robotcell
demo``), and a KR 16 on the floor beside a turntable (run command by command, as a technician
would). Every exported pose, read back from the controller text, must match the true cell within
4 times the 1-sigma the calibrations reported (plus the export's rounding).
"""

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from view_helpers import figure_from_page, triads

from robotcell import load_robot, make_pose
from robotcell.cell import Cell, Frame, Tool, Turntable
from robotcell.controllers.data import collect, flatten_table
from robotcell.demo.walkthrough import EXPORT_FILES, VIEW_TABLE
from robotcell.export import EXPORT_FORMATS, parse_export
from robotcell.io.poseformats import pose_from_vendor
from robotcell.programs.check import check_program_file
from robotcell.studies.demo import demo_cells
from robotcell.studies.plan import pose_error

#: Controller reference frame of each export (see docs/export.md).
REFERENCE = {"kuka": "world", "abb": "world", "fanuc": "robot", "yaskawa": "robot"}
#: Export rounding: 1e-6 mm and 1e-6 deg are far below; allow for it explicitly.
ROUNDING_M, ROUNDING_RAD = 1e-8, 1e-8


def pose_sigma(result):
    """Lengths of the 1-sigma position (m) and rotation (rad) vectors of a result's pose."""
    s = result["sigma"]
    pos = next(v for k, v in s.items() if k.endswith("_position_mm"))
    rot = next(v for k, v in s.items() if k.endswith("_rotation_deg"))
    return float(np.linalg.norm(pos)) * 1e-3, math.radians(float(np.linalg.norm(rot)))


def assert_within(est, true, sigma_p, sigma_r, what):
    dp, dr = pose_error(est, true)
    assert dp <= 4 * sigma_p + ROUNDING_M, f"{what}: position error {dp * 1e3:.4f} mm > 4 sigma"
    assert dr <= 4 * sigma_r + ROUNDING_RAD, f"{what}: rotation error {math.degrees(dr):.5f} deg"


def combine(*parts):
    """Combined 1-sigma of independent contributions (position m, rotation rad, lever m)."""
    sp = math.sqrt(sum((p ** 2 + (lever * r) ** 2) for p, r, lever in parts))
    sr = math.sqrt(sum(r ** 2 for _, r, _ in parts))
    return sp, sr


def check_exports(cell_file, truth, results, tmp_path, capsys):
    """Export the calibrated cell in every format, parse it back, compare with the truth.

    KUKA and ABB hold frames on the turntable relative to the table and the table root in the
    world; FANUC and YASKAWA hold every frame, the table root included, as a fixed user frame
    at the robot base (track and table at 0), which adds the uncertainty of the table and of
    the track's rotation over the lever arm from the robot.
    """
    tool_s = pose_sigma(results["tcp"])
    table_s = pose_sigma(results["turntable"])
    part_s = pose_sigma(results["workpiece"])
    track_s = pose_sigma(results["track"]) if "track" in results else (0.0, 0.0)
    for fmt in EXPORT_FORMATS:
        out = tmp_path / f"export_{fmt}.txt"
        code, _, err = run(capsys, "export", "--cell", cell_file, "--format", fmt, "-o", out)
        if fmt == "ur":  # a UR export holds no track or turntable: refused, nothing written
            assert code == 2 and "hold no external axes" in err and not out.exists()
            continue
        assert code == 0, err
        got = parse_export(out.read_text(encoding="utf-8"), fmt)
        want = collect(truth, REFERENCE[fmt])
        at_robot = REFERENCE[fmt] == "robot"
        for g, w in zip(got.tools, want.tools, strict=True):
            assert g.name == w.name and g.number == w.number
            assert_within(g.pose, w.pose, *tool_s, f"{fmt} tool {g.name}")

        if at_robot:  # every frame fixed, the table root among them
            frames = {s.name: s for s in got.frames}
            assert set(frames) == {s.name for s in flatten_table(want)}
            for w in flatten_table(want):
                if w.name == want.turntable.name:
                    own = (table_s[0], table_s[1], 0.0)
                elif w.name == "part":
                    lever = float(np.linalg.norm(want.frames[0].pose[:3, 3]))
                    own = combine((part_s[0], part_s[1], 0.0), (table_s[0], table_s[1], lever))
                    own = (own[0], own[1], 0.0)
                else:
                    own = (*pose_sigma(results[w.name]), 0.0)
                # Seen from the robot: plus the track's rotation over the lever arm.
                lever = float(np.linalg.norm(w.pose[:3, 3]))
                sig = combine(own, (track_s[0], track_s[1], lever))
                assert_within(frames[w.name].pose, w.pose, *sig, f"{fmt} {w.name}")
        else:
            assert_within(got.turntable.pose, want.turntable.pose, *table_s, f"{fmt} turntable")
            frames = {s.name: s for s in got.frames}
            for w in want.frames:
                g = frames[w.name]
                assert g.on_table == w.on_table
                sig = part_s if w.on_table else pose_sigma(results[w.name])
                assert_within(g.pose, w.pose, *sig, f"{fmt} frame {w.name}")
            if truth.track is not None:
                assert_within(got.track_robot.pose, want.track_robot.pose, *track_s,
                              f"{fmt} track")
                assert_within(got.track_root.pose, want.track_root.pose, 0.0, 0.0,
                              f"{fmt} track root")


def test_demo_track_cell_end_to_end(tmp_path, capsys):
    """`robotcell demo`: the track-and-turntable cell, every file written (its time is measured
    by benchmarks/, not here)."""
    code, out, err = run(capsys, "demo", "-o", tmp_path)
    assert code == 0, err
    assert "calibrated vs true cell" in out
    # it states the accuracy it simulates and calibrates at, and what each 1-sigma holds
    assert ("touch-up error 0.1 mm (1-sigma per coordinate), simulated and stated to every "
            "calibration (--sigma 0.1)") in out and out.count("--sigma 0.1 ") == 4
    assert "(noise 0.02 mm, 1-sigma per coordinate)" in out and "--accuracy 0.02 " in out
    assert "  tool torch: relative to the flange, from its own touches only" in out
    assert "  ur: not written: Universal Robots programs and exports hold no external axes" in out
    assert ("  turntable DKP_400 (T_world_B): relative to frame 'world', from its own touches "
            "and inherited errors (recorded)") in out
    assert ("relative to the measuring device's frame, from the arm's identification only, not "
            "the tool's and frames' calibrations)") in out
    for name in ["cell.yaml", *(f"cell.yaml.{i}.bak" for i in range(1, 5)), "truth.yaml",
                 *(f for fmt, f in EXPORT_FILES.items() if fmt != "ur"),
                 *(f"{p}.{ext}" for p in ("tcp", "track", "turntable", "workpiece")
                   for ext in ("csv", "json")),
                 *(f"report_{p}.html" for p in ("tcp", "track", "turntable", "workpiece")),
                 "cell.html", "program.html"]:
        assert (tmp_path / name).is_file(), name
        assert name.endswith(".html") <= ((tmp_path / name).stat().st_size < 5_000_000), name
    # the demo's program of a seam on the part is good in the calibrated cell
    assert "robot program" in out
    report = check_program_file(tmp_path / "program" / "seam.src",
                                Cell.load(tmp_path / "cell.yaml"))
    assert report.good and len(report.points) == 36
    # and its view has the arm at each of them, named as the program names them
    program = figure_from_page((tmp_path / "program.html").read_text(encoding="utf-8"))
    assert [s["label"] for s in program["layout"]["sliders"][0]["steps"]] == [
        p.name for p in report.points]
    # the last step identifies a virtual arm and filters a path: both errors are printed
    m = re.search(r"([0-9.]+) mm RMS from it without filtering, ([0-9.]+) mm filtered", out)
    assert m and float(m.group(1)) > 0.5 and float(m.group(2)) < 0.05, out[-600:]
    assert Cell.load(tmp_path / "accuracy" / "cell.yaml").identified.provenance.source == "identify"
    assert (tmp_path / "accuracy" / "commanded.csv").is_file()
    # it ends with the acceptance test: the nominal cell fails, the calibrated one passes
    assert re.search(r"nominal cell: verdict: FAIL: AP_p [0-9.]+ mm \(P\d\) > 0.5 mm", out)
    m = re.search(r"calibrated cell: verdict: PASS: AP_p ([0-9.]+) mm", out)
    assert m and float(m.group(1)) < 0.3, out[-900:]
    assert "iso9283.html: the acceptance report" in out.rstrip().splitlines()[-3]
    for name in ("plan.csv", "nominal.csv", "calibrated.csv", "kuka/ISOPOSES.src",
                 "kuka/ISOPATHS.src"):
        assert (tmp_path / "iso9283" / name).is_file(), name
    assert "verdict: PASS" in (tmp_path / "iso9283.html").read_text(encoding="utf-8")
    truth, nominal = demo_cells()
    cell = Cell.load(tmp_path / "cell.yaml")
    # The 3D view shows the calibrated cell: the torch 50 mm above the part's origin.
    view = figure_from_page((tmp_path / "cell.html").read_text(encoding="utf-8"))
    above = cell.frame_pose("part", 0.0, VIEW_TABLE) @ make_pose(np.eye(3), [0, 0, 0.05])
    np.testing.assert_allclose(triads(view, "tools")["torch"][0], above[:3, 3] * 1e3, atol=1e-6)
    # Every calibrated item carries its provenance.
    assert cell.tools["torch"].provenance.source == "tcp"
    assert cell.track.provenance.source == "track"
    assert cell.turntable.provenance.source == "turntable"
    assert cell.frames["part"].provenance.source == "workpiece"
    # The calibration moved every item from the nominal towards the true value.
    for est, nom, true in [(cell.tools["torch"].T_F_TCP, nominal.tools["torch"].T_F_TCP,
                            truth.tools["torch"].T_F_TCP),
                           (cell.turntable.T_parent_B, nominal.turntable.T_parent_B,
                            truth.turntable.T_parent_B)]:
        assert pose_error(est, true)[0] < 0.2 * pose_error(nom, true)[0]
    results = {p: json.loads((tmp_path / f"{p}.json").read_text()) for p in
               ("tcp", "track", "turntable", "workpiece")}
    scale_sigma = results["track"]["sigma"]["scale"]
    assert abs(cell.track.scale - truth.track.scale) <= 4 * scale_sigma
    check_exports(tmp_path / "cell.yaml", truth, results, tmp_path, capsys)
    # Each calibration recorded its touch file, so the whole cell can be fitted again in one go.
    assert Path(cell.tools["torch"].provenance.measurements) == tmp_path / "tcp.csv"
    code, out, err = run(capsys, "calibrate", "cell", "--cell", tmp_path / "cell.yaml")
    assert code == 0 and "4 calibrations fitted together" in out, err


def turntable_cells():
    """A KR 16 on the floor beside a turntable: the truth and the nominal cell."""
    robot = load_robot("kuka_kr16")

    def cell(tool, table, part, fixture):
        return Cell(robot=robot, robot_model="kuka_kr16", name="kr16_turntable",
                    T_world_R=pose_from_vendor([0, 0, 400, 0, 0, 0], "kuka"),
                    turntable=Turntable(pose_from_vendor(table, "kuka"), lower=-2 * math.pi,
                                        upper=2 * math.pi, name="DKP_400"),
                    tools={"torch": Tool(pose_from_vendor(tool, "kuka"), number=1, mass=3.2)},
                    frames={"fixture": Frame(pose_from_vendor(fixture, "kuka"), number=1),
                            "part": Frame(pose_from_vendor(part, "kuka"), parent="turntable",
                                          number=2)})

    truth = cell([311.2, 1.8, 96.4, -0.4, 44.7, 0.5], [1302.5, 701.8, 448.9, 0.4, -0.15, 0.1],
                 [101.9, 49.2, 80.7, 30.6, 0.05, 0.1], [1000.0, -800.0, 300.0, -20.0, 0.2, -0.1])
    nominal = cell([312.5, 0, 95, 0, 45, 0], [1300, 700, 450, 0, 0, 0], [100, 50, 80, 30, 0, 0],
                   [1000, -800, 300, -20, 0, 0])
    return truth, nominal


def test_turntable_cell_command_by_command(tmp_path, capsys):
    truth, nominal = turntable_cells()
    truth_file, cell_file = tmp_path / "truth.yaml", tmp_path / "cell.yaml"
    truth.save(truth_file)
    nominal.save(cell_file)
    steps = [
        ("tcp", ["--tool", "torch"], ["--name", "torch"]),
        ("turntable", ["--tool", "torch"], ["--tool", "torch", "--height=-50"]),
        ("workpiece", ["--tool", "torch", "--frame", "part"],
         ["--tool", "torch", "--name", "part", "--turntable", tmp_path / "turntable.json"]),
        ("frame", ["--tool", "torch", "--frame", "fixture"],
         ["--tool", "torch", "--name", "fixture"]),
    ]
    results = {}
    for seed, (procedure, sim_args, cal_args) in enumerate(steps):
        csv = tmp_path / f"{procedure}.csv"
        code, _, err = run(capsys, "simulate", procedure, "--cell", truth_file, "--noise", "0.1",
                           "--seed", seed, "-o", csv, *sim_args)
        assert code == 0, err
        assert f"robotcell calibrate {procedure} {csv}" in err
        code, out, err = run(capsys, "calibrate", procedure, csv, "--cell", cell_file, "--json",
                             *cal_args)
        assert code == 0, err
        (tmp_path / f"{procedure}.json").write_text(out)
        results[procedure] = json.loads(out)
    results["fixture"] = results["frame"]
    check_exports(cell_file, truth, results, tmp_path, capsys)


def test_a_poor_demo_names_the_noise_parameter_in_python_and_the_option_in_the_cli(
        tmp_path, capsys, monkeypatch):
    """The demo states the accuracy it simulates; touches worse than that (5 mm) are poor."""
    from robotcell.demo import walkthrough as demo
    from robotcell.errors import InputError
    from robotcell.studies.simulate import simulate

    monkeypatch.setattr(demo, "simulate", lambda truth, procedure, noise, **kw: simulate(
        truth, procedure, noise=5e-3, **kw))
    with pytest.raises(InputError, match="tcp: poor calibration, nothing written: .*; try a "
                                         "smaller noise$"):
        demo.run_demo(tmp_path / "lib", noise=1e-4, echo=lambda *a, **k: None)
    code, _, err = run(capsys, "demo", "-o", tmp_path / "cli", "--noise", "0.1")
    assert code == 2 and err.rstrip().endswith("; try a smaller --noise")
