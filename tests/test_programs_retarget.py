"""Retargeting joint points after a recalibration (robotcell.programs.retarget): the TCP stays
where it was, every other line of the program stays as it was."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import CELL

from robotcell.cell import Cell, Provenance
from robotcell.io.poseformats import pose_from_vendor
from robotcell.programs import read_program
from robotcell.programs.frames import tool_pose_of
from robotcell.programs.retarget import RetargetFailed, retarget_program

#: Joint points in the example cell: a1..a6 (deg), track (mm), table (deg).
POINTS = [([-60, -80, 95, 10, 40, -20], 1200.0, 0.0),
          ([-75, -60, 85, -30, 60, 45], 1800.0, 90.0),
          ([-90, -70, 100, 20, -50, 190], 2400.0, -45.0)]


def _kuka(folder: Path) -> Path:
    src = ["DEF jpoints( )", "  BAS (#INITMOV,0 )", "$TOOL=TOOL_DATA[1]", "$BASE=$NULLFRAME"]
    dat = ["DEFDAT jpoints", "; taught on the pendant"]
    for i, (q, e, t) in enumerate(POINTS, start=1):
        axes = ",".join(f"A{k + 1} {v}" for k, v in enumerate(q))
        dat.append(f"DECL E6AXIS XJ{i}={{{axes},E1 {e},E2 {t},E3 0.0,E4 0.0,E5 0.0,E6 0.0}}")
        src += [f"PTP XJ{i}", "  $OUT[3]=TRUE"]
    src.append("END")
    (folder / "jpoints.dat").write_text("\n".join(dat + ["ENDDAT"]) + "\n")
    (folder / "jpoints.src").write_text("\n".join(src) + "\n")
    return folder / "jpoints.src"


def _abb(folder: Path) -> Path:
    L = ["MODULE jpoints"]
    for i, (q, e, t) in enumerate(POINTS, start=1):
        L.append(f"    CONST jointtarget j{i}:=[[{','.join(map(str, q))}],"
                 f"[{e},{t},9E9,9E9,9E9,9E9]];")
    L += ["    PROC main()"] + [f"        MoveAbsJ j{i},v200,fine,torch\\WObj:=wobj0;"
                                  for i in range(1, 4)]
    L += ["    ENDPROC", "ENDMODULE"]
    (folder / "jpoints.mod").write_text("\n".join(L) + "\n")
    return folder / "jpoints.mod"


def _fanuc(folder: Path) -> Path:
    L = ["/PROG  JPOINTS", "/ATTR", "/MN", "   1:  UTOOL_NUM=1 ;"]
    L += [f"{i + 1:4d}:J P[{i}] 20% FINE ;" for i in range(1, 4)]
    L.append("/POS")
    for i, (q, e, t) in enumerate(POINTS, start=1):
        L += [f"P[{i}]{{", "   GP1:", "\tUF : 0, UT : 1,",
              f"\tJ1= {q[0]} deg,\tJ2= {q[1]} deg,\tJ3= {q[2]} deg,",
              f"\tJ4= {q[3]} deg,\tJ5= {q[4]} deg,\tJ6= {q[5]} deg,", f"\tE1= {e} mm",
              "   GP2:", "\tUF : 0, UT : 1,", f"\tJ1= {t} deg", "};"]
    L.append("/END")
    (folder / "jpoints.ls").write_text("\n".join(L) + "\n")
    return folder / "jpoints.ls"


@pytest.fixture(scope="module")
def cells() -> tuple[Cell, Cell]:
    old = Cell.load(CELL)
    new = Cell.load(CELL)
    moved = old.tools["torch"].T_F_TCP @ pose_from_vendor([2.0, -1.0, 0.5, 0.3, -0.5, 0.2],
                                                          "kuka")
    new.set_tool("torch", moved, Provenance.now("tcp", rms_mm=0.2))
    return old, new


@pytest.mark.parametrize("make", [_kuka, _abb, _fanuc])
def test_after_a_tool_recalibration_every_tcp_stays_within_1e_3_mm(cells, make, tmp_path):
    old, new = cells
    (tmp_path / "in").mkdir()
    path = make(tmp_path / "in")
    result = retarget_program(path, old, new, tmp_path / "out")
    assert len(result.points) == 3 and result.cartesian == 0
    program, _ = read_program(tmp_path / "out" / path.name)
    vendor = program.vendor
    for p, (q, e, t) in zip(program.points, POINTS):
        before = old.fk(np.radians(q), e * 1e-3, np.radians(t),
                        tool=tool_pose_of(old, vendor, p.tool))
        after = new.fk(p.joints, e * 1e-3, np.radians(t), tool=tool_pose_of(new, vendor, p.tool))
        assert np.linalg.norm(after[:3, 3] - before[:3, 3]) < 1e-6  # 1e-3 mm
        assert np.abs(after[:3, :3] - before[:3, :3]).max() < 1e-9
        assert 0 < np.max(np.abs(p.joints - np.radians(q))) < np.radians(2)
    assert max(r.tcp_error for r in result.points) < 1e-9
    # every other line is kept (KUKA: the .src as it was, the .dat with new axis values)
    changed = []
    for f in (tmp_path / "in").iterdir():
        old_lines = f.read_text().splitlines()
        new_lines = (tmp_path / "out" / f.name).read_text().splitlines()
        assert len(old_lines) == len(new_lines)
        changed += [a for a, b in zip(old_lines, new_lines) if a != b]
    assert len(changed) == (3 if vendor != "fanuc" else 6)


def test_the_command_reports_the_change_per_point(cells, tmp_path, capsys):
    new = cells[1]
    new_file = tmp_path / "new.yaml"
    new.save(new_file)
    (tmp_path / "in").mkdir()
    src = _kuka(tmp_path / "in")
    code, out, err = run(capsys, "program", "retarget", src, "--from", CELL, "--to", new_file,
                         "-o", tmp_path / "out", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert [p["name"] for p in data["points"]] == ["XJ1", "XJ2", "XJ3"]
    assert all(0 < p["change_deg"] < 2 and p["tcp_error_mm"] < 1e-6 for p in data["points"])
    assert sorted(Path(f).name for f in data["files"]) == ["jpoints.dat", "jpoints.src"]


def test_a_point_the_new_cell_cannot_reach_writes_nothing(cells, tmp_path, capsys):
    old = cells[0]
    far = Cell.load(CELL)
    far.set_tool("torch", old.tools["torch"].T_F_TCP @ pose_from_vendor(
        [0, 0, -2500, 0, 0, 0], "kuka"), Provenance.now("tcp"))
    (tmp_path / "in").mkdir()
    src = _kuka(tmp_path / "in")
    with pytest.raises(RetargetFailed, match="XJ1 .*cannot put the TCP where the old one had"):
        retarget_program(src, old, far, tmp_path / "out")
    assert not (tmp_path / "out").exists()
    far_file = tmp_path / "far.yaml"
    far.save(far_file)
    code, _, err = run(capsys, "program", "retarget", src, "--from", CELL, "--to", far_file,
                         "-o", tmp_path / "out")
    assert code == 3 and "nothing written" in err


def _fanuc_point(folder: Path, q: list[float], e: float = 1200.0, t: float = 0.0) -> Path:
    """A FANUC listing of one joint position (deg), rail ``e`` (mm), table ``t`` (deg)."""
    L = ["/PROG  ONE", "/ATTR", "/MN", "   1:  UTOOL_NUM=1 ;", "   2:J P[1] 20% FINE ;", "/POS",
         "P[1]{", "   GP1:", "\tUF : 0, UT : 1,",
         f"\tJ1={q[0]:10.3f} deg,\tJ2={q[1]:10.3f} deg,"
         f"\tJ3={q[2]:10.3f} deg,", f"\tJ4={q[3]:10.3f} deg,\tJ5={q[4]:10.3f} deg,"
         f"\tJ6={q[5]:10.3f} deg,", f"\tE1={e:10.3f}  mm", "   GP2:", "\tUF : 0, UT : 1,",
         f"\tJ1={t:10.3f} deg", "};", "/END"]
    (folder / "one.ls").write_text("\n".join(L) + "\n")
    return folder / "one.ls"


def test_a_point_whose_configuration_leaves_the_limits_is_named_not_changed(cells, tmp_path,
                                                                           capsys):
    # Axis 1 just inside its limit (185 deg): after the tool change the point keeps its
    # configuration only with axis 1 beyond it. Turning axis 1 a whole turn the other way (or
    # another branch) would be silently another configuration: refused, naming the axis.
    old, new = cells
    probe = np.radians([170.0, -80, 95, 10, 40, -20])
    T = old.fk(probe, 1.2, 0.0, tool="torch")
    sol = new.ik(T, track=1.2, tool="torch")
    d = np.abs(sol.q - probe).sum(-1)
    step = np.degrees(sol.q[np.argmin(np.where(np.isfinite(d), d, np.inf))][0] - probe[0])
    assert abs(step) > 1e-3
    a1 = 185 - abs(step) / 2 if step > 0 else -185 + abs(step) / 2
    (tmp_path / "in").mkdir()
    path = _fanuc_point(tmp_path / "in", [a1, -80, 95, 10, 40, -20])
    with pytest.raises(RetargetFailed, match=r"P\[1\] \(line 5\): the new cell keeps the point's "
                                             r"configuration only with axis 1 at -?18[45]\.\d deg,"
                                             r" outside its limits \[-185, 185\] deg"):
        retarget_program(path, old, new, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_a_point_already_outside_the_limits_is_named(cells, tmp_path, capsys):
    # The program's J6 is beyond the model's 350 deg: the retarget names it, and keeps the
    # point's configuration (a 2 mm tool change moves the axes by a fraction of a degree, never
    # to another branch).
    old, new = cells
    new_file = tmp_path / "new.yaml"
    new.save(new_file)
    (tmp_path / "in").mkdir()
    path = _fanuc_point(tmp_path / "in", [-60, -80, 95, 10, 40, 355])
    code, _, err = run(capsys, "program", "retarget", path, "--from", CELL, "--to", new_file,
                       "-o", tmp_path / "out")
    assert code == 3
    assert "P[1] (line 5): in the program axis 6 is at 355.0 deg, outside its limits" in err
    assert "outside them in the program already" in err
    # within the limits, the same point keeps its configuration: every axis moves by little
    path = _fanuc_point(tmp_path / "in", [-60, -80, 95, 10, 40, 345])
    result = retarget_program(path, old, new, tmp_path / "out2")
    assert result.notes == [] and result.points[0].change < np.radians(2)
