"""--robot-name on the acceptance test (iso9283 plan/analyse, simulate iso9283), compensate and
program retarget/compensate: in a cell of two robots each command gives the named robot's
result (what it gives for that robot alone, or the library call on that robot's view); an
unknown name exits 2 with one error line listing the robots."""

from __future__ import annotations

import json
import math
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import pose_to_vendor
from robotcell.accuracy.poses import compensate_poses
from robotcell.accuracy.program import compensate_program
from robotcell.cell import Cell, Provenance
from robotcell.kinematics.transforms import make_pose
from robotcell.programs.retarget import retarget_program
from robotcell.robot.models import save_robot

ROOT = Path(__file__).resolve().parents[1]
TWO = ROOT / "examples" / "cell_two_robots_positioner.yaml"
ROBOTS = ("kuka", "abb")
#: Joint values (deg) each robot reaches near the positioner, and its track position (mm).
JOINTS = {"kuka": ([[10, -70, 95, 10, 40, -20], [14, -68, 93, 8, 44, -16]], 1200.0),
          "abb": ([[10, -20, 30, 10, 40, -20], [14, -18, 28, 8, 44, -16]], None)}


@pytest.fixture
def two(tmp_path):
    path = tmp_path / "two.yaml"
    shutil.copy(TWO, path)
    return path


def alone(path: Path, name: str, out: Path) -> Path:
    """Robot ``name`` of the cell alone in a one-robot cell file, with the shared parts."""
    cell = Cell.load(path)
    unit = cell.robots[name]
    frames = {k: f for k, f in cell.frames.items() if f.parent in ("world", "turntable")}
    base = {} if unit.track is not None else {"T_world_R": unit.T_world_R}
    Cell(robot=unit.robot, robot_model=unit.model, track=unit.track, turntable=cell.turntable,
         tools=dict(unit.tools), frames=frames, name=cell.name, **base).save(out)
    return out


def ok(capsys, *args):
    code, out, err = run(capsys, *args)
    assert code == 0, err
    return out


@pytest.mark.parametrize("robot", ROBOTS)
def test_the_acceptance_test_of_a_named_robot_is_that_robots_alone(capsys, two, tmp_path,
                                                                    robot):
    one = alone(two, robot, tmp_path / "one.yaml")
    for cell, where, name in ((two, ["--robot-name", robot], "two"), (one, [], "one")):
        ok(capsys, "iso9283", "plan", "--cell", cell, *where, "--tool", "torch", "--size", "300",
           "-o", tmp_path / f"plan_{name}.csv")
        ok(capsys, "simulate", "iso9283", "--cell", cell, *where, "--plan",
           tmp_path / f"plan_{name}.csv", "--seed", "1", "--path-cycles", "0",
           "-o", tmp_path / f"meas_{name}.csv")
    plan, meas = (tmp_path / "plan_two.csv").read_text(), (tmp_path / "meas_two.csv").read_text()
    assert plan == (tmp_path / "plan_one.csv").read_text()
    assert meas == (tmp_path / "meas_one.csv").read_text()
    analysed = [ok(capsys, "iso9283", "analyse", tmp_path / "meas_two.csv", "--plan",
                   tmp_path / "plan_two.csv", "--cell", cell, *where, "--json")
                for cell, where in ((two, ["--robot-name", robot]), (one, []))]
    assert analysed[0] == analysed[1]


def test_the_two_robots_get_different_test_cubes(capsys, two, tmp_path):
    for robot in ROBOTS:
        ok(capsys, "iso9283", "plan", "--cell", two, "--robot-name", robot, "--tool", "torch",
           "--size", "300", "-o", tmp_path / f"{robot}.csv")
    assert (tmp_path / "kuka.csv").read_text() != (tmp_path / "abb.csv").read_text()


def perturbed(robot, rng):
    """The arm as it is: every link constant off by up to 0.3 mm / 0.03 deg."""
    def mm():
        return rng.uniform(-0.3e-3, 0.3e-3)

    def deg():
        return math.radians(rng.uniform(-0.03, 0.03))

    joints = tuple(replace(j, a=j.a + mm(), d=j.d + mm(), alpha=j.alpha + deg())
                   for j in robot.joints)
    return replace(robot, name=f"{robot.name}_true", joints=joints, ik_seed=robot)


@pytest.fixture
def identified(two):
    """The two-robot cell with an identified arm for each robot."""
    rng = np.random.default_rng(7)
    cell = Cell.load(two)
    text = two.read_text()
    for name in ROBOTS:
        unit = cell.robots[name]
        save_robot(perturbed(unit.robot, rng), two.parent / f"{name}_arm.yaml")
        line = f"    model: {unit.model}\n"
        assert text.count(line) == 1
        text = text.replace(line, f"{line}    identified: {name}_arm.yaml\n")
    two.write_text(text)
    return two


def poses_file(cell: Cell, robot: str, path: Path) -> Path:
    """World poses the robot's torch reaches (x, y, z, a, b, c; track mm for the KUKA)."""
    joints, track = JOINTS[robot]
    T = cell.fk(np.radians(joints), track=0.0 if track is None else track * 1e-3,
                table=np.zeros(2), tool="torch", robot=robot)
    rows = pose_to_vendor(T, "kuka")
    head = "x,y,z,a,b,c" + (",track" if track is not None else "")
    lines = [",".join(f"{v:.4f}" for v in r) + (f",{track}" if track is not None else "")
             for r in rows]
    path.write_text("\n".join([head, *lines]) + "\n")
    return path


@pytest.mark.parametrize("robot", ROBOTS)
def test_compensate_filters_through_the_named_robots_identified_arm(capsys, identified,
                                                                    tmp_path, robot):
    cell = Cell.load(identified)
    poses = poses_file(cell, robot, tmp_path / "poses.csv")
    out = ok(capsys, "compensate", poses, "--cell", identified, "--robot-name", robot, "--tool",
             "torch", "--json")
    expected = compensate_poses(poses, cell.for_robot(robot), "torch").to_json()
    assert json.loads(out) == json.loads(json.dumps(expected))


@pytest.mark.parametrize("robot", ROBOTS)
def test_program_compensate_filters_the_named_robots_program(capsys, identified, tmp_path,
                                                             robot):
    cell = Cell.load(identified)
    poses = poses_file(cell, robot, tmp_path / "poses.csv")
    vendor = {"kuka": "kuka", "abb": "abb"}[robot]
    ok(capsys, "program", "write", poses, "--cell", identified, "--robot-name", robot, "--tool",
       "torch", "--format", vendor, "-o", tmp_path / "prog")
    program = next(p for p in (tmp_path / "prog").iterdir() if p.suffix in (".src", ".mod"))
    ok(capsys, "program", "compensate", program, "--cell", identified, "--robot-name", robot,
       "-o", tmp_path / "cli")
    compensate_program(program, cell.for_robot(robot), tmp_path / "lib")
    for written in (tmp_path / "lib").iterdir():
        assert (tmp_path / "cli" / written.name).read_text() == written.read_text()


def joint_program(robot: str, folder: Path) -> Path:
    """A program of joint points of the robot (KUKA E6AXIS with the track, ABB jointtarget)."""
    joints, track = JOINTS[robot]
    if robot == "abb":
        lines = ["MODULE jpoints"] + [
            f"    CONST jointtarget j{i}:=[[{','.join(map(str, q))}],[10,20,9E9,9E9,9E9,9E9]];"
            for i, q in enumerate(joints, start=1)]
        lines += ["    PROC main()"] + [f"        MoveAbsJ j{i},v200,fine,torch\\WObj:=wobj0;"
                                          for i in range(1, len(joints) + 1)]
        (folder / "jpoints.mod").write_text("\n".join(lines + ["    ENDPROC", "ENDMODULE"]) + "\n")
        return folder / "jpoints.mod"
    src = ["DEF jpoints( )", "  BAS (#INITMOV,0 )", "$TOOL=TOOL_DATA[1]", "$BASE=$NULLFRAME"]
    dat = ["DEFDAT jpoints"]
    for i, q in enumerate(joints, start=1):
        axes = ",".join(f"A{k + 1} {v}" for k, v in enumerate(q))
        dat.append(f"DECL E6AXIS XJ{i}={{{axes},E1 {track},E2 10,E3 20,E4 0,E5 0,E6 0}}")
        src.append(f"PTP XJ{i}")
    (folder / "jpoints.dat").write_text("\n".join(dat + ["ENDDAT"]) + "\n")
    (folder / "jpoints.src").write_text("\n".join(src + ["END"]) + "\n")
    return folder / "jpoints.src"


@pytest.mark.parametrize("robot", ROBOTS)
def test_retarget_moves_the_named_robots_joint_points(capsys, two, tmp_path, robot):
    new_file = tmp_path / "new.yaml"
    new = Cell.load(two)
    shift = make_pose(np.eye(3), [1e-3, 0, 0])  # the torch found 1 mm further out
    new.set_tool("torch", new.robots[robot].tools["torch"].T_F_TCP @ shift,
                 Provenance.now("manual"), robot=robot)
    new.save(new_file)
    program = joint_program(robot, tmp_path)
    out = ok(capsys, "program", "retarget", program, "--from", two, "--to", new_file,
             "--robot-name", robot, "-o", tmp_path / "cli", "--json")
    points = json.loads(out)["points"]
    expected = retarget_program(program, Cell.load(two).for_robot(robot),
                                Cell.load(new_file).for_robot(robot), tmp_path / "lib")
    assert [p["change_deg"] for p in points] == pytest.approx(
        [math.degrees(p.change) for p in expected.points], abs=1e-8)
    assert min(p["change_deg"] for p in points) > 0.01  # the points moved for the new torch
    assert max(p["tcp_error_mm"] for p in points) < 1e-6


@pytest.mark.parametrize("command", [
    ["iso9283", "plan", "--cell", "{two}", "--tool", "torch"],
    ["iso9283", "analyse", "m.csv", "--plan", "p.csv", "--cell", "{two}"],
    ["simulate", "iso9283", "--cell", "{two}", "--plan", "p.csv"],
    ["compensate", "p.csv", "--cell", "{two}", "--tool", "torch"],
    ["program", "retarget", "p.src", "--from", "{two}", "--to", "{two}", "-o", "{out}"],
    ["program", "compensate", "p.src", "--cell", "{two}", "-o", "{out}"],
    ["calibrate", "cell", "--cell", "{two}"],
])
def test_an_unknown_robot_name_exits_2_with_one_error_line(capsys, two, tmp_path, command):
    args = [a.format(two=two, out=tmp_path / "out") for a in command]
    text = two.read_text()
    code, out, err = run(capsys, *args, "--robot-name", "fanuc")
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith("error:"), err
    assert "no robot 'fanuc'; its robots: kuka, abb" in err
    assert two.read_text() == text and not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", [
    ["iso9283", "plan", "--cell", "{two}", "--tool", "torch"],
    ["compensate", "p.csv", "--cell", "{two}", "--tool", "torch"],
    ["program", "retarget", "p.src", "--from", "{two}", "--to", "{two}", "-o", "{out}"],
])
def test_a_cell_of_several_robots_needs_a_name(capsys, two, tmp_path, command):
    args = [a.format(two=two, out=tmp_path / "out") for a in command]
    code, _, err = run(capsys, *args)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "has 2 robots (kuka, abb): say which one with --robot-name NAME" in err


def test_analyse_refuses_a_robot_name_without_a_cell(capsys, tmp_path):
    code, _, err = run(capsys, "iso9283", "analyse", "m.csv", "--plan", "p.csv",
                       "--robot-name", "abb")
    assert code == 2 and "--robot-name names a robot of a cell file; it needs --cell" in err
