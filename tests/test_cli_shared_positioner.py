"""``robotcell calibrate shared-positioner``: two robots' calibrations of the two-robot demo cell's
positioner compared, and all their touches in one fit, from the files the demo writes."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from cli_helpers import run
from shared_positioner_helpers import demo_folder, shared_args

from robotcell.cell import Cell
from robotcell.cell.calibrate.robottorobot import RobotTouchFile
from robotcell.cell.calibrate.sharedpositioner import shared_positioner
from robotcell.errors import InputError


@pytest.fixture(scope="module")
def demo(tmp_path_factory) -> Path:
    """The two-robot demo's folder: the calibrated cell and every touch file."""
    return demo_folder(tmp_path_factory.mktemp("demo2"))


def _tool_off(d: Path, mm: float) -> str:
    """A copy of the calibrated cell with the ABB's torch ``mm`` off along the flange's X."""
    text = (d / "cell.yaml").read_text(encoding="utf-8")
    abb = text.index("  abb:")
    start = text.index("frame: {x: ", text.index("torch:", abb))
    x = re.match(r"frame: \{x: ([-\d.]+)", text[start:])
    assert x is not None
    text = text[:start] + f"frame: {{x: {float(x.group(1)) + mm}" + text[start + x.end():]
    (d / "tool_off.yaml").write_text(text, encoding="utf-8")
    return "tool_off.yaml"


def test_consistent_calibrations_agree_and_the_joint_fit_is_printed(demo, capsys, tmp_path):
    out_file = tmp_path / "shared.json"
    code, out, err = run(capsys, *shared_args(demo), "--json", "-o", out_file)
    assert code == 0, err
    data = json.loads(out_file.read_text(encoding="utf-8"))
    assert data["procedure"] == "robot-to-robot" and data["method"] == "shared positioner"
    assert data["agreement"]["agree"] is True
    assert "positioner agree within 3 sigma" in data["agreement"]["message"]
    assert data["verdict"]["level"] == "good"
    code, out, err = run(capsys, *shared_args(demo))
    assert code == 0 and out.startswith("kuka's and abb's calibrations of the positioner agree")
    assert "T_ref_B (KUKA X,Y,Z mm, A,B,C deg)" in out and "axis_angle (deg)" in out


def test_a_2mm_error_of_one_robots_tool_is_named_and_nothing_written(demo, capsys, tmp_path):
    cell = _tool_off(demo, 2.0)
    out_file = tmp_path / "shared.txt"
    code, _, err = run(capsys, *shared_args(demo, cell), "-o", out_file)
    assert code == 3
    lines = err.strip().splitlines()
    assert lines[-1].startswith("error: kuka's and abb's calibrations of the positioner disagree")
    assert re.search(r"by -?\d+\.\d+ mm \(\d+\.\d sigma\)", lines[-1]), lines[-1]
    assert not out_file.exists()
    code, out, _ = run(capsys, *shared_args(demo, cell), "--accept-poor")
    assert code == 0 and "disagree" in out


@pytest.mark.parametrize(("change", "message"), [
    (("--robot", "fanuc"), "fanuc"),
    (("--tool-other", "welder"), "robot 'abb' has no tool 'welder'; its tools: pointer, torch"),
    (("--track-ref", "500"), ("column 'track' differs from the track position 500 mm of robot "
                             "'kuka'")),
    (("--robot", "kuka"), "the reference and the other robot are both 'kuka'"),
    (("--tool-sigma", "0"), "--tool-sigma must be a positive number"),
])
def test_bad_input_exits_2_with_one_error_line_and_writes_nothing(demo, capsys, tmp_path,
                                                                  change, message):
    args = [str(a) for a in shared_args(demo)]
    i = args.index(change[0])
    args[i + 1] = change[1]
    out_file = tmp_path / "shared.txt"
    before = (demo / "cell.yaml").read_bytes()
    code, _, err = run(capsys, *args, "-o", out_file)
    assert code == 2, err
    assert err.count("error:") == 1 and message in err and "Traceback" not in err
    assert not out_file.exists() and (demo / "cell.yaml").read_bytes() == before


def test_output_onto_an_input_is_refused(demo, capsys):
    common = demo / "robot_to_robot_abb.txt"  # a touch file named as the report would be
    shutil.copy(demo / "robot_to_robot_abb.csv", common)
    before = common.read_bytes()
    args = [str(a) for a in shared_args(demo)]
    args[args.index("--common") + 2] = str(common)
    code, _, err = run(capsys, *args, "-o", common)
    assert code == 2 and err.count("error:") == 1
    assert "names the same file as --common" in err and common.read_bytes() == before


def test_a_cell_without_a_shared_positioner_is_refused(demo):
    cell = Cell.load(demo / "cell.yaml")
    cell.turntable = None
    common = (RobotTouchFile("kuka", str(demo / "robot_to_robot_kuka.csv"), "torch", 1.0),
              RobotTouchFile("abb", str(demo / "robot_to_robot_abb.csv"), "torch"))
    with pytest.raises(InputError, match="the cell has no 2-axis positioner in the world"):
        shared_positioner(cell, common, (str(demo / "positioner_kuka.csv"),
                                         str(demo / "positioner_abb.csv")))
