"""The command line on a cell of several robots: --robot-name says which robot a command acts
for; an unknown or missing name exits 2, lists the robots and writes nothing."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import pose_to_vendor
from robotcell.cell import Cell
from robotcell.studies.simulate import simulate

ROOT = Path(__file__).resolve().parents[1]
TWO = ROOT / "examples" / "cell_two_robots_positioner.yaml"


@pytest.fixture
def two(tmp_path):
    path = tmp_path / "cell.yaml"
    shutil.copy(TWO, path)
    return path


def _alone(path: Path, name: str, out: Path) -> Path:
    """Robot ``name`` of the cell alone in a one-robot cell file at its base."""
    cell = Cell.load(path)
    unit = cell.robots[name]
    frames = {k: f for k, f in cell.frames.items() if f.parent in ("world", "turntable")}
    Cell(robot=unit.robot, robot_model=unit.model, T_world_R=unit.T_world_R, track=unit.track,
         turntable=cell.turntable, tools=dict(unit.tools), frames=frames, name=cell.name).save(out)
    return out


def test_ik_of_a_named_robot_prints_what_the_robot_alone_prints(capsys, two, tmp_path):
    alone = _alone(two, "abb", tmp_path / "abb.yaml")
    cell = Cell.load(two)
    T = cell.fk(np.radians([10, 20, 10, 0, 40, 0]), table=[0.2, 0.5], tool="torch", frame="part",
                robot="abb")
    pose = ",".join(f"{v:.6f}" for v in pose_to_vendor(T, "kuka"))
    args = ["ik", "--frame", "part", "--tool", "torch", "--table", "11.459156,28.647890",
            "--pose", pose]
    code, out, err = run(capsys, *args, "--cell", two, "--robot-name", "abb")
    assert code == 0, err
    code1, out1, _ = run(capsys, *args, "--cell", alone)
    assert code1 == 0 and out == out1


@pytest.mark.parametrize("command", [
    ["ik", "--pose", "1000,0,1000,0,90,0"],
    ["fk", "--joints", "0,-90,90,0,0,0"],
    ["cell", "show"],
    ["reach", str(ROOT / "examples" / "seam_part.csv"), "--frame", "part", "--table", "0,0"],
])
def test_unknown_robot_name_exits_2_listing_the_robots(capsys, two, command):
    where = ["--cell", two] if command[0] != "cell" else [two]
    code, _, err = run(capsys, *command, *where, "--robot-name", "fanuc")
    assert code == 2
    assert "no robot 'fanuc'; its robots: kuka, abb" in err
    assert "Traceback" not in err


@pytest.mark.parametrize("command", [
    ["ik", "--pose", "1000,0,1000,0,90,0"],
    ["fk", "--joints", "0,-90,90,0,0,0"],
])
def test_cell_of_several_robots_without_robot_name_exits_2(capsys, two, command):
    code, _, err = run(capsys, *command, "--cell", two)
    assert code == 2
    assert "has 2 robots (kuka, abb): say which one with --robot-name NAME" in err


def test_cell_show_lists_every_robot_and_the_shared_parts(capsys, two):
    code, out, err = run(capsys, "cell", "show", two)
    assert code == 0, err
    assert "2 robots (kuka, abb)" in out
    assert "robot kuka kuka_kr16" in out and "robot abb abb_irb2400" in out
    assert "shared by the robots:" in out and "frame (kuka)" in out
    code, out, _ = run(capsys, "cell", "show", two, "--robot-name", "abb")
    assert code == 0 and "robot abb abb_irb2400" in out and "kuka_kr16" not in out


def test_calibrate_tcp_writes_the_tool_under_the_named_robot(capsys, two, tmp_path):
    touches = tmp_path / "tcp.csv"
    simulate(Cell.load(two).for_robot("abb"), "tcp", seed=1, tool="pointer").write_csv(touches)
    before = Cell.load(two)
    code, _, err = run(capsys, "calibrate", "tcp", touches, "--cell", two, "--robot-name", "abb",
                       "--name", "pointer")
    assert code == 0, err
    after = Cell.load(two)
    new, old = after.robots["abb"].tools["pointer"], before.robots["abb"].tools["pointer"]
    assert new.provenance.source == "tcp"
    assert np.allclose(new.T_F_TCP[:3, 3], old.T_F_TCP[:3, 3], atol=1e-3)
    assert "pointer" not in after.robots["kuka"].tools
    text, was = two.read_text().splitlines(), TWO.read_text().splitlines()
    assert text[:text.index("  abb:")] == was[:was.index("  abb:")]  # the KUKA's lines unchanged
    code, out, _ = run(capsys, "cell", "history", two)
    assert code == 0 and "abb: tool pointer (tcp" in out.splitlines()[-1]


def test_calibrate_with_an_unknown_robot_name_writes_nothing(capsys, two, tmp_path):
    touches = tmp_path / "tcp.csv"
    simulate(Cell.load(two).for_robot("abb"), "tcp", seed=1, tool="pointer").write_csv(touches)
    code, _, err = run(capsys, "calibrate", "tcp", touches, "--cell", two, "--robot-name",
                       "fanuc", "--name", "pointer")
    assert code == 2
    assert "no robot 'fanuc'; its robots: kuka, abb" in err
    assert two.read_bytes() == TWO.read_bytes()
    assert not list(tmp_path.glob("*.bak"))


def test_view_draws_every_robot_and_needs_a_name_for_joints(capsys, two, tmp_path):
    code, _, err = run(capsys, "view", two, "-o", tmp_path / "all.html")
    assert code == 0, err
    page = (tmp_path / "all.html").read_text()
    assert "kuka: robot kuka_kr16" in page and "abb: robot abb_irb2400" in page
    code, _, err = run(capsys, "view", two, "--joints", "0,10,10,0,30,0", "-o",
                       tmp_path / "one.html")
    assert code == 2 and "say which one with --robot-name NAME" in err
    assert not (tmp_path / "one.html").exists()
    code, _, err = run(capsys, "view", two, "--robot-name", "abb", "--joints", "0,10,10,0,30,0",
                       "-o", tmp_path / "one.html")
    assert code == 0, err


def test_export_urdf_writes_every_robot(capsys, two, tmp_path):
    code, _, err = run(capsys, "export", "--cell", two, "--format", "urdf", "-o",
                       tmp_path / "cell.urdf")
    assert code == 0, err
    text = (tmp_path / "cell.urdf").read_text()
    assert 'link name="kuka_base_link"' in text and 'link name="abb_base_link"' in text
    code, _, err = run(capsys, "export", "--cell", two, "--format", "kuka")
    assert code == 2 and "--robot-name" in err
