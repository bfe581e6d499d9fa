"""Files as people have them: encodings, spreadsheet CSV dialects, unknown columns, atomic output,
no traceback on the cases of issue 11, and docs that agree with the behaviour."""

from __future__ import annotations

import json
import os
import re
import stat
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import InputError, load_robot, pose_from_vendor
from robotcell.io.fileio import atomic_copy, atomic_write, read_text
from robotcell.io.tables import read_csv, unknown_columns

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"
URDFS = sorted((resources.files("robotcell") / "robots" / "urdf").iterdir(), key=str)


# -- reading --------------------------------------------------------------------------------------
def test_utf8_bom_is_not_part_of_the_first_column(tmp_path):
    p = tmp_path / "bom.csv"
    p.write_bytes(b"\xef\xbb\xbfx,y,z\n1,2,3\n")
    cols = read_csv(p)
    assert list(cols) == ["x", "y", "z"]
    np.testing.assert_array_equal(cols["x"], [1.0])


@pytest.mark.parametrize("encoding", ["cp1252", "latin-1"])
def test_windows_1252_and_latin1_notes_are_read(tmp_path, encoding):
    p = tmp_path / "notes.csv"
    text = "x,y,z,note\n1.5,2,3,Prüfstück à gauche\n4,5,6,Öse ½\n"
    p.write_bytes(text.encode(encoding))
    cols = read_csv(p)
    assert cols["note"] == ["Prüfstück à gauche", "Öse ½"]
    np.testing.assert_array_equal(cols["x"], [1.5, 4.0])


def test_windows_1252_euro_sign_and_undefined_bytes(tmp_path):
    p = tmp_path / "euro.csv"
    p.write_bytes(b"x,note\n1,\x80 \x81\n")  # 0x80 is the euro sign in 1252; 0x81 is undefined
    assert read_csv(p)["note"] == ["€ \x81"]


def test_semicolons_with_decimal_commas_are_read(tmp_path):
    p = tmp_path / "eu.csv"
    p.write_text("x;y;z;e1\n1200,5;-300,25;400;0\n1100;-290,75;400,125;90\n", encoding="utf-8")
    cols = read_csv(p)
    np.testing.assert_array_equal(cols["x"], [1200.5, 1100.0])
    np.testing.assert_array_equal(cols["y"], [-300.25, -290.75])
    np.testing.assert_array_equal(cols["z"], [400.0, 400.125])


def test_thousands_separator_refused_naming_the_dialect(tmp_path):
    p = tmp_path / "eu.csv"
    p.write_text("x;y\n1.234,5;2\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"semicolon-separated with decimal commas \(European "
                                         r"locale\).*'1234,5'"):
        read_csv(p)


def test_decimal_commas_in_a_comma_file_get_a_hint(tmp_path):
    p = tmp_path / "mixed.csv"
    p.write_text("x,y,z\n1,5,2,0,3,0\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"line 2 has 6 values, header has 3 \(decimal commas"):
        read_csv(p)


@pytest.mark.parametrize("content, match", [
    (b"\xff\xfex\x00,\x00y\x00", "UTF-16"),
    (b"x,y\n1,\x002\n", "not a text file"),
    (b"x,y\n1,1e300\n", r"line 2: column 'y' has 1e300, beyond 1e\+15"),
    (b"x,y\n1,nan\n", "NaN or infinite"),
])
def test_unreadable_csv_refused(tmp_path, content, match):
    p = tmp_path / "bad.csv"
    p.write_bytes(content)
    with pytest.raises(InputError, match=match):
        read_csv(p)


def test_unknown_columns_named_with_the_closest_known():
    cols = {"x": 0, "y": 0, "z": 0, "piont": 0, "note": 0, "temperature": 0}
    assert unknown_columns(cols, ["x", "y", "z", "point"]) == [
        "'piont' (did you mean 'point'?)", "'temperature'"]


def test_misspelt_column_is_warned_on_stderr(tmp_path, capsys):
    rows = ["x,y,z,a,b,c,piont"]
    pivot, tcp = np.array([1100.0, -200.0, 300.0]), np.array([10.0, 5.0, 200.0])
    for k in range(5):
        abc = [70.0 * k, 160.0 + 5 * k, 10.0 * np.sin(k)]
        p = pivot - pose_from_vendor([0, 0, 0, *abc], "kuka")[:3, :3] @ tcp
        rows.append(",".join(f"{v:.6f}" for v in [*p, *abc]) + ",tcp")
    f = tmp_path / "tcp.csv"
    f.write_text("\n".join(rows) + "\n")
    code, _, err = run(capsys, "calibrate", "tcp", f)
    assert code in (0, 3)  # the warning comes whatever the verdict
    assert "warning:" in err and "'piont' (did you mean 'point'?) not used by this command" in err


def test_cell_and_model_yaml_in_windows_1252(tmp_path):
    text = EXAMPLE.read_text(encoding="utf-8")
    p = tmp_path / "cell.yaml"
    p.write_bytes(("# Zelle für Schweißen\n" + text).encode("cp1252"))
    from robotcell.cell import Cell
    assert Cell.load(p).name == Cell.load(EXAMPLE).name
    model = tmp_path / "robot.yaml"
    lib = resources.files("robotcell") / "robots" / "kuka_kr16.yaml"
    model.write_bytes(("# Gerät: KR 16, Prüfung\n" + lib.read_text(encoding="utf-8"))
                      .encode("cp1252"))
    np.testing.assert_allclose(load_robot(model).fk(np.zeros(6)),
                               load_robot("kuka_kr16").fk(np.zeros(6)))


def test_read_text_names_a_missing_file_and_a_folder(tmp_path):
    with pytest.raises(InputError, match="cell file '.*nope.yaml' does not exist"):
        read_text(tmp_path / "nope.yaml", "cell file")
    with pytest.raises(InputError, match="does not exist \\(it is a folder\\)"):
        read_text(tmp_path, "cell file")


# -- writing --------------------------------------------------------------------------------------
def test_atomic_write_keeps_permissions_and_refuses_folders(tmp_path):
    p = tmp_path / "out.txt"
    p.write_text("old")
    os.chmod(p, 0o664)
    atomic_write(p, "new")
    assert p.read_text() == "new" and stat.S_IMODE(p.stat().st_mode) == 0o664
    atomic_copy(p, tmp_path / "copy.txt")
    assert stat.S_IMODE((tmp_path / "copy.txt").stat().st_mode) == 0o664
    with pytest.raises(InputError, match="it is a folder"):
        atomic_write(tmp_path, "x")
    with pytest.raises(InputError, match="the folder '.*missing' does not exist"):
        atomic_write(tmp_path / "missing" / "out.txt", "x")
    assert sorted(q.name for q in tmp_path.iterdir()) == ["copy.txt", "out.txt"]


def test_failed_atomic_write_keeps_old_file_and_leaves_no_temporary(tmp_path, monkeypatch):
    p = tmp_path / "out.txt"
    p.write_text("old")

    def boom(*args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(InputError, match="cannot write .*out.txt: No space left on device"):
        atomic_write(p, "new")
    assert p.read_text() == "old" and [q.name for q in tmp_path.iterdir()] == ["out.txt"]


@pytest.fixture
def joints_csv(tmp_path):
    f = tmp_path / "joints.csv"
    f.write_text("a1,a2,a3,a4,a5,a6\n0,-90,90,0,0,0\n10,-80,80,0,30,0\n")
    return f


@pytest.fixture
def poses_csv(tmp_path):
    f = tmp_path / "poses.csv"
    f.write_text("x,y,z,a,b,c\n1200,0,1200,0,90,0\n")
    return f


def _commands(tmp_path, joints_csv, poses_csv):
    return {
        "export": ["export", "--cell", EXAMPLE, "--format", "kuka"],
        "fk": ["fk", "kuka_kr16", "--input", joints_csv],
        "ik": ["ik", "kuka_kr16", "--input", poses_csv],
        "simulate": ["simulate", "frame", "--cell", EXAMPLE, "--tool", "pointer", "--seed", "1"],
    }


@pytest.mark.parametrize("command", ["export", "fk", "ik", "simulate"])
def test_output_into_missing_folder_or_onto_folder_refused(tmp_path, capsys, joints_csv,
                                                           poses_csv, command):
    args = _commands(tmp_path, joints_csv, poses_csv)[command]
    before = sorted(tmp_path.iterdir())
    code, out, err = run(capsys, *args, "-o", tmp_path / "nodir" / "out.txt")
    assert code == 2 and "Traceback" not in out + err
    assert re.search(r"^error: cannot write .*out.txt: the folder '.*nodir' does not exist", err)
    code, out, err = run(capsys, *args, "-o", tmp_path)
    assert code == 2 and "Traceback" not in out + err
    assert re.search(r"^error: cannot write .*: it is a folder; give a file name", err, re.MULTILINE)
    assert sorted(tmp_path.iterdir()) == before


@pytest.mark.parametrize("command", ["export", "fk", "ik", "simulate"])
def test_output_written_atomically_with_permissions_kept(tmp_path, capsys, joints_csv,
                                                        poses_csv, command):
    args = _commands(tmp_path, joints_csv, poses_csv)[command]
    target = tmp_path / "out.txt"
    target.write_text("old")
    os.chmod(target, 0o640)
    code, _out, _ = run(capsys, *args, "-o", target)
    assert code == 0 and target.read_text() not in ("old", "")
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
    assert not [q for q in tmp_path.iterdir() if q.name.endswith(".tmp")]


def _turntable_csv(tmp_path):
    from robotcell.kinematics.transforms import rot_z

    T = pose_from_vendor([2000, 900, 200, 90, 0.2, -0.1], "kuka")
    theta = np.radians([0.0, 60.0, 120.0, 180.0, 240.0, 300.0])
    f = ((rot_z(theta) @ [0.35, 0.0, 0.05]) @ T[:3, :3].T + T[:3, 3]) * 1e3
    f += np.random.default_rng(3).normal(0, 0.05, f.shape)
    p = tmp_path / "table.csv"
    p.write_text("x,y,z,e1\n" + "\n".join(
        ",".join(f"{v:.4f}" for v in [*fi, np.degrees(t)]) for fi, t in zip(f, theta)) + "\n")
    return p


def test_json_with_o_keeps_a_good_file_when_a_later_run_is_refused(tmp_path, capsys):
    table = _turntable_csv(tmp_path)
    result = tmp_path / "turntable.json"
    code, out, err = run(capsys, "calibrate", "turntable", table, "--json", "-o", result)
    assert code == 0 and f"wrote {result}" in err
    assert "calibration: turntable" in out  # the terminal shows the report
    good = result.read_text()
    assert json.loads(good)["procedure"] == "turntable"
    code, stdout, _ = run(capsys, "calibrate", "turntable", table, "--json")
    assert json.loads(stdout) == json.loads(good)
    # A refused run (here a missing file) leaves the good file as it was, and nothing else.
    code, _, err = run(capsys, "calibrate", "turntable", tmp_path / "typo.csv", "--json",
                       "-o", result)
    assert code == 2 and err.startswith("error:")
    assert result.read_text() == good
    assert sorted(q.name for q in tmp_path.iterdir()) == ["table.csv", "turntable.json"]
    code, _, err = run(capsys, "calibrate", "turntable", table, "-o", tmp_path / "no" / "r.txt")
    assert code == 2 and "does not exist" in err and not (tmp_path / "no").exists()


def test_calibrate_o_without_json_writes_the_report(tmp_path, capsys):
    table = _turntable_csv(tmp_path)
    code, out, _ = run(capsys, "calibrate", "turntable", table, "-o", tmp_path / "r.txt")
    assert code == 0 and (tmp_path / "r.txt").read_text().strip() == out.strip()


# -- no traceback ---------------------------------------------------------------------------------
@pytest.mark.parametrize("value", ["-3", "0", "1", "2"])
def test_simulate_touches_below_the_minimum_refused_up_front(tmp_path, capsys, value):
    code, out, err = run(capsys, "simulate", "turntable", "--cell", EXAMPLE, "--tool", "pointer",
                         "--touches", value, "-o", tmp_path / "t.csv")
    assert code == 2 and "Traceback" not in out + err
    assert f"needs at least 3 table angles (touches), got {value}" in err
    code, _, err = run(capsys, "simulate", "tcp", "--cell", EXAMPLE, "--tool", "torch",
                       "--touches", value, "-o", tmp_path / "t.csv")
    assert code == 2 and "at least 3 touches of the reference point" in err
    assert list(tmp_path.iterdir()) == []


def test_simulate_minimum_files_are_accepted_by_calibrate(tmp_path, capsys):
    csv = tmp_path / "t.csv"
    code, _, err = run(capsys, "simulate", "turntable", "--cell", EXAMPLE, "--tool", "pointer",
                       "--touches", "3", "--seed", "2", "-o", csv)
    assert code == 0
    copy = tmp_path / "cell_calibrated.yaml"
    copy.write_bytes(EXAMPLE.read_bytes())
    code, _, _ = run(capsys, "calibrate", "turntable", csv, "--cell", copy, "--tool", "pointer",
                     "--height=-50")
    assert code in (0, 3)  # accepted (3 touches leave no redundancy: the verdict may say so)
    code, _, err = run(capsys, "simulate", "turntable", "--cell", EXAMPLE, "--tool", "pointer",
                       "--angles", "0,90")
    assert code == 2 and "needs at least 3 table angles, got 2" in err
    code, _, err = run(capsys, "simulate", "track", "--cell", EXAMPLE, "--tool", "pointer",
                       "--reference", "1500,0,100", "--positions", "2")
    assert code == 2 and "needs at least 3 touches; 1 reference point(s) x 2 positions" in err


@pytest.mark.parametrize("option, value, message", [
    ("--radius", "-300", "--radius must be a positive number of millimetres, got -300"),
    ("--radius", "0", "--radius must be a positive number of millimetres, got 0"),
    ("--height", "nan", "--height must be a finite number of millimetres, got nan"),
    ("--track", "inf", "--track must be a finite number of millimetres, got inf"),
])
def test_simulate_lengths_refused_in_millimetres(capsys, option, value, message):
    code, _, err = run(capsys, "simulate", "turntable", "--cell", EXAMPLE, "--tool", "pointer",
                       option, value)
    assert code == 2 and message in err and "(m)" not in err


@pytest.mark.parametrize("procedure, option, value, message", [
    ("track", "--travel", "-100", "--travel must be a positive number of millimetres, got -100"),
    ("frame", "--size", "-5", "--size must be a positive number of millimetres, got -5"),
    ("frame", "--repeats", "100", "300 touches asked for; a simulation places at most 200"),
    ("tcp", "--seed", "-1", "Invalid value for '--seed'"),
    ("turntable", "--touches", "1000000000000", "a simulation places at most 200 touches"),
])
def test_simulate_design_options_refused(capsys, procedure, option, value, message):
    code, out, err = run(capsys, "simulate", procedure, "--cell", EXAMPLE, "--tool", "pointer",
                         option, value)
    assert code == 2 and message in err and "Traceback" not in out + err


def test_simulate_follow_up_calibrates_a_copy_not_the_truth(tmp_path, capsys):
    truth = tmp_path / "truth.yaml"
    truth.write_bytes(EXAMPLE.read_bytes())
    csv = tmp_path / "tt.csv"
    code, _, err = run(capsys, "simulate", "turntable", "--cell", truth, "--tool", "pointer",
                       "--seed", "1", "-o", csv)
    assert code == 0
    copy = tmp_path / "truth_calibrated.yaml"
    lines = [ln.strip() for ln in err.splitlines()]
    assert f"cp {truth} {copy}" in lines
    hint = next(ln for ln in lines if ln.startswith("robotcell calibrate"))
    assert f"--cell {copy} " in hint and f"--cell {truth} " not in hint
    # The printed commands work, and leave the truth as it was.
    copy.write_bytes(truth.read_bytes())
    before = truth.read_bytes()
    code, _, _ = run(capsys, *hint.split()[1:])
    assert code == 0 and truth.read_bytes() == before and copy.read_bytes() != before


def test_turntable_file_with_1e300_refused(tmp_path, capsys):
    table = _turntable_csv(tmp_path)
    lines = table.read_text().splitlines()
    lines[3] = "1e300," + lines[3].split(",", 1)[1]
    table.write_text("\n".join(lines) + "\n")
    code, out, err = run(capsys, "calibrate", "turntable", table)
    assert code == 2 and "Traceback" not in out + err
    assert "line 4: column 'x' has 1e300, beyond 1e+15 in size" in err


def test_non_utf8_binary_csv_and_yaml_refused_without_traceback(tmp_path, capsys):
    junk = tmp_path / "junk.csv"
    junk.write_bytes(bytes(range(256)))
    code, out, err = run(capsys, "calibrate", "tcp", junk)
    assert code == 2 and "not a text file" in err and "Traceback" not in out + err
    code, out, err = run(capsys, "cell", "show", junk)
    assert code == 2 and "not a text file" in err and "Traceback" not in out + err


@pytest.mark.parametrize("change, message", [
    (lambda d: d.update(residuals_mm="abc"), "'residuals_mm' must be a list of numbers"),
    (lambda d: d.update(rms_mm=None), "'rms_mm' must be a number"),
    (lambda d: d.update(condition="x"), "'condition' has the wrong type or size"),
    (lambda d: d.update(matrix=[[1, 2], [3]]), "'matrix' has the wrong type or size"),
    (lambda d: d.update(labels=[1]), "'labels' has the wrong type or size"),
    (lambda d: d.update(warnings=0), "'warnings' must be a list of texts"),
    (lambda d: d.update(residuals_xyz_mm=[[1, 2]]), "'residuals_xyz_mm' has the wrong type"),
    (lambda d: d.update(unchecked=True), "'unchecked' has the wrong type or size"),
    (lambda d: d.update(outliers=-1.0), "'outliers' has the wrong type or size"),
    (lambda d: d.update(dof=[1, 2]), "'dof' has the wrong type or size"),
    (lambda d: d.update(noise_sigma_mm="x"), "'noise_sigma_mm' has the wrong type or size"),
    (lambda d: d.update(accuracy_source=3), "'accuracy_source' has the wrong type or size"),
    (lambda d: d.update(height_mm=[[1, 2], [3]]), "'height_mm' must be a number"),
    (lambda d: d.update(axis=[0, 1]), "'axis' must be a list of 3 numbers"),
    (lambda d: d.update(matrix=None), "'matrix' must be a 4x4 list of numbers"),
    (lambda d: d.update(axis=[1e300, 0, 0]), "'axis' must be a unit vector"),
    (lambda d: d["sigma"].update(radius_mm=[[1, 2], [3]]), "'sigma' has the wrong type or size"),
])
def test_report_on_malformed_result_json(tmp_path, capsys, change, message):
    table = _turntable_csv(tmp_path)
    good = tmp_path / "tt.json"
    run(capsys, "calibrate", "turntable", table, "--json", "-o", good)
    data = json.loads(good.read_text())
    change(data)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    code, out, err = run(capsys, "report", bad, "-o", tmp_path / "out" / "r.html")
    assert code == 2 and message in err and "Traceback" not in out + err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("change, message", [
    (lambda c: c[:5], "must be a 6x6 array of finite numbers, got shape \\(5, 6\\)"),
    (lambda c: [row[:5] for row in c[:5]] + [[1]], "must be a 6x6 array of numbers"),
    (lambda c: [[v if (i, j) != (0, 1) else 5.0 for j, v in enumerate(r)]
                for i, r in enumerate(c)], "is not a covariance"),
    (lambda c: [[-abs(v) if i == j else v for j, v in enumerate(r)] for i, r in enumerate(c)],
     "is not a covariance"),
    (lambda c: "abc", "must be a 6x6 array of numbers"),
])
def test_malformed_turntable_covariance_refused(tmp_path, capsys, change, message):
    table = _turntable_csv(tmp_path)
    tt = tmp_path / "tt.json"
    assert run(capsys, "calibrate", "turntable", table, "--json", "-o", tt)[0] == 0
    data = json.loads(tt.read_text())
    key = "T_R_B_covariance_mm_rad"
    data[key] = change(data[key])
    tt.write_text(json.dumps(data))
    wp = tmp_path / "wp.csv"
    wp.write_text("point,x,y,z,e1\norigin,2100,900,250,0\nx,2250,900,250,0\nxy,2100,1000,250,0\n")
    code, out, err = run(capsys, "calibrate", "workpiece", wp, "--turntable", tt)
    assert code == 2 and f"'{key}' " in err and re.search(message, err)
    assert "Traceback" not in out + err


def _random_urdf(rng: np.random.Generator, n: int = 6) -> str:
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = []
    for i in range(n):
        xyz = " ".join(f"{v:.4f}" for v in rng.uniform(-0.4, 0.4, 3))
        rpy = " ".join(f"{v:.4f}" for v in rng.uniform(-np.pi, np.pi, 3))
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        kind = "prismatic" if rng.random() < 0.15 else "revolute"
        joints.append(f'<joint name="j{i + 1}" type="{kind}"><parent link="l{i}"/>'
                      f'<child link="l{i + 1}"/><origin xyz="{xyz}" rpy="{rpy}"/>'
                      f'<axis xyz="{axis[0]:.6f} {axis[1]:.6f} {axis[2]:.6f}"/>'
                      '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    return f'<robot name="random">{links}{"".join(joints)}</robot>'


def _check_from_urdf(capsys, urdf: Path, out: Path, convention: str) -> None:
    from robotcell.dhprocedure import read_urdf

    code, stdout, err = run(capsys, "dh", "from-urdf", urdf, "--convention", convention, "-o", out)
    assert code == 0, err
    assert "Traceback" not in stdout + err
    model = load_robot(out)
    q = np.random.default_rng(5).uniform(-1, 1, (20, model.n_joints))
    # The file holds mm to 9 decimals and degrees to 12: FK agrees to 1e-9 m.
    assert np.abs(model.fk(q) - read_urdf(str(urdf)).fk(q)).max() < 1e-9


@pytest.mark.parametrize("urdf", URDFS, ids=lambda p: Path(str(p)).stem)
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_dh_from_urdf_writes_plain_floats_for_shipped_urdfs(tmp_path, capsys, urdf, convention):
    _check_from_urdf(capsys, Path(str(urdf)), tmp_path / "model.yaml", convention)


def test_dh_from_urdf_writes_random_serial_chains(tmp_path, capsys):
    rng = np.random.default_rng(25)
    for k in range(25):
        urdf = tmp_path / f"chain{k}.urdf"
        urdf.write_text(_random_urdf(rng))
        _check_from_urdf(capsys, urdf, tmp_path / f"chain{k}.yaml",
                         "modified" if k % 2 else "standard")


def test_unexpected_failure_is_one_line_not_a_traceback(capsys, monkeypatch):
    import robotcell.cli.export as export_cli

    def broken(*args, **kwargs):
        raise RuntimeError("simulated defect")

    monkeypatch.setattr(export_cli, "export_cell", broken)
    code, out, err = run(capsys, "export", "--cell", EXAMPLE, "--format", "kuka")
    assert code == 1 and "Traceback" not in out + err
    assert err.startswith("error: unexpected RuntimeError: simulated defect")
    assert "please report it" in err


# -- docs and behaviour ---------------------------------------------------------------------------
def test_usage_errors_say_error_in_lower_case_and_exit_2(capsys):
    code, _, err = run(capsys, "fk", "kuka_kr16", "--bogus")
    assert code == 2 and "error: No such option '--bogus'" in err and "Error:" not in err


def test_unreachable_pose_exits_2_with_error(capsys):
    code, _out, err = run(capsys, "ik", "kuka_kr16", "--pose", "1200,0,1500,0,90,0")
    assert code == 2 and err.startswith("error: no valid solution") and "Error:" not in err


def test_readme_ik_example_is_reachable(capsys):
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    commands = re.findall(r"^robotcell (ik kuka_kr16 --pose \S+.*)$", readme, re.MULTILINE)
    assert commands
    for command in commands:
        code, out, _ = run(capsys, *command.split())
        assert code == 0 and " yes " in out


def test_references_exist_and_no_citation_of_a_missing_file():
    refs = ROOT / "docs" / "references.md"
    text = refs.read_text(encoding="utf-8")
    for fact in ("Rz(A) Ry(B) Rx(C)", "Rz(R) Ry(P) Rx(W)", "orient", "$config.dat",
                 "4.7 us/pose", "DHRobot.fkine"):
        assert fact in text
    cited = []
    for p in [ROOT / "README.md", *ROOT.glob("docs/*.md"), *ROOT.glob("tests/*.py"),
              *ROOT.glob("benchmarks/*.py"), *ROOT.glob("src/robotcell/**/*.py")]:
        body = p.read_text(encoding="utf-8")
        if re.search(r"(?<![\w/])REFERENCES\.md|/work/shared", body) and p.name != "test_files.py":
            cited.append(p.name)
    assert cited == []


def test_european_csv_gives_the_same_calibration(tmp_path, capsys):
    table = _turntable_csv(tmp_path)
    eu = tmp_path / "eu.csv"
    eu.write_bytes(b"\xef\xbb\xbf" + table.read_text().replace(",", ";").replace(".", ",")
                   .encode("utf-8"))
    _, plain, _ = run(capsys, "calibrate", "turntable", table, "--json")
    code, european, err = run(capsys, "calibrate", "turntable", eu, "--json")
    assert code == 0 and "warning" not in err
    assert json.loads(european)["matrix"] == json.loads(plain)["matrix"]


def test_plan_refuses_a_missing_output_folder_before_any_work(tmp_path, capsys):
    code, out, err = run(capsys, "plan", "turntable", "--cell", EXAMPLE, "--tool", "pointer",
                         "-o", tmp_path / "nodir" / "touches.csv")
    assert code == 2 and "the folder" in err and "does not exist" in err
    assert "plan for" not in out  # refused before the designs were compared


def test_plan_refuses_huge_counts_up_front(capsys):
    code, out, err = run(capsys, "plan", "turntable", "--cell", EXAMPLE, "--tool", "pointer",
                         "--touches", "1000000000000")
    assert code == 2 and "a simulation places at most 200 touches" in err
    assert "Traceback" not in out + err


def test_poor_calibration_writes_no_output_file(tmp_path, capsys):
    table = _turntable_csv(tmp_path)
    lines = table.read_text().splitlines()
    for k in (2, 4):  # two touches 50 mm off (one alone would be left out): a poor verdict
        x, rest = lines[k].split(",", 1)
        lines[k] = f"{float(x) + 50.0:.4f},{rest}"
    table.write_text("\n".join(lines) + "\n")
    result = tmp_path / "tt.json"
    code, out, err = run(capsys, "calibrate", "turntable", table, "--json", "-o", result)
    assert code == 3 and not result.exists() and "Traceback" not in out + err
    code, _, _ = run(capsys, "calibrate", "turntable", table, "--json", "-o", result,
                     "--accept-poor")
    assert code == 0 and json.loads(result.read_text())["procedure"] == "turntable"


def test_o_with_single_pose_writes_the_file(tmp_path, capsys):
    out = tmp_path / "pose.csv"
    code, stdout, _ = run(capsys, "fk", "kuka_kr16", "--joints", "0,-90,90,0,0,0", "-o", out)
    assert code == 0 and stdout == ""
    row = "1088.000000,0.000000,1320.000000,0.000000,0.000000,0.000000"
    assert out.read_text().splitlines() == ["X,Y,Z,A,B,C", row]
    table = tmp_path / "ik.txt"
    code, stdout, _ = run(capsys, "ik", "kuka_kr16", "--pose", "1200,0,1200,0,90,0", "-o", table)
    assert code == 0 and stdout == "" and "0 front up" in table.read_text()


def test_read_only_file_is_not_replaced(tmp_path, capsys):
    from robotcell.cell import Cell

    cell = tmp_path / "cell.yaml"
    cell.write_bytes(EXAMPLE.read_bytes())
    os.chmod(cell, 0o444)
    before = cell.read_bytes()
    with pytest.raises(InputError, match=r"the file is read-only \(mode 444\)"):
        Cell.load(cell).save(cell)
    out = tmp_path / "kuka.dat"
    out.write_text("kept")
    os.chmod(out, 0o444)
    code, _, err = run(capsys, "export", "--cell", cell, "--format", "kuka", "-o", out)
    assert code == 2 and "the file is read-only (mode 444)" in err
    assert cell.read_bytes() == before and out.read_text() == "kept"
    assert stat.S_IMODE(cell.stat().st_mode) == 0o444
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cell.yaml", "kuka.dat"]  # no .bak


# The suite turns warnings into errors; this test shows what a user sees when one is shown.
@pytest.mark.filterwarnings("default::RuntimeWarning")
def test_python_warning_is_one_line_without_source(capsys, monkeypatch):
    import warnings

    import robotcell.cli.export as export_cli

    real = export_cli.export_cell

    def noisy(*args, **kwargs):
        warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=1)
        return real(*args, **kwargs)

    monkeypatch.setattr(export_cli, "export_cell", noisy)
    code, _, err = run(capsys, "export", "--cell", EXAMPLE, "--format", "kuka")
    assert code == 0
    assert err == "warning: RuntimeWarning: overflow encountered in multiply\n"


@pytest.mark.parametrize("option", ["-o", "--html"])
def test_reach_and_sweep_outputs_checked_before_work(tmp_path, capsys, poses_csv, option):
    code, out, err = run(capsys, "reach", poses_csv, "--cell", EXAMPLE, "--tool", "pointer",
                         option, tmp_path / "nodir" / "reach.out")
    assert code == 2 and "the folder" in err and "does not exist" in err
    code, out, err = run(capsys, "reach", poses_csv, "--cell", EXAMPLE, "--tool", "pointer",
                         option, tmp_path)
    assert code == 2 and "it is a folder" in err and "Traceback" not in out + err
    code, out, err = run(capsys, "sweep", "--cell", EXAMPLE, "--targets", poses_csv, "--layouts",
                         tmp_path / "l.yaml", "-o", tmp_path / "nodir" / "sweep.csv")
    assert code == 2 and "the folder" in err and "Traceback" not in out + err
