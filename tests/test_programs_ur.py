"""Universal Robots (URScript .script): programs written and read back through the arm's FK,
the ISO 9283 plan of a UR5e checked by 'program check', public scripts read, the export read
back, and what a UR program cannot hold refused."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.cell.model import cell_from_dict
from robotcell.controllers.model import Program, ProgramPoint, Ref
from robotcell.controllers.registry import by_suffix, get
from robotcell.errors import InputError
from robotcell.export import export_cell, parse_export
from robotcell.io.poseformats import pose_to_vendor
from robotcell.iso9283 import plan, write_programs
from robotcell.iso9283.cycles import path_sequence, pose_sequence
from robotcell.kinematics.transforms import invert
from robotcell.programs import read_program
from robotcell.programs.check import check_program_file

DATA = Path(__file__).resolve().parent / "data" / "programs" / "ur"
TRACK_CELL = Path(__file__).resolve().parent.parent / "examples" / "cell_kr16_track_turntable.yaml"
UR = get("ur")


def ur5e_cell() -> Cell:
    """A UR5e on the floor, a 100 mm probe, and a feature 'table' turned about Z."""
    return cell_from_dict({
        "name": "ur5e_cell", "robot": {"model": "ur5e"},
        "tools": {"probe": {"frame": {"x": 0, "y": 0, "z": 100, "a": 0, "b": 0, "c": 0}},
                  "gun": {"frame": {"x": 20, "y": -10, "z": 150, "a": 30, "b": 20, "c": -10},
                          "mass": 1.5}},
        "frames": {"table": {"frame": {"x": 350, "y": -250, "z": 20, "a": 35, "b": 0,
                                        "c": 180}}}})


def assert_same_pose(A, B, tol_m=1e-9, what=""):
    A, B = np.asarray(A), np.asarray(B)
    assert np.max(np.abs(A[..., :3, 3] - B[..., :3, 3])) < tol_m, what
    assert np.max(np.abs(A[..., :3, :3] - B[..., :3, :3])) < 1e-9, what


# -- written, read back, through the FK --------------------------------------------------------
def _random_program(cell: Cell, rng, frame: str | None) -> tuple[Program, np.ndarray]:
    """Points at random joints inside the limits: Cartesian (in ``frame`` or the base) and
    joint points, linear and joint motions; and each point's TCP in the robot base."""
    robot = cell.robot
    n = 12
    q = rng.uniform(np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi), (n, 6))
    tool = cell.tools["gun"].T_F_TCP
    T_R_TCP = robot.fk(q) @ tool
    data = UR.data(cell)
    if frame is None:
        fref, T_R_X = UR.world_ref, np.eye(4)
    else:
        slot = next(s for s in data.frames if s.name == frame)
        fref, T_R_X = Ref(number=slot.number, name=frame, kind="base"), slot.pose
    tref = Ref(number=2, name="gun")
    points = []
    for i in range(n):
        joint = i % 4 == 3
        points.append(ProgramPoint(
            f"p{i + 1}", 0, "ptp" if i % 3 == 0 else "lin", tref, fref,
            pose=None if joint else invert(T_R_X) @ T_R_TCP[i],
            joints=q[i] if joint else None, speed=float(rng.uniform(0.01, 1.0)),
            zone=float(rng.choice([0.0, rng.uniform(0.0, 0.02)]))))
    return Program("random_ur", "ur", points, data=data), T_R_TCP


@pytest.mark.parametrize("seed,frame", [(1, None), (2, "table"), (3, "table")])
def test_a_written_program_reads_back_to_the_commanded_poses_and_joints(seed, frame, tmp_path):
    cell = ur5e_cell()
    rng = np.random.default_rng(seed)
    program, T_R_TCP = _random_program(cell, rng, frame)
    texts = UR.write_program(program, ["a test program"])
    assert list(texts) == ["random_ur.script"]
    path = tmp_path / "random_ur.script"
    path.write_text(texts["random_ur.script"], encoding="utf-8")
    back, skipped = read_program(path)
    assert skipped == [] and back.name == "random_ur" and back.vendor == "ur"
    assert len(back.points) == len(program.points)
    for w, r in zip(program.points, back.points):
        assert r.motion == w.motion
        assert_same_pose(r.tool.pose, cell.tools["gun"].T_F_TCP)
        if w.joints is not None:
            np.testing.assert_allclose(r.joints, w.joints, rtol=0, atol=5e-13)
            assert r.pose is None
            continue
        assert_same_pose(r.pose, w.pose, what=r.name)
        if frame is not None:
            assert r.frame.name == frame
            assert_same_pose(r.frame.pose, UR.data(cell).frames[0].pose)
        assert r.zone == pytest.approx(w.zone, abs=1e-9)
        assert r.speed == (pytest.approx(w.speed, abs=1e-9) if w.motion == "lin" else None)
    # through the cell: every point where it was commanded (the FK of the solved joints)
    report = check_program_file(path, cell)
    got = np.stack([p.T_world_TCP for p in report.points])
    assert_same_pose(got, cell.T_world_R @ T_R_TCP, tol_m=1e-9)
    # joint points exactly as written
    for p, w in zip(report.points, program.points):
        if w.joints is not None:
            np.testing.assert_allclose(p.q, w.joints, rtol=0, atol=5e-13)


def test_the_iso9283_plan_of_a_ur5e_is_written_as_urscript_and_passes_program_check(
        tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    cell_file = tmp_path / "ur5e.yaml"
    cell_file.write_text("name: ur5e_test\nrobot: {model: ur5e}\ntools:\n  probe: {frame: "
                         "{x: 0, y: 0, z: 100, a: 0, b: 0, c: 0}}\n")
    code, _, err = run(capsys, "iso9283", "plan", "--cell", cell_file, "--tool", "probe",
                       "-o", "plan.csv", "--programs", "iso", "--format", "ur")
    assert code == 0, err
    files = sorted(Path("iso/ur").iterdir())
    assert [f.name for f in files] == ["ISOPATHS.script", "ISOPOSES.script"]
    for f in files:
        code, out, err = run(capsys, "program", "check", f, "--cell", cell_file)
        assert code == 0, f"{f}: {out}{err}"
        assert "all good" in out
    # every point of both programs, read back through the FK, is the plan's to 1e-6 mm
    cell = Cell.load(cell_file)
    p = plan(cell, "probe")
    for file, (names, _, _) in (("ISOPOSES", pose_sequence(p)), ("ISOPATHS", path_sequence(p))):
        report = check_program_file(f"iso/ur/{file}.script", cell)
        assert len(report.points) == len(names)
        want = p.T[[p.names.index(n) for n in names]]
        got = np.stack([pt.T_world_TCP for pt in report.points])
        assert_same_pose(got, want, tol_m=1e-9, what=file)
    assert len(pose_sequence(p)[0]) == 1 + 5 * 30
    # without --format the plan is written for the controllers that hold a UR arm: UR alone
    written = write_programs(p, cell, tmp_path / "all")
    assert {Path(f).parent.name for f in written} == {"ur"}


# -- real scripts ----------------------------------------------------------------------------
CORPUS = sorted(DATA.rglob("*.script"))


@pytest.mark.parametrize("path", CORPUS, ids=[p.name for p in CORPUS])
def test_a_public_script_is_read_and_checked_never_refused(path, capsys):
    program, skipped = read_program(path)
    assert by_suffix(path.suffix) is UR and (program.points or skipped)
    assert all(s.startswith("line ") for s in skipped), skipped
    code, out, err = run(capsys, "program", "check", path, "--cell", DATA / "cell.yaml")
    assert code in (0, 3), err
    readme = (DATA / "README.md").read_text(encoding="utf-8")
    assert f"`{path.relative_to(DATA).as_posix()}`" in readme


def test_polyscope_waypoints_features_and_run_time_targets_are_read_as_the_manual_says():
    program, skipped = read_program(DATA / "excerpts" / "waypoints_plane.script")
    assert program.name == "waypoints_plane"
    p = program.points
    assert [x.name for x in p] == ["Waypoint_1_p", "Waypoint_2_p", "line 17", "line 18",
                                   "line 20"]
    assert [x.motion for x in p] == ["ptp", "ptp", "lin", "lin", "ptp"]
    assert p[0].where.endswith(":5") and p[0].joints is None and p[0].speed is None
    assert p[1].zone == pytest.approx(0.01) and p[2].zone == pytest.approx(0.005)
    assert p[2].speed == pytest.approx(0.25) and p[3].zone == 0.0
    np.testing.assert_allclose(p[0].pose[:3, 3], [0.45, -0.15, 0.4])
    assert p[2].frame.name == "Plane_1"
    np.testing.assert_allclose(p[2].frame.pose[:3, 3], [0.4, -0.2, 0.05])
    np.testing.assert_allclose(p[3].pose[:3, 3], [0.1, 0.0, 0.1])
    np.testing.assert_allclose(p[2].tool.pose[:3, 3], [0.0, 0.0, 0.1])
    assert p[4].joints is not None and p[4].frame is p[0].frame
    assert skipped == ["line 22: movec (circular motions are not checked)"]
    program, skipped = read_program(DATA / "excerpts" / "holding_force.script")
    assert [x.name for x in program.points] == ["Start_pos_p"]
    np.testing.assert_allclose(program.points[0].pose[:3, 3], [-0.14, -0.3, 0.25])
    assert len(skipped) == 1 and "a target computed at run time" in skipped[0]


def test_robodk_scripts_keep_the_manual_order_of_movej_arguments():
    program, skipped = read_program(DATA / "robodk" / "Prog1.script")
    assert [x.motion for x in program.points] == ["ptp", "ptp", "lin", "ptp"]
    # movej(q, a, v, t, r): RoboDK's fifth argument is the blend radius, a variable set once
    assert [x.zone for x in program.points] == [0.0, 0.001, 0.001, 0.001]
    # speed_ms is set twice in the file: a value set at run time, not read
    assert program.points[2].speed is None
    assert skipped == ["line 69: movec (circular motions are not checked)"]
    program, _ = read_program(DATA / "robodk" / "UniveralRobots.script")
    # a set_tcp inside a subprogram counts for the motions after it in the file
    np.testing.assert_allclose(program.points[0].tool.pose[:3, 3], [0.05, 0.0, 0.45])


# -- refused ---------------------------------------------------------------------------------
GOOD = ("def prog():\n  set_tcp(p[0, 0, 0.1, 0, 0, 0])\n"
        "  movej([0, -1.57, 1.57, -1.57, -1.57, 0], r=0)\n"
        "  movel(p[0.4, -0.1, 0.3, 0, 3.14159, 0], v=0.1, r=0.002)\nend\nprog()\n")


@pytest.mark.parametrize("text,match", [
    (GOOD.replace("p[0.4, -0.1, 0.3, 0, 3.14159, 0]", "p[0.4, -0.1, 0.3, 0, 3.14159]"),
     r"prog\.script: line 4: a pose is p\[x, y, z, rx, ry, rz\], six numbers"),
    (GOOD.replace("0.4, -0.1", "nan, -0.1"), r"prog\.script: line 4: 'nan' is not finite"),
    (GOOD.replace("-1.57, 1.57, -1.57, -1.57, 0]", "-1.57, 1.57, -1.57, -1.57]"),
     r"line 3: joint positions are six numbers"),
    (GOOD.replace("0.3, 0,", "0.3x, 0,"), r"line 4: '0\.3x' is not a number"),
    (GOOD.replace("end\n", ""), r"line 5: 1 block\(s\) not closed by 'end'.*truncated"),
    (GOOD.replace("v=0.1, r=0.002)", "v=0.1, r=0.002"), r"line 4: the brackets of .* not "
                                                        r"closed"),
    # statements at the top of the file are a program, but then the 'end' closes nothing
    (GOOD.replace("def prog():\n", ""), r"prog\.script: line 4: 'end' closes no block"),
    (GOOD.replace("movej(", "movej(1e400, ").replace("[0, -1.57", "[1e400, -1.57"),
     r"line 3: .*(not finite|beyond)"),
])
def test_a_script_that_cannot_be_read_is_refused_naming_the_line(text, match, tmp_path):
    path = tmp_path / "prog.script"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=match):
        read_program(path)


def test_a_file_that_is_not_text_is_refused(tmp_path):
    path = tmp_path / "prog.script"
    path.write_bytes(GOOD.encode("utf-16"))
    with pytest.raises(InputError, match=r"not a text file robotcell reads"):
        read_program(path)
    path.write_bytes(b"def prog():\n\x00\x01movej\nend\n")
    with pytest.raises(InputError, match=r"not a text file \(it holds NUL characters\)"):
        read_program(path)


def test_a_cell_with_a_track_or_turntable_is_refused_for_ur(tmp_path, capsys):
    cell = Cell.load(TRACK_CELL)
    with pytest.raises(InputError, match=r"Universal Robots programs and exports hold no "
                                         r"external axes .* a track 'KL1500' and a turntable"):
        export_cell(cell, "ur")
    assert UR.refusal(cell).startswith("Universal Robots programs and exports hold no")
    assert get("kuka").refusal(cell) is None
    out = tmp_path / "prog"
    code, stdout, err = run(capsys, "program", "write", Path(TRACK_CELL).parent / "seam_part.csv",
                            "--cell", TRACK_CELL, "--tool", "torch", "--frame", "part",
                            "--format", "ur", "-o", out)
    assert code == 2 and stdout == ""
    assert err.count("error:") == 1 and err.startswith("error: Universal Robots programs")
    assert "Traceback" not in err and not out.exists()
    code, _, err = run(capsys, "export", "--cell", TRACK_CELL, "--format", "ur", "-o",
                       tmp_path / "cell.script")
    assert code == 2 and err.count("error:") == 1 and not (tmp_path / "cell.script").exists()


def test_a_ur_arm_gets_no_other_controllers_flags_and_a_name_must_be_urscript(tmp_path):
    cell = ur5e_cell()
    assert get("kuka").refusal(cell) is not None and UR.refusal(cell) is None
    assert UR.config_values(cell.robot, np.zeros((3, 6))).shape == (3, 0)
    for bad in ("end", "movel", "1prog", "a-b"):
        with pytest.raises(InputError, match="program name"):
            UR.program_name(bad)
    assert UR.program_name("ISOPOSES") == "ISOPOSES"


def test_program_write_through_the_cli_in_a_feature_is_checked_good(tmp_path, capsys):
    cell_file = tmp_path / "cell.yaml"
    cell_file.write_text(
        "name: ur5e_cell\nrobot: {model: ur5e}\n"
        "tools:\n  probe: {frame: {x: 0, y: 0, z: 100, a: 0, b: 0, c: 0}}\n"
        "frames:\n  table: {frame: {x: 350, y: -250, z: 20, a: 35, b: 0, c: 0}}\n")
    path = tmp_path / "seam.csv"
    path.write_text("x,y,z,a,b,c,motion,speed,zone\n"
                    "0,0,100,0,180,0,ptp,,\n"
                    "50,20,100,0,180,0,lin,50,2\n"
                    "100,40,120,10,180,0,lin,80,0\n")
    code, out, err = run(capsys, "program", "write", path, "--cell", cell_file, "--tool",
                         "probe", "--frame", "table", "--format", "ur", "-o", tmp_path / "prog")
    assert code == 0, err
    text = (tmp_path / "prog" / "seam.script").read_text(encoding="utf-8")
    assert text.startswith("def seam():\n") and text.endswith("end\nseam()\n")
    assert re.search(r"^  global table=p\[0\.350000000, -0\.250000000, 0\.020000000, ", text,
                     re.MULTILINE)
    assert "movel(pose_trans(table, p[0.050000000, 0.020000000, 0.100000000, " in text
    assert ", v=0.050000000, r=0.002000000)" in text
    code, out, err = run(capsys, "program", "check", tmp_path / "prog" / "seam.script",
                         "--cell", cell_file)
    assert code == 0 and "3 points, all good" in out, out + err


def test_a_script_written_again_into_a_folder_with_spaces_reads_back_the_same(tmp_path, capsys):
    """Written twice into a folder whose name has spaces, for a frame with a 24-character
    name: the same file, and program check reads it both times."""
    folder = tmp_path / "my programs" / "cell A"
    folder.parent.mkdir()
    cell_file = tmp_path / "my cell.yaml"
    name = "fixture_of_the_left_part"
    cell_file.write_text(
        "name: ur5e_cell\nrobot: {model: ur5e}\n"
        "tools:\n  probe: {frame: {x: 0, y: 0, z: 100, a: 0, b: 0, c: 0}}\n"
        f"frames:\n  {name}: {{frame: {{x: 350, y: -250, z: 20, a: 35, b: 0, c: 0}}}}\n")
    path = tmp_path / "seam path.csv"
    path.write_text("x,y,z,a,b,c,motion,speed\n0,0,100,0,180,0,ptp,\n50,20,100,0,180,0,lin,50\n")
    texts = []
    for _ in range(2):
        code, _, err = run(capsys, "program", "write", path, "--cell", cell_file, "--tool",
                           "probe", "--frame", name, "--format", "ur", "-o", folder)
        assert code == 0, err
        script = next(folder.glob("*.script"))
        texts.append(script.read_text(encoding="utf-8"))
        code, out, err = run(capsys, "program", "check", script, "--cell", cell_file)
        assert code == 0 and "2 points, all good" in out, out + err
    assert texts[0] == texts[1] and f"global {name}=p[" in texts[0]


# -- export ----------------------------------------------------------------------------------
def test_the_export_reads_back_to_the_cells_tools_and_frames():
    cell = ur5e_cell()
    text = export_cell(cell, "ur")
    assert "set_tcp(p[0.020000000, -0.010000000, 0.150000000, " in text
    assert "set_payload(1.500000000, [0.000000000, 0.000000000, 0.000000000])" in text
    got, want = parse_export(text, "ur"), UR.data(cell)
    assert [(s.name, s.number) for s in got.tools] == [(s.name, s.number) for s in want.tools]
    for g, w in zip(got.tools + got.frames, want.tools + want.frames, strict=True):
        assert g.name == w.name
        assert_same_pose(g.pose, w.pose, tol_m=1e-9, what=g.name)
    assert got.tools[1].mass == 1.5 and got.tools[0].mass is None
    rng = np.random.default_rng(7)
    for _ in range(20):  # random frames: the rotation vector near 0 and near pi
        angle = rng.choice([rng.uniform(0, 1e-6), rng.uniform(np.pi - 1e-6, np.pi),
                            rng.uniform(0, np.pi)])
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        from scipy.spatial.transform import Rotation
        T = np.eye(4)
        T[:3, :3] = Rotation.from_rotvec(angle * axis).as_matrix()
        T[:3, 3] = rng.uniform(-2, 2, 3)
        cell.update_frame("table", T, cell.frames["table"].provenance)
        back = parse_export(export_cell(cell, "ur"), "ur").frames[0].pose
        assert_same_pose(back, UR.data(cell).frames[0].pose, tol_m=1e-9)


def test_a_frame_whose_name_is_a_urscript_word_is_refused():
    cell = ur5e_cell()
    cell.frames["end"] = cell.frames.pop("table")
    with pytest.raises(InputError, match=r"frame 'end' is not a URScript name"):
        export_cell(cell, "ur")


def test_program_check_of_a_bad_script_exits_2_with_one_error_line(tmp_path, capsys):
    cell_file = tmp_path / "cell.yaml"
    cell_file.write_text("name: c\nrobot: {model: ur5e}\n")
    path = tmp_path / "bad.script"
    path.write_text(GOOD.replace("0.4, -0.1", "nan, -0.1"), encoding="utf-8")
    code, out, err = run(capsys, "program", "check", path, "--cell", cell_file)
    assert code == 2 and out == "" and "Traceback" not in err
    assert err.count("error:") == 1 and "bad.script: line 4: 'nan' is not finite" in err
    path.write_text(GOOD, encoding="utf-8")
    code, out, err = run(capsys, "program", "check", path, "--cell", TRACK_CELL)
    assert code == 2 and err.count("error:") == 1 and "hold no external axes" in err


def test_joint_points_are_retargeted_to_a_recalibrated_cell(tmp_path, capsys):
    old, new = tmp_path / "old.yaml", tmp_path / "new.yaml"
    old.write_text("name: c\nrobot: {model: ur5e}\ntools:\n  probe: {frame: {x: 0, y: 0, "
                   "z: 100, a: 0, b: 0, c: 0}}\n")
    new.write_text("name: c\nrobot: {model: ur5e, frame: {x: 0.4, y: -0.3, z: 0.5, a: 0.1, "
                   "b: 0.05, c: 0}}\ntools:\n  probe: {frame: {x: 0, y: 0, z: 100, a: 0, b: 0, "
                   "c: 0}}\n")
    path = tmp_path / "joints.script"
    path.write_text("def joints():\n  set_tcp(p[0, 0, 0.1, 0, 0, 0])\n"
                    "  movej([0.1, -1.2, 1.3, -1.6, -1.57, 0.2], r=0)\n"
                    "  movel([0.3, -1.2, 1.3, -1.6, -1.57, 0.2], v=0.1, r=0)\nend\njoints()\n")
    code, out, err = run(capsys, "program", "retarget", path, "--from", old, "--to", new, "-o",
                         tmp_path / "rt")
    assert code == 0, err
    back, _ = read_program(tmp_path / "rt" / "joints.script")
    q_old = np.array([[0.1, -1.2, 1.3, -1.6, -1.57, 0.2], [0.3, -1.2, 1.3, -1.6, -1.57, 0.2]])
    q_new = np.stack([p.joints for p in back.points])
    assert 1e-4 < np.max(np.abs(q_new - q_old)) < 0.05      # moved a little, same branch
    a, b = Cell.load(old), Cell.load(new)
    tcp = back.points[0].tool.pose
    T_old = a.T_world_R @ a.robot.fk(q_old) @ tcp
    T_new = b.T_world_R @ b.robot.fk(q_new) @ tcp
    np.testing.assert_allclose(T_new[:, :3, 3], T_old[:, :3, 3], atol=1e-9)


def test_fuzz_mutated_scripts_end_with_a_documented_status(tmp_path, capsys):
    """Seeded mutations of the corpus and of a written script, checked and retargeted:
    exit 0, 2 (one error line) or 3 only, never a traceback, nothing left on refusal."""
    from programs_helpers import outcome_problems, write_mutation
    from test_cli_fuzz import mutate_text

    cell_file = tmp_path / "cell.yaml"
    cell_file.write_text((DATA / "cell.yaml").read_text())
    sources = [*CORPUS, tmp_path / "written.script"]
    program, _ = _random_program(ur5e_cell(), np.random.default_rng(5), "table")
    sources[-1].write_text(UR.write_program(program, ["fuzz"])["random_ur.script"])
    rng = np.random.default_rng(2026)
    failures, codes = [], {}
    for k in range(150):
        src = sources[k % len(sources)]
        text = src.read_text(encoding="utf-8")  # the cp1252 mutation needs cp1252 text
        content, what = mutate_text(text.encode("cp1252", "replace").decode("cp1252"), rng)
        path = tmp_path / f"case{k}.script"
        write_mutation(path, content)
        out = tmp_path / f"out{k}"
        args = (["program", "check", path, "--cell", cell_file] if k % 2 else
                ["program", "retarget", path, "--from", cell_file, "--to", cell_file, "-o", out])
        code, stdout, err = run(capsys, *args)
        codes[code] = codes.get(code, 0) + 1
        problems = outcome_problems(code, stdout, err, out.exists() and any(out.iterdir()))
        if problems:
            failures.append(f"case {k} ({src.name}, {what}): {', '.join(problems)}\n  "
                            f"{err.strip()[-300:]}")
    assert not failures, "\n".join(failures[:6])
    assert codes.get(2, 0) > 0 and (codes.get(0, 0) + codes.get(3, 0)) > 0, codes


def test_an_export_named_as_a_ur_program_is_refused_and_the_ur_export_takes_script(
        tmp_path, capsys):
    cell_file = tmp_path / "cell.yaml"
    cell_file.write_text("name: c\nrobot: {model: ur5e}\n")
    code, _, err = run(capsys, "export", "--cell", cell_file, "--format", "kuka", "-o",
                       tmp_path / "x.script")
    assert code == 2 and "the name says a Universal Robots program" in err
    code, _, err = run(capsys, "export", "--cell", cell_file, "--format", "ur", "-o",
                       tmp_path / "x.src")
    assert code == 2 and "the name says a KUKA program" in err and "name it x.script" in err
    code, _, err = run(capsys, "export", "--cell", cell_file, "--format", "ur", "-o",
                       tmp_path / "x.script")
    assert code == 0 and (tmp_path / "x.script").is_file()


def _script(q_a, pose_w, q_w) -> str:
    def nums(v):
        return ", ".join(f"{x:.12f}" for x in v)
    return (f"def qnear_test():\n  set_tcp(p[0.0, 0.0, 0.0, 0.0, 0.0, 0.0])\n"
            f"  global A_q=[{nums(q_a)}]\n  global W_p=p[{nums(pose_w)}]\n"
            f"  global W_q=[{nums(q_w)}]\n"
            "  movej(A_q, a=1.4, v=1.05)\n"
            "  movej(get_inverse_kin(W_p, qnear=W_q), a=1.4, v=1.05)\n"
            "  movej(A_q, a=1.4, v=1.05)\n"
            "  movej(get_inverse_kin(W_p, W_q), a=1.4, v=1.05)\n"
            "  movej(A_q, a=1.4, v=1.05)\n"
            "  movej(get_inverse_kin(W_p), a=1.4, v=1.05)\n"
            "end\nqnear_test()\n")


def test_get_inverse_kin_takes_the_solution_nearest_to_qnear(tmp_path):
    """A waypoint PolyScope saves as get_inverse_kin(pose, qnear=joints) is checked at the
    solution nearest to its qnear ("the solution closest to qnear", script manual), even where
    the previous point sits at another solution of the same pose; without a qnear, at the one
    nearest to the previous point."""
    cell = ur5e_cell()
    robot = cell.robot
    q_w = np.array([0.3, -1.2, 1.4, -1.5, -1.2, 0.4])
    T = robot.fk(q_w)
    sol = robot.ik(T)
    others = [q for q, ok in zip(sol.q, sol.valid) if ok and np.max(np.abs(q - q_w)) > 0.5]
    q_a = min(others, key=lambda q: np.linalg.norm(q - q_w))   # the same pose, another branch
    path = tmp_path / "qnear_test.script"
    path.write_text(_script(q_a, pose_to_vendor(T, "ur"), q_w))
    report = check_program_file(path, cell)
    q = np.stack([p.q for p in report.points])
    np.testing.assert_allclose(q[1], q_w, atol=1e-9)   # qnear, named
    np.testing.assert_allclose(q[3], q_w, atol=1e-9)   # qnear, second argument
    np.testing.assert_allclose(q[5], q_a, atol=1e-9)   # none: nearest to the previous point
    for p in report.points:
        assert_same_pose(p.T_world_TCP, cell.T_world_R @ T, tol_m=1e-9)
