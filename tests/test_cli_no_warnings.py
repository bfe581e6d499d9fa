"""No numpy warning reaches a user: absurd input is refused where it is read, naming the value.

Before, these inputs printed ``warning: RuntimeWarning: overflow encountered in dot`` (and the
like) and went on, or ended in an unexpected exit. The suite turns warnings into errors
(pyproject.toml), so a warning anywhere in these runs fails them too.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import load_robot
from robotcell.io.tables import write_csv
from robotcell.robot.models import save_robot

ROOT = Path(__file__).resolve().parents[1]
URDF = ROOT / "src" / "robotcell" / "robots" / "urdf" / "ur5e.urdf"
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"


def _refused(capsys, args, match):
    code, out, err = run(capsys, *args)
    assert code == 2 and "Warning" not in out + err, err
    assert match in err and err.count("error:") == 1, err


@pytest.mark.parametrize("old, new, match", [
    ('<origin xyz="0 0 0.1625"', '<origin xyz="0 0 1e308"',
     "joint 'shoulder_pan_joint': origin xyz [0.0, 0.0, 1e+308] m is beyond 100 m"),
    ('<origin xyz="-0.425 0 0"', '<origin xyz="-1e300 0 0"', "origin xyz [-1e+300, 0.0, 0.0] m"),
    ('<origin xyz="-0.425 0 0"', '<origin xyz="nan 0 0"', "origin xyz [nan, 0.0, 0.0] must be finite"),
    ('lower="-3.141592653589793"', 'lower="-1e308"', "limits [-1e+308, 3.14159] reach beyond 1000 rad"),
])
def test_a_urdf_with_absurd_numbers_is_refused_naming_the_joint(tmp_path, capsys, old, new, match):
    text = URDF.read_text()
    assert old in text
    path = tmp_path / "arm.urdf"
    path.write_text(text.replace(old, new, 1))
    _refused(capsys, ["dh", "from-urdf", path], match)


def test_a_urdf_axis_of_1e300_is_a_direction(tmp_path, capsys):
    path = tmp_path / "arm.urdf"
    path.write_text(URDF.read_text().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1e300"/>', 1))
    code, out, err = run(capsys, "dh", "from-urdf", path)
    assert code == 0 and err == "" and "a [mm]" in out


def test_a_model_file_link_of_1e308_mm_is_refused(tmp_path, capsys):
    path = tmp_path / "m.yaml"
    save_robot(load_robot("kuka_kr16"), path)
    text = path.read_text()
    assert "a: 260," in text
    path.write_text(text.replace("a: 260,", "a: 1.0e+308,", 1))
    _refused(capsys, ["fk", path, "--joints", "0,-90,90,0,0,0"],
             "joint 1: key 'a' is 1e+308 mm, beyond 1e+15 mm")


def test_a_target_1e14_mm_away_is_refused_naming_line_and_column(tmp_path, capsys):
    seam = tmp_path / "seam.csv"
    lines = (ROOT / "examples" / "seam_part.csv").read_text().splitlines()
    row = lines[3].split(",")
    row[0] = "1e14"
    seam.write_text("\n".join(lines[:3] + [",".join(row)] + lines[4:]) + "\n")
    for args in (["reach", "--cell", EXAMPLE, seam, "--frame", "part", "--tool", "torch"],
                 ["ik", "--cell", EXAMPLE, "--input", seam, "--frame", "part", "--tool", "torch"]):
        _refused(capsys, args, "a target beyond 100 m, the size of any real cell: line 4, "
                               "column 'x': 1e+14 mm")
    _refused(capsys, ["ik", "kuka_kr16", "--pose", "1e12,0,0,0,90,0"], "--pose: a target beyond")


def test_simulate_height_of_1e300_mm_is_refused(tmp_path, capsys):
    _refused(capsys, ["simulate", "turntable", "--cell", EXAMPLE, "--tool", "pointer", "--height",
                      "-1e300"], "--height must be within +-100000 mm (100 m, the size of any real cell)")


def test_identical_rows_are_one_configuration(tmp_path, capsys):
    robot = load_robot("kuka_kr16")
    q = np.tile([10.0, -60.0, 50.0, 40.0, -20.0, 70.0], (20, 1))
    xyz = robot.fk(np.radians(q))[:, :3, 3] * 1e3
    path = tmp_path / "tracker.csv"
    write_csv(path, [f"a{i}" for i in range(1, 7)] + list("xyz"), np.hstack([q, xyz]))
    _refused(capsys, ["identify", path, "--robot", "kuka_kr16"],
             "20 rows in 1 distinct configuration(s) (the others repeat them) give 3 measured "
             "coordinates")


def test_positioner_touches_all_identical_are_refused(tmp_path, capsys):
    cell = tmp_path / "pos.yaml"
    shutil.copy(ROOT / "examples" / "cell_kr16_positioner.yaml", cell)
    path = tmp_path / "t.csv"
    path.write_text("a1,a2,a3,a4,a5,a6,e1,e2\n" + "-20,-60,80,70,60,50,0,0\n" * 12)
    code, out, err = run(capsys, "calibrate", "positioner", path, "--cell", cell, "--tool",
                         "pointer")
    assert code == 2 and not re.search(r"\w+Warning", out + err), err
