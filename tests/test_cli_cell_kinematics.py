"""``robotcell ik --cell`` and ``robotcell fk --cell``: targets in cell frames, track and table."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.ik import abb_confdata, kuka_status_turn
from robotcell.ik.limits import wrap_to_pi
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.io.tables import read_csv

CELL = Path(__file__).parent.parent / "examples" / "cell_kr16_track_turntable.yaml"


def joints_file(tmp_path: Path, n: int, seed: int = 1) -> tuple[Path, np.ndarray, np.ndarray, np.ndarray]:
    """Random in-limit joints (deg), track (mm) and table (deg) values, written as CSV."""
    cell = Cell.load(CELL)
    rng = np.random.default_rng(seed)
    r = cell.robot
    q = np.degrees(rng.uniform(np.maximum(r.lower, -3.0), np.minimum(r.upper, 3.0), (n, 6)))
    q[:, 4] = np.where(np.abs(q[:, 4]) < 5, 20.0, q[:, 4])  # away from the wrist singularity
    e = rng.uniform(500, 5500, n)
    th = rng.uniform(-180, 180, n)
    path = tmp_path / "joints.csv"
    header = "a1,a2,a3,a4,a5,a6,track,table"
    np.savetxt(path, np.column_stack([q, e, th]), delimiter=",", header=header, comments="",
               fmt="%.12f")
    return path, q, e, th


@pytest.mark.parametrize("fmt", ["kuka", "abb"])
def test_fk_ik_batch_round_trip_in_a_turntable_frame(tmp_path, capsys, fmt):
    """fk --cell writes poses in frame 'part'; ik --cell with the same track and table finds the
    original joints, with the controller's flags."""
    src, q, e, th = joints_file(tmp_path, 60)
    poses = tmp_path / "poses.csv"
    code, _, err = run(capsys, "fk", "--cell", CELL, "--input", src, "--output", poses,
                       "--frame", "part", "--tool", "torch", "--format", fmt)
    assert code == 0, err
    # The poses are those of the library's Cell.fk.
    cell = Cell.load(CELL)
    T = cell.fk(np.radians(q), e * 1e-3, np.radians(th), "torch", "part")
    cols = read_csv(poses)
    got = pose_from_vendor(np.column_stack([cols[f.lower()] for f in
                                            ("X", "Y", "Z", "A", "B", "C")] if fmt == "kuka" else
                                           [cols[k] for k in ("x", "y", "z", "q1", "q2", "q3", "q4")]),
                           fmt)
    np.testing.assert_allclose(got[:, :3, 3], T[:, :3, 3], atol=1e-9)
    # Add the per-row track and table columns and solve back.
    text = poses.read_text().splitlines()
    lines = [text[0] + ",track,table"] + [f"{line},{a:.12f},{b:.12f}" for line, a, b in zip(text[1:], e, th)]
    poses.write_text("\n".join(lines) + "\n")
    out = tmp_path / "joints_back.csv"
    code, _, err = run(capsys, "ik", "--cell", CELL, "--input", poses, "--output", out,
                       "--frame", "part", "--tool", "torch", "--format", fmt)
    assert code == 0, err
    back = read_csv(out)
    got_q = np.column_stack([back[f"a{i}"] for i in range(1, 7)])
    pose_i = back["pose"].astype(int)
    np.testing.assert_allclose(back["track"], e[pose_i], atol=1e-6)
    np.testing.assert_allclose(back["table"], th[pose_i], atol=1e-6)
    diff = np.abs(wrap_to_pi(np.radians(got_q - q[pose_i]))).max(axis=1)
    # 6 decimals of mm and deg (of the quaternion for abb) in the pose file.
    tol = 1e-5 if fmt == "kuka" else 1e-3
    hit = np.zeros(len(q), bool)
    hit[pose_i[diff < tol]] = True
    assert hit.all()
    # The configuration flags of the original's row.
    rows = np.flatnonzero(diff < tol)
    if fmt == "kuka":
        s, t = kuka_status_turn(cell.robot, np.radians(got_q[rows]))
        np.testing.assert_array_equal(back["status"][rows], s)
        np.testing.assert_array_equal(back["turn"][rows], t)
        s0, _ = kuka_status_turn(cell.robot, np.radians(q[pose_i[rows]]))
        np.testing.assert_array_equal(back["status"][rows], s0)
    else:
        cf = abb_confdata(cell.robot, np.radians(got_q[rows]))
        got_cf = np.column_stack([back[k] for k in ("cf1", "cf4", "cf6", "cfx")])[rows]
        np.testing.assert_array_equal(got_cf, cf)


def test_single_pose_with_chosen_track(capsys):
    """Without --track the track position is chosen; fk --cell at it reproduces the target."""
    cell = Cell.load(CELL)
    T = cell.fk(np.radians([10, -80, 100, 20, 40, 30]), 2.0, 0.0, "torch", "world")
    pose = ",".join(f"{v:.9f}" for v in pose_to_vendor(T, "kuka"))
    code, out, err = run(capsys, "ik", "--cell", CELL, "--pose", pose, "--tool", "torch")
    assert code == 0, err
    assert "chosen" in out and "S/T" in out
    track_mm = float(out.split("track ")[1].split(" mm")[0])
    sol = cell.ik(T, tool="torch")  # the library's choice
    np.testing.assert_allclose(track_mm, float(sol.track) * 1e3, atol=1e-3)
    first = out.splitlines()[3].split()
    q = [float(v) for v in first[-11:-5]]
    code, out2, err = run(capsys, "fk", "--cell", CELL, "--joints", ",".join(map(str, q)),
                          "--track", track_mm, "--tool", "torch")
    assert code == 0, err
    vals = [float(v) for v in out2.splitlines()[1].split()[1::2]]
    np.testing.assert_allclose(vals[:3], pose_to_vendor(T, "kuka")[:3], atol=0.01)


def test_given_track_near_and_all(capsys):
    cell = Cell.load(CELL)
    q0 = np.radians([10, -80, 100, 20, 40, 30])
    T = cell.fk(q0, 1.5, np.radians(45), None, "part")
    pose = ",".join(f"{v:.9f}" for v in pose_to_vendor(T, "kuka"))
    code, out, err = run(capsys, "ik", "--cell", CELL, "--pose", pose, "--frame", "part",
                         "--track", 1500, "--table", 45, "--near", "10,-80,100,20,40,30")
    assert code == 0, err
    assert "track 1500.000 mm (given), table 45 deg" in out
    row = out.splitlines()[3].split()
    np.testing.assert_allclose([float(v) for v in row[-11:-5]], np.degrees(q0), atol=1e-5)
    code, out, err = run(capsys, "ik", "--cell", CELL, "--pose", pose, "--frame", "part",
                         "--track", 1500, "--table", 45, "--all")
    assert code == 0 and len(out.splitlines()) == 3 + 8


@pytest.mark.parametrize("args, match", [
    (["--frame", "nowhere"], "error: unknown frame 'nowhere'; the cell has:"),
    (["--tool", "wrench"], "error: unknown tool 'wrench'; the cell has: pointer, torch"),
    (["--track", "100", "--pose", "9000,0,50,0,180,0"], "error: no valid solution for the target"),
    (["--tool", "1,2,3"], "error: --tool needs 6 comma-separated values"),
])
def test_ik_refusals(capsys, args, match):
    pose = [] if "--pose" in args else ["--pose", "1800,-1200,600,0,180,0"]
    code, out, err = run(capsys, "ik", "--cell", CELL, *pose, *args)
    assert code == 2 and out == ""
    assert re.search(match, err), err


def test_fk_and_ik_warn_about_a_track_or_table_value_outside_its_limits(capsys):
    # The value is named in a warning line; fk computes the pose (the one of the model at that
    # track position, checked against the closed form: the track moves the robot along its
    # axis), ik marks every branch outside the limits.
    cell = Cell.load(CELL)
    q = "0,-90,90,0,45,0"
    code, out, err = run(capsys, "fk", "--cell", CELL, "--joints", q, "--track", "-1")
    assert code == 0 and err == ("warning: track position -1 mm is outside the track limits "
                                 "[0, 6000] mm; computed anyway, but the axis cannot move there\n")
    code, out0, _ = run(capsys, "fk", "--cell", CELL, "--joints", q, "--track", "0")
    xyz = [np.array([float(v) for v in o.splitlines()[1].split()[1::2]][:3]) for o in (out, out0)]
    shift = (cell.track.T_world_L[:3, :3] @ cell.track.direction) * cell.track.scale * -1.0
    np.testing.assert_allclose(xyz[0] - xyz[1], shift, atol=1e-6)
    T = cell.fk(np.radians([10, -80, 100, 20, 40, 30]), 5.9, 0.0, None, "world")
    pose = ",".join(f"{v:.9f}" for v in pose_to_vendor(T, "kuka"))
    for opt, text in ((["--track", "6050"], "track position 6050 mm is outside the track limits"),
                      (["--track", "5900", "--table", "400"],
                       "table angle 400 deg is outside the turntable limits")):
        code, out, err = run(capsys, "ik", "--cell", CELL, "--pose", pose, *opt, "--all")
        assert code == 0 and f"warning: {text}" in err, err
        assert "yes" not in out and "limits" in out


@pytest.mark.parametrize("args, match", [
    (["--frame", "nowhere"], "error: unknown frame 'nowhere'"),
    (["--tool", "wrench"], "error: unknown tool 'wrench'"),
    (["kuka_kr16"], "error: give either ROBOT or --cell CELL.yaml, not both"),
])
def test_fk_refusals(capsys, args, match):
    robot = [a for a in args if a == "kuka_kr16"]
    opts = [a for a in args if a != "kuka_kr16"]
    code, out, err = run(capsys, "fk", *robot, "--cell", CELL, "--joints", "0,-90,90,0,45,0", *opts)
    assert code == 2 and out == ""
    assert re.search(match, err), err


def test_neither_robot_nor_cell(capsys):
    code, _, err = run(capsys, "ik", "--pose", "1,2,3,0,0,0")
    assert code == 2 and "error: give a ROBOT (library name or model file) or --cell" in err


def test_long_batch_shows_progress_on_stderr(tmp_path, capsys):
    src = joints_file(tmp_path, 2000, seed=3)[0]
    poses = tmp_path / "poses.csv"
    code, _, err = run(capsys, "fk", "--cell", CELL, "--input", src, "--output", poses)
    assert code == 0, err
    out = tmp_path / "j.csv"
    code, stdout, err = run(capsys, "ik", "--cell", CELL, "--input", poses, "--output", out,
                            "--track", 1000)
    assert code == 0
    assert "ik" in err and stdout == ""
    assert out.read_text().startswith("pose,branch,track,table,a1,")


def test_ik_cell_carries_and_prints_the_reach_error_of_a_rounded_target(tmp_path, capsys):
    """A target 0.3 um outside the stretched elbow's reach is solved at the boundary; Cell.ik
    reports the distance per branch as the arm's IK does, and ik --cell prints it in mm."""
    from robotcell.ik import opw_parameters, solve

    cell = Cell.load(CELL)
    r = cell.robot
    p = opw_parameters(r)
    a3 = p.signs[2] * (-np.arctan2(p.a2, p.c3) - p.offsets[2])  # A3 of the stretched elbow
    q = np.array([0.3, -0.5, a3, 0.2, 0.7, 0.5])
    T_R = r.fk(q)
    T_R[:3, 3] *= 1 + 2e-7  # rounded outward by a fraction of a micrometre
    arm = solve(r, T_R)
    T_W = cell.frame_pose("robot", track=1.0) @ T_R
    sol = cell.ik(T_W, track=1.0)
    assert sol.reach_error is not None and sol.reach_error.shape == (8,)
    np.testing.assert_allclose(sol.reach_error, arm.reach_error, rtol=1e-6, atol=1e-12)
    k = int(np.nanargmin(np.abs(sol.q - q).sum(axis=-1)))
    assert sol.valid[k] and 1e-7 < sol.reach_error[k] < 1e-6
    chosen = cell.ik(np.stack([T_W, T_W]))  # the track chosen: one value per target and branch
    assert chosen.reach_error.shape == (2, 8)
    pose = ",".join(repr(float(v)) for v in pose_to_vendor(T_W, "kuka"))
    code, out, err = run(capsys, "ik", "--cell", CELL, "--track", "1000", "--pose", pose)
    assert code == 0, err
    assert "reach error mm" in out
    row = next(line for line in out.splitlines() if line.lstrip().startswith(f"{k} "))
    assert float(row.split()[-1]) == pytest.approx(sol.reach_error[k] * 1e3, rel=1e-3)
    inside = ",".join(repr(float(v)) for v in pose_to_vendor(
        cell.frame_pose("robot", track=1.0) @ r.fk([0.1, -1.2, 1.4, 0.3, 0.6, 0.2]), "kuka"))
    code, out, err = run(capsys, "ik", "--cell", CELL, "--track", "1000", "--pose", inside)
    assert code == 0 and "reach error" not in out, err  # inside the reach: no column
    poses = tmp_path / "p.csv"
    poses.write_text("x,y,z,a,b,c\n" + pose + "\n" + inside + "\n")
    code, out, err = run(capsys, "ik", "--cell", CELL, "--track", "1000", "--input", poses)
    assert code == 0, err
    rows = read_csv_text(out)
    assert "reach_error_mm" in rows[0]
    first = [float(x["reach_error_mm"]) for x in rows if x["pose"] == "0" and x["branch"] == str(k)]
    assert first == [pytest.approx(sol.reach_error[k] * 1e3, rel=1e-3)]
    assert all(float(x["reach_error_mm"]) == 0.0 for x in rows if x["pose"] == "1")


def read_csv_text(text: str) -> list[dict]:
    import csv
    import io

    return list(csv.DictReader(io.StringIO(text)))
