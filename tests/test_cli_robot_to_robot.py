"""``robotcell simulate robot-to-robot`` and ``robotcell calibrate robot-to-robot``: two robots'
touch files written from a true layout, and the pose recovered from them."""

from __future__ import annotations

import json
import re

import numpy as np
from cli_helpers import run

TOOLS = ["--robot-ref", "kuka_kr16", "--tool-ref", "0,0,200,0,0,0", "--robot-other",
         "abb_irb2400", "--tool-other", "50,0,180,0,0,0"]


def _simulate(capsys, tmp_path, *extra):
    r1, r2 = tmp_path / "r1.csv", tmp_path / "r2.csv"
    code, _, err = run(capsys, "simulate", "robot-to-robot", "--seed", "4", "--ref-output", r1,
                       "--other-output", r2, *extra)
    assert code == 0, err
    return r1, r2, err


def test_simulated_files_calibrate_to_the_true_pose(capsys, tmp_path) -> None:
    r1, r2, err = _simulate(capsys, tmp_path, "--pose", "1650,-150,0,170,0,0")
    assert "robotcell calibrate robot-to-robot" in err
    assert r1.read_text().splitlines()[0] == "a1,a2,a3,a4,a5,a6,point"
    code, out, err = run(capsys, "calibrate", "robot-to-robot", r1, r2, *TOOLS, "--sigma", "0.1",
                         "--tool-sigma", "0.05", "--json")
    assert code == 0, err
    result = json.loads(out)
    assert result["procedure"] == "robot-to-robot" and result["robots"] == ["r1", "r2"]
    xyzabc = np.array(result["xyzabc"])
    assert np.allclose(xyzabc[:3], [1650, -150, 0], atol=1.0)
    assert abs(xyzabc[3] - 170) < 0.1 and np.allclose(xyzabc[4:], 0, atol=0.1)
    assert result["verdict"]["level"] == "good"
    assert set(result["sigma_parts"]["T_ref_other"]) == {"relative_to", "own", "recorded"}


def test_report_names_the_pose_and_the_assumed_tools(capsys, tmp_path) -> None:
    r1, r2, _ = _simulate(capsys, tmp_path)
    code, out, _ = run(capsys, "calibrate", "robot-to-robot", r1, r2, *TOOLS, "--sigma", "0.1")
    assert code == 0
    assert "T_ref_other (KUKA X,Y,Z mm, A,B,C deg): 1600." in out or "): 1599." in out
    assert "ASSUMED accuracy) [r1 tool, r2 tool]" in out
    assert out.rstrip().splitlines()[-1].startswith("verdict: ")


def test_bad_input_exits_2_with_one_error_line_and_writes_nothing(capsys, tmp_path) -> None:
    r1, r2, _ = _simulate(capsys, tmp_path)
    lines = r2.read_text().splitlines()
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join(lines[:1] + [ln.replace("P3", "P9") for ln in lines[1:]]) + "\n")
    out = tmp_path / "result.json"
    cases = [
        ([r1, bad, *TOOLS], r"touched by one robot only \(P3 by r1 only; P9 by bad only\)"),
        ([r1, r2], "r1.csv: joint values a1..a6 need the robot's model \\(--robot-ref"),
        ([r1, r2, *TOOLS, "--tool-sigma", "0"], "--tool-sigma must be a positive number"),
    ]
    for args, message in cases:
        code, _, err = run(capsys, "calibrate", "robot-to-robot", *args, "--json", "-o", out)
        assert code == 2
        assert len(err.strip().splitlines()) == 1 and re.search(message, err), err
        assert not out.exists()


def test_simulate_refuses_one_file_for_both_robots(capsys, tmp_path) -> None:
    f = tmp_path / "r.csv"
    code, _, err = run(capsys, "simulate", "robot-to-robot", "--ref-output", f, "--other-output",
                       f)
    assert code == 2 and "names the same file as --ref-output" in err and not f.exists()
