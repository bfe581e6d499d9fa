"""The robots and fk commands, in process through the CLI entry point."""

import numpy as np
import pytest
from cli_helpers import run

from robotcell import load_robot, pose_from_vendor


def test_robots_lists_library(capsys):
    code, out, _ = run(capsys, "robots")
    assert code == 0
    assert "kuka_kr16" in out and "ur5e" in out and "stanford_arm" in out and "RRPRRR" in out


def test_robots_show_prints_table_with_units(capsys):
    code, out, _ = run(capsys, "robots", "show", "kuka_kr16")
    assert code == 0
    assert "a [mm]" in out and "alpha [deg]" in out and "source:" in out and "verified:" in out


def test_fk_single_pose_formats(capsys):
    robot = load_robot("kuka_kr16")
    q = np.radians([10, -80, 70, 20, 30, 40])
    code, out, _ = run(capsys, "fk", "kuka_kr16", "--joints", "10,-80,70,20,30,40")
    assert code == 0
    values = [float(tok) for tok in out.split()[1::2]]
    np.testing.assert_allclose(pose_from_vendor(values, "kuka"), robot.fk(q), atol=1e-6)
    code, out, _ = run(capsys, "fk", "kuka_kr16", "--joints", "10,-80,70,20,30,40", "--format", "abb")
    assert out.startswith("x ") and "q4" in out


def test_fk_batch_csv(tmp_path, capsys):
    robot = load_robot("ur5e")
    q_deg = np.random.default_rng(0).uniform(-90, 90, (5, 6))
    src = tmp_path / "joints.csv"
    src.write_text("a1,a2,a3,a4,a5,a6\n" + "\n".join(",".join(f"{v:.6f}" for v in r) for r in q_deg))
    dst = tmp_path / "poses.csv"
    code, _, _ = run(capsys, "fk", "ur5e", "--input", str(src), "--output", str(dst), "--format", "fanuc")
    assert code == 0
    rows = np.loadtxt(dst, delimiter=",", skiprows=1)
    assert dst.read_text().splitlines()[0] == "X,Y,Z,W,P,R"
    np.testing.assert_allclose(pose_from_vendor(rows, "fanuc"), robot.fk(np.radians(q_deg)), atol=1e-6)


def test_fk_tool_option(capsys):
    code, out, _ = run(capsys, "fk", "kuka_kr16", "--joints", "0,-90,90,0,0,0", "--tool", "100,0,200,0,0,0")
    assert code == 0
    # At home the KUKA flange axes are parallel to the base (flange at X 1088, Z 1320 mm), so
    # the tool offset adds straight on.
    assert out.split()[:6] == ["X", "1188.0000", "Y", "0.0000", "Z", "1520.0000"]


@pytest.mark.parametrize("args, message", [
    (("fk", "kuka_kr16", "--joints", "0,0,0"), "--joints needs 6 comma-separated values, got 3"),
    (("fk", "kuka_kr16", "--joints", "0,0,0,0,0,nan"), "NaN"),
    (("fk", "kuka_kr15", "--joints", "0"), "did you mean kuka_kr16"),
    (("fk", "kuka_kr16"), "give exactly one of --joints"),
    (("fk", "kuka_kr16", "--input", "nope.csv"), "nope.csv: no such file"),
])
def test_fk_errors_exit_2(capsys, args, message):
    code, _, err = run(capsys, *args)
    assert code == 2
    assert message in err
