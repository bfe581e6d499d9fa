"""``robotcell ik`` command line."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from robotcell.cli import main
from robotcell.io.poseformats import pose_to_vendor
from robotcell.robot.models import load_robot


def run(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    out = capsys.readouterr()
    return exc.value.code, out.out, out.err


def run_ok(argv, capsys):
    main(argv)
    return capsys.readouterr().out


def test_single_pose_table(capsys):
    out = run_ok(["ik", "kuka_kr6_r700_sixx", "--pose", "470,0,750,0,0,0"], capsys)
    assert "opw solver" in out
    first = out.splitlines()[3].split()
    assert first == ["0", "front", "up", "0.000", "-90.000", "90.000", "0.000", "0.000", "0.000",
                     "yes", "S", "6", "T", "2"]
    assert "back" not in out  # out of limits: listed only with --all
    out = run_ok(["ik", "kuka_kr6_r700_sixx", "--pose", "470,0,750,0,0,0", "--all"], capsys)
    assert out.count("limits") == 4


def test_near_and_abb_flags(capsys):
    out = run_ok(["ik", "abb_irb2400", "--pose", "940,0,1455,0.7071068,0,0.7071068,0",
                  "--format", "abb", "--near", "0,0,0,0,0,0"], capsys)
    assert "[0,0,0,0]" in out and len(out.strip().splitlines()) == 4


def test_batch_round_trip(tmp_path, capsys):
    robot = load_robot("kuka_kr16")
    rng = np.random.default_rng(0)
    q = rng.uniform(robot.lower, robot.upper, (20, 6))
    poses = pose_to_vendor(robot.fk(q), "kuka")
    src = tmp_path / "poses.csv"
    with src.open("w") as fh:
        fh.write("x,y,z,a,b,c\n" + "\n".join(",".join(f"{v:.9f}" for v in row) for row in poses))
    dst = tmp_path / "joints.csv"
    run_ok(["ik", "kuka_kr16", "--input", str(src), "--output", str(dst)], capsys)
    rows = list(csv.DictReader(dst.read_text().splitlines()))
    got = {}
    for r in rows:
        got.setdefault(int(r["pose"]), []).append([float(r[f"a{i}"]) for i in range(1, 7)])
    for i in range(20):
        d = np.abs((np.array(got[i]) - np.degrees(q[i]) + 180) % 360 - 180).max(axis=1)
        assert d.min() < 1e-5  # 9 decimals of mm/deg in the input file
    dst2 = tmp_path / "near.csv"
    run_ok(["ik", "kuka_kr16", "--input", str(src), "--output", str(dst2), "--near",
            ",".join(str(v) for v in np.degrees(q[0]))], capsys)
    rows = list(csv.DictReader(dst2.read_text().splitlines()))
    assert len(rows) == 20 and rows[0]["found"] == "1"
    np.testing.assert_allclose([float(rows[0][f"a{i}"]) for i in range(1, 7)], np.degrees(q[0]), atol=1e-5)


def test_errors(capsys, tmp_path):
    code, _, err = run(["ik", "stanford_arm", "--pose", "1,2,3,0,0,0"], capsys)
    assert code == 2 and "joint(s) 3 are prismatic" in err
    code, _, err = run(["ik", "kuka_kr16", "--pose", "1,2,3"], capsys)
    assert code == 2 and "--pose needs 6 comma-separated values" in err
    code, _, err = run(["ik", "kuka_kr16"], capsys)
    assert code == 2 and "give exactly one of --pose" in err
    code, _, err = run(["ik", "kuka_kr16", "--pose", "9000,0,0,0,0,0"], capsys)
    assert code == 2 and err.startswith("error: no valid solution")
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y,z,a,b\n1,2,3,4,5\n")
    code, _, err = run(["ik", "kuka_kr16", "--input", str(bad)], capsys)
    assert code == 2 and "missing column(s) c" in err
