"""Linear motions of a program followed as a controller follows them (robotcell.programs.lines):
a configuration change or a singularity on the way is named, a large but smooth wrist turn is
not (docs/programs.md, "Checking")."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import ROBODK

from robotcell.cell import Cell
from robotcell.io.poseformats import pose_to_vendor
from robotcell.programs.check import check_program_file
from robotcell.programs.config import config_values

#: A KR 16 at the world origin; the programs below use the flange as their tool.
CELL = ROBODK / "cell_kr16.yaml"


@pytest.fixture(scope="module")
def cell() -> Cell:
    return Cell.load(CELL)


def _krl(folder: Path, cell: Cell, points: list[tuple[str, np.ndarray | list[float]]],
         flags: list[tuple[int, int]] | None = None) -> Path:
    """A KUKA program (the excerpt a pendant saves: PTP to the first point, LIN to the rest)
    whose E6POS points are the flange poses of the joints given (deg), with their S and T."""
    q = np.radians([p for _, p in points])
    T = cell.robot.fk(q, tool=np.eye(4))
    st = config_values(cell.robot, q, "kuka") if flags is None else np.array(flags)
    src = ["DEF line( )", "$TOOL=$NULLFRAME", "$BASE=$NULLFRAME", "BAS(#VEL_PTP,20)"]
    dat = ["DEFDAT line"]
    for k, ((name, _), pose, (s, t)) in enumerate(zip(points, T, st)):
        v = pose_to_vendor(pose, "kuka")
        dat.append(f"DECL E6POS {name}={{X {v[0]:.4f},Y {v[1]:.4f},Z {v[2]:.4f},A {v[3]:.5f},"
                   f"B {v[4]:.5f},C {v[5]:.5f},S {s},T {t},E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,"
                   "E6 0.0}")
        src.append(f"{'PTP' if k == 0 else 'LIN'} {name}")
    (folder / "line.src").write_text("\n".join(src + ["END"]) + "\n")
    (folder / "line.dat").write_text("\n".join(dat + ["ENDDAT"]) + "\n")
    return folder / "line.src"


def test_a_40_deg_wrist_turn_on_a_short_linear_motion_is_good(cell, tmp_path, capsys):
    # A linear motion that turns the tool by 38 deg about its axis (axis 6 turns 38 deg, the
    # other axes stay): controllers save and run such moves; a fixed 30 deg limit called it bad.
    src = _krl(tmp_path, cell, [("XP1", [10, -80, 100, 20, 60, 10]),
                                ("XP2", [10, -80, 100, 20, 60, 48])])
    report = check_program_file(src, cell)
    assert report.good, report.rows()
    assert math.degrees(report.points[1].q[5] - report.points[0].q[5]) == pytest.approx(38, abs=1e-3)
    code, out, err = run(capsys, "program", "check", src, "--cell", CELL)
    assert code == 0, err
    assert "2 points, all good" in out


def test_a_linear_motion_to_the_flipped_wrist_names_the_flip(cell, tmp_path):
    # The target is the same pose reached with axis 5 the other way round (and axes 4 and 6 half
    # a turn off): a straight line can only get there through the wrist singularity.
    src = _krl(tmp_path, cell, [("XP1", [0, -90, 100, 0, 30, 0]),
                                ("XP2", [0, -90, 100, 0, -30, 0])])
    report = check_program_file(src, cell)
    assert [p.name for p in report.bad] == ["XP2"]
    (why,) = [w for w in report.bad[0].problems if "configuration" in w]
    assert why.startswith("the linear motion from XP1 changes the arm's configuration (the wrist "
                          "flips: axis 5 changes sign)")


def test_a_linear_motion_through_the_wrist_singularity_is_named(cell, tmp_path):
    # Both ends 2 deg and more from the wrist singularity, in the same configuration; the
    # straight line between them (the TCP 100 mm to either side of a pose with axis 5 at 0)
    # passes through it, where axes 4 and 6 swing half a turn.
    T = cell.robot.fk(np.radians([0, -90, 100, 0, 0, 0]), tool=np.eye(4))
    ends = []
    for dy in (-0.1, 0.1):
        pose = T.copy()
        pose[1, 3] += dy
        ends.append(pose)
    sol = cell.robot.ik(np.stack(ends), tool=np.eye(4))
    # the branch with axis 5 positive at both ends (the flags then agree)
    q = [sol.q[k][np.flatnonzero(sol.valid[k] & (sol.q[k][:, 4] > 0))[0]] for k in (0, 1)]
    assert np.all(np.degrees([x[4] for x in q]) > 2)
    src = _krl(tmp_path, cell, [("XP1", np.degrees(q[0])), ("XP2", np.degrees(q[1]))])
    report = check_program_file(src, cell)
    assert [p.name for p in report.bad] == ["XP2"]
    problems = report.bad[0].problems
    assert any(w.startswith("the linear motion from XP1 passes 0.0") and "wrist singularity"
               in w for w in problems), problems
    assert not any("axis 5 is" in w for w in problems)  # the points themselves are good


def test_the_singular_margin_is_an_option(cell, tmp_path, capsys):
    # A point 3 deg from the wrist singularity is good with the default margin (2 deg) and bad
    # with a margin of 5 deg given on the command line.
    src = _krl(tmp_path, cell, [("XP1", [0, -90, 100, 0, 3, 0])])
    code, _, err = run(capsys, "program", "check", src, "--cell", CELL)
    assert code == 0, err
    code, _, err = run(capsys, "program", "check", src, "--cell", CELL, "--singular-margin", "5")
    assert code == 3 and "margin 5 deg" in err


def test_a_linear_motion_that_arrives_a_turn_away_from_the_written_configuration(cell,
                                                                                tmp_path):
    # ABB's ConfL \On: the controller keeps the quadrants written; the straight line from p1
    # arrives with axis 6 at 30 deg, the target's cf6 (-4) asks for -330 deg.
    q = np.radians([[10, -90, 100, 10, 45, 10], [10, -90, 100, 10, 45, 30]])
    T = cell.robot.fk(q, tool=np.eye(4))
    cf = config_values(cell.robot, q, "abb")
    cf[1, 2] -= 4
    targets = []
    for k, (pose, c) in enumerate(zip(T, cf)):
        v = pose_to_vendor(pose, "abb")
        targets.append(f"CONST robtarget p{k + 1}:=[[{v[0]:.4f},{v[1]:.4f},{v[2]:.4f}],"
                       f"[{','.join(f'{x:.10f}' for x in v[3:])}],[{','.join(map(str, c))}],"
                       "[9E9,9E9,9E9,9E9,9E9,9E9]];")
    lines = ["MODULE turn", *targets, "PROC turn()", "ConfL \\On;", "MoveJ p1,v100,fine,tool0;",
             "MoveL p2,v100,fine,tool0;", "ENDPROC", "ENDMODULE"]
    path = tmp_path / "turn.mod"
    path.write_text("\n".join(lines) + "\n")
    report = check_program_file(path, cell)
    assert [p.name for p in report.bad] == ["p2"]
    assert report.bad[0].problems == [
        "the linear motion from p1 arrives with axis 6 at 30.0 deg, a whole turn from the point's "
        "-330.0 deg as its configuration is written"]
