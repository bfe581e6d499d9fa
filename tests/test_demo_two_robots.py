"""`robotcell demo --robots 2`: a cell of two robots sharing a positioner commissioned from
simulated touches, every result printed beside the truth within its reported sigma, and both
robots' calibrations of the positioner compared and fitted together."""

import re
from pathlib import Path

from cli_helpers import run

from robotcell.cell import Cell
from robotcell.demo.tworobots import run_two_robot_demo

ROOT = Path(__file__).resolve().parents[1]

FILES = ["cell.yaml", "truth.yaml", "tcp_kuka.csv", "tcp_abb.csv", "track_kuka.csv",
         "robot_to_robot_kuka.csv", "robot_to_robot_abb.csv", "positioner_kuka.csv",
         "positioner_abb.csv", "report_tcp_kuka.html", "report_tcp_abb.html",
         "report_track_kuka.html", "report_robot_to_robot.html", "report_positioner_kuka.html",
         "report_shared_positioner.html", "cell.html"]


def test_two_robot_demo_prints_every_result_within_4_sigma_of_the_truth(tmp_path, capsys):
    code, out, err = run(capsys, "demo", "--robots", "2", "-o", tmp_path, "--seed", "3")
    assert code == 0, err
    assert "touch-up error 0.1 mm (1-sigma per coordinate)" in out
    for name in FILES:
        assert (tmp_path / name).stat().st_size > 0, name
    # tools of both robots, the track, the ABB's base and the positioner's root, then the ABB's
    # base and the positioner's root of the fit of all touches: position and rotation each
    sigmas = [float(v) for v in re.findall(r"= (-?[\d.]+) sigma", out)]
    assert len(sigmas) == 14, out
    assert max(sigmas) <= 4.0, out
    # the ABB's calibration of the positioner against the KUKA's, component by component
    assert "kuka's and abb's calibrations of the positioner agree within 3 sigma" in out
    assert "$ robotcell calibrate shared-positioner" in out
    ratios = [float(v) for v in re.findall(r"(?:mm|deg) +(-?\d+\.\d)\n", out)]
    assert len(ratios) == 8 and max(map(abs, ratios)) <= 4.0, out
    cell = Cell.load(tmp_path / "cell.yaml")
    assert cell.robots["abb"].base_provenance.source == "robot-to-robot"
    assert cell.robots["kuka"].tools["torch"].provenance.source == "tcp"
    assert cell.robots["abb"].tools["torch"].provenance.source == "tcp"
    assert cell.turntable.provenance.source == "positioner"
    assert "3D view of the calibrated cell, both robots" in out


def test_the_library_call_returns_every_pose_within_4_sigma_of_the_truth(tmp_path):
    lines: list[str] = []
    rows = run_two_robot_demo(tmp_path, seed=5, echo=lines.append)
    assert [r.item.split(" (")[0] for r in rows] == [
        "tool torch of kuka", "tool torch of abb", "track KL1500 of kuka", "base of abb in kuka",
        "positioner DKP_2 root", "base of abb in kuka, all touches",
        "positioner axes in kuka, all touches"]
    for r in rows:
        assert 0 < r.position_sigma < 1e-3 and 0 < r.rotation_sigma < 1e-2, r.item
        assert r.position_error <= 4 * r.position_sigma, r.item
        assert r.rotation_error <= 4 * r.rotation_sigma, r.item
    assert any("everything is in" in line for line in lines)
    # the fit of all touches is at least as good as the link alone
    assert rows[5].position_sigma <= rows[3].position_sigma
    assert rows[5].rotation_sigma <= rows[3].rotation_sigma


def test_the_demo_cell_is_the_example_cell():
    """The demo needs no files: it carries a copy of the example, kept equal to it."""
    packaged = ROOT / "src" / "robotcell" / "demo" / "two_robots_cell.yaml"
    example = ROOT / "examples" / "cell_two_robots_positioner.yaml"
    assert packaged.read_bytes() == example.read_bytes()


def test_a_third_robot_is_refused(tmp_path, capsys):
    code, _, err = run(capsys, "demo", "--robots", "3", "-o", tmp_path / "d")
    assert code == 2 and "'--robots': 3 is not in the range 1<=x<=2" in err
    assert not (tmp_path / "d").exists()
