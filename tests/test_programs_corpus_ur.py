"""The URScript corpus read as meant (tests/data/programs/ur/, sources in its README.md): files
of statements at the top, PolyScope X's set_tcp with a name, poses composed with pose_add,
one-line blocks, a function's parameters and poses of expressions; and what is not a program
refused with its cause and line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.programs import read_program

DATA = Path(__file__).resolve().parent / "data" / "programs" / "ur"
ADDED = ["excerpts/interactive_cubes.script", "excerpts/polyscopex_application.script",
         "urscript_examples/admittance_control.script", "pharmbio/dan_to_out18.script"]


def test_waypoints_composed_with_pose_add_and_one_line_blocks_are_read():
    program, skipped = read_program(DATA / "excerpts" / "interactive_cubes.script")
    assert program.name == "interactive_cubes"  # no def around the statements: the file's name
    p = program.points
    assert [(x.name, x.line, x.motion) for x in p] == [
        ("home_p", 22, "ptp"), ("WP_Left", 27, "ptp"), ("WP_Up", 28, "ptp"), ("WP_Up", 29, "lin")]
    home = pose_from_vendor([0.5, -0.1, 0.45, 0.0, 3.14159265359, 0.0], "ur")
    np.testing.assert_allclose(p[0].pose, home, atol=1e-12)
    np.testing.assert_allclose(p[0].near, [0, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0],
                               atol=1e-11)  # get_inverse_kin(home_p, qnear=home_q)
    # pose_add: positions added, rotations multiplied (here the same), a chain of two
    np.testing.assert_allclose(p[1].pose[:3, 3], [0.5, -0.3, 0.45], atol=1e-12)
    np.testing.assert_allclose(p[2].pose[:3, 3], [0.5, -0.3, 0.55], atol=1e-12)
    np.testing.assert_allclose(p[2].pose[:3, :3], home[:3, :3], atol=1e-12)
    assert p[1].where.endswith(":6") and p[2].where.endswith(":7")
    assert (p[3].speed, p[3].zone) == (pytest.approx(0.25), pytest.approx(0.01))
    assert skipped == [
        "line 16: movel(p[x, y, z, rx, ry, rz]) (a pose of values computed at run time)",
        "line 19: movel(home_p) (home_p is a parameter of the function, set by each call)"]


def test_pose_add_rotates_by_the_product_of_the_rotations(tmp_path):
    a = pose_from_vendor([0.1, 0.2, 0.3, 0.3, -0.2, 0.1], "ur")
    b = pose_from_vendor([0.0, 0.0, 0.1, 0.0, 0.5, 0.0], "ur")
    text = ("global a=p[0.1, 0.2, 0.3, 0.3, -0.2, 0.1]\n"
            "global c = pose_add(a, p[0.0, 0.0, 0.1, 0.0, 0.5, 0.0])\n"
            "global d = pose_trans(a, p[0.0, 0.0, 0.1, 0.0, 0.5, 0.0])\n"
            "movel(c, v=0.1)\nmovel(d, v=0.1)\n")
    got = _read(text, tmp_path)
    np.testing.assert_allclose(got.points[0].pose[:3, 3], a[:3, 3] + b[:3, 3], atol=1e-12)
    np.testing.assert_allclose(got.points[0].pose[:3, :3], a[:3, :3] @ b[:3, :3], atol=1e-12)
    np.testing.assert_allclose(got.points[1].pose, a @ b, atol=1e-12)


def test_polyscope_x_statements_and_a_named_tcp_are_read():
    program, skipped = read_program(DATA / "excerpts" / "polyscopex_application.script")
    assert program.name == "polyscopex_application"
    p = program.points
    assert [(x.name, x.motion) for x in p] == [("line 25", "ptp"), ("line 26", "lin")]
    # set_tcp(p[0, 0, 0.15, 0, 0, 0], "Gripper"): the pose is the first argument
    for x in p:
        np.testing.assert_allclose(x.tool.pose[:3, 3], [0.0, 0.0, 0.15])
    np.testing.assert_allclose(p[0].joints, [0, -1.5707963268, 1.5707963268, -1.5707963268,
                                             -1.5707963268, 0])
    np.testing.assert_allclose(p[1].pose[:3, 3], [0.5, -0.2, 0.3])
    assert p[1].speed == pytest.approx(0.25)
    assert skipped == ["line 17: movel(target_pose) (target_pose is a variable set at run time "
                       "or not given a value in this file)"]


def test_a_library_of_functions_is_read_with_its_motions_named():
    program, skipped = read_program(DATA / "urscript_examples" / "admittance_control.script")
    assert program.name == "admittance_control" and program.points == []
    assert skipped == ["line 244: speedl (a speed motion is not checked)"]


def test_a_global_hidden_by_a_parameter_is_read_only_outside_the_function(tmp_path):
    text = ("global home_p=p[.5, -.1, .45, 0, 3.14159, 0]\n"
            "def go(home_p, up=p[0, 0, 0.1, 0, 0, 0]):\n"
            "  local t = pose_add(home_p, up)\n"
            "  movel(t, v=0.1)\n"
            "  movel(home_p, v=0.1)\n"
            "end\n"
            "global above = pose_add(home_p, p[0, 0, 0.1, 0, 0, 0])\n"
            "movel(above, v=0.1)\nmovel(home_p, v=0.1)\ngo(above)\n")
    program = _read(text, tmp_path)
    assert [(x.name, x.line) for x in program.points] == [("above", 8), ("home_p", 9)]
    np.testing.assert_allclose(program.points[0].pose[:3, 3], [0.5, -0.1, 0.55], atol=1e-12)


def test_a_first_def_with_statements_after_it_is_a_function_not_the_program(tmp_path):
    path = tmp_path / "lib.ur.script"
    path.write_text("def helper():\n  sleep(1)\nend\nmovej([0, -1.57, 1.57, -1.57, -1.57, 0])\n")
    program, skipped = read_program(path)
    assert program.name == "lib" and len(program.points) == 1 and not skipped
    path.write_text("sec io_watch():\n  set_digital_out(0, True)\nend\n")
    assert read_program(path)[0].name == "io_watch"


def _read(text: str, folder: Path):
    """The program of ``text`` read as a URScript file in ``folder``."""
    path = folder / "prog.script"
    path.write_text(text, encoding="utf-8")
    return read_program(path)[0]


@pytest.mark.parametrize("text,match", [
    ("# Placeholder file for unit test\n\n",
     r"prog\.script: no URScript statement, only comments or blank lines: not a URScript"),
    ("confirm user safety parameters\npower on\ndef prog():\n  sleep(1)\nend\n",
     r"prog\.script: line 1: 'confirm user safety parameters' is not a URScript statement"),
    ("def harness():\n  {{ test_script_code }}\nend\n",
     r"line 2: '\{\{ test_script_code \}\}' is not a URScript statement"),
    ("# HEADER_BEGIN\n    global reg_offset_float = # float register offset\n",
     r"line 2: 'global reg_offset_float =' assigns no value \(a template"),
    ("def f(x):\n  movel(p[x, 0, 0, 0, 0], v=0.1)\nend\nmovel(p[0.4, 0, 0.3, 0, 3.1, 0])\n"
     "movel(p[0.4, 0, 0.3, 0, 3.1], v=0.1)\n", r"line 5: a pose is p\[x, y, z, rx, ry, rz\]"),
    ("def f(x):\n  local q = pose_inv(p[nan, 0, 0, x[3], x[4], x[5]])\nend\n",
     r"line 2: 'nan' is not finite"),
    ("if (n == 1): movej([0, -1.57, 1.57, -1.57, -1.57, 0])\n",
     r"line 1: 1 block\(s\) not closed by 'end' \(truncated file\?\)"),
])
def test_text_that_is_no_urscript_program_is_refused_naming_the_cause(text, match, tmp_path):
    path = tmp_path / "prog.script"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=match):
        read_program(path)


def _broken(text: str, how: str) -> bytes:
    if how == "truncated":  # cut inside the last motion
        return text[:text.rindex("movel(") + 12].encode()
    if how == "not UTF-8":
        return text.encode("utf-16")
    return text.replace("p[.500000000000", "p[nan", 1).replace("p[0.5, -0.2", "p[nan, -0.2",
                                                               1).encode()


@pytest.mark.parametrize("how", ["truncated", "not UTF-8", "a NaN"])
@pytest.mark.parametrize("name", ADDED[:2])
def test_a_broken_copy_of_an_added_file_is_refused_with_one_error_line(name, how, tmp_path,
                                                                       capsys):
    path = tmp_path / Path(name).name
    path.write_bytes(_broken((DATA / name).read_text(encoding="utf-8"), how))
    code, out, err = run(capsys, "program", "check", path, "--cell", DATA / "cell.yaml")
    assert code == 2 and out == ""
    assert err.count("error:") == 1 and err.startswith(f"error: {path}") and "Traceback" not in err
