"""Paths with a moving track, and where a path must break."""

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from test_cellik import track_cell

from robotcell import InputError
from robotcell.cell.ik import TRACK_WINDOW, split_path
from robotcell.kinematics.transforms import make_pose

DOWN = Rotation.from_euler("y", 180, degrees=True).as_matrix()  # torch pointing down


def seam(x0, x1, n, y=1.0, z=0.5):
    """A straight seam along X of the world, the torch pointing down (m)."""
    return make_pose(DOWN, np.column_stack([np.linspace(x0, x1, n), np.full(n, y), np.full(n, z)]))


def test_long_seam_needs_a_moving_track_which_follows_it_smoothly():
    cell = track_cell()
    T = seam(0.8, 4.8, 81)  # 4 m: longer than the arm reaches from one track position
    with pytest.raises(InputError, match="no arm configuration follows the whole path"):
        cell.ik_path(T, tool="torch", track_motion="fixed")
    path = cell.ik_path(T, tool="torch", track_motion="moving")
    assert np.allclose(cell.fk(path.q, track=path.track, tool="torch"), T, atol=1e-9)
    assert np.all(cell.robot.within_limits(path.q))
    assert np.all((path.track >= 0.0) & (path.track <= 6.0))
    assert path.max_step < math.radians(30)
    de = np.diff(path.track)
    assert np.all(de > 0)                                   # moves one way along the seam
    assert np.max(np.abs(np.diff(de))) < 0.2 * np.max(de)   # smooth: no jerk in the steps
    assert path.manipulability > 0


def test_split_path_reports_out_of_reach_and_keeps_both_sides():
    cell = track_cell()
    T = seam(1.0, 3.0, 41)
    T[15:20, 1, 3] = 4.0  # five targets 4 m beside the track
    split = split_path(cell, T, tool="torch")
    assert split.segments == [(0, 15), (20, 41)]
    assert [b.index for b in split.breaks] == [15, 16, 17, 18, 19]
    assert {b.kind for b in split.breaks} == {"reach"}
    assert "target 16" in split.breaks[0].message
    assert np.all(np.isnan(split.track[15:20])) and np.all(np.isfinite(split.track[:15]))
    for a, b in split.segments:  # every segment is a continuous path
        cell.ik_path(T[a:b], tool="torch", track=split.track[a:b])


def test_split_path_reports_the_shoulder_singularity():
    cell = track_cell()
    # Axis 2 sweeps the wrist centre across axis 1 (at A2 = -103 deg with A3 = 0 on a KR 16):
    # the shoulder configuration changes through a singular one.
    q = np.tile([0.3, 0.0, 0.0, 0.4, 0.6, 0.2], (21, 1))
    q[:, 1] = np.radians(np.linspace(-113, -93, 21))
    T = cell.fk(q, track=2.0, tool="torch")
    split = split_path(cell, T, track=2.0, tool="torch")
    assert [b.kind for b in split.breaks] == ["singularity"]
    assert split.segments == [(0, 11), (11, 21)]
    assert "shoulder 1" in split.breaks[0].message and "singular" in split.breaks[0].message
    dets = np.abs(np.linalg.det(cell.robot.jacobian(q)))
    assert dets[10] < 0.05 * dets.max()  # truly next to the singular configuration


def axis1_limited(cell, upper):
    """``cell`` with axis 1 limited to +-``upper`` (rad)."""
    j1 = cell.robot.joints[0]
    cell.robot = replace(cell.robot, joints=(replace(j1, lower=-upper, upper=upper),)
                         + cell.robot.joints[1:])
    return cell


def axis1_sweep(cell):
    """Targets of A1 = 10 .. 50 deg in 2 deg steps (A1 = 30 deg at index 10), track at 2 m."""
    q = np.tile([0.0, -1.2, 1.6, 0.4, 0.6, 0.2], (21, 1))
    q[:, 0] = np.radians(np.linspace(10, 50, 21))
    return cell.fk(q, track=2.0, tool="torch")


def test_split_path_reports_a_joint_limit():
    # Axis 1 limited to +-30 deg: the shoulder-back configurations (A1 + 180) are all outside.
    cell = axis1_limited(track_cell(), math.radians(30))
    split = split_path(cell, axis1_sweep(cell), track=2.0, tool="torch")
    assert split.segments == [(0, 11)]
    assert [b.kind for b in split.breaks] == ["limit"] * 10
    assert split.breaks[0].index == 11 and "axis 1" in split.breaks[0].message


def test_split_path_counts_a_value_at_the_limit_up_to_rounding_as_inside():
    # The IK of the target at 30 deg gives 30 deg plus or minus rounding (1e-14 rad on some
    # machines): put the limit exactly 1e-14 rad below the value the IK returns here.
    cell = track_cell()
    T = axis1_sweep(cell)
    sol = cell.ik(T, track=2.0, tool="torch")
    a1 = sol.q[10, sol.valid[10], 0]
    assert np.allclose(a1, math.radians(30), rtol=0, atol=1e-12)
    cell = axis1_limited(cell, float(a1.max()) - 1e-14)
    assert cell.robot.upper[0] < a1.max()   # the value is beyond the limit by rounding
    split = split_path(cell, T, track=2.0, tool="torch")
    assert split.segments == [(0, 11)] and split.breaks[0].index == 11


def test_split_path_of_a_followable_path_is_one_segment():
    cell = track_cell()
    split = split_path(cell, seam(1.5, 2.5, 21), tool="torch", track_motion="fixed")
    assert split.segments == [(0, 21)] and split.breaks == []
    assert np.ptp(split.track) == 0


def test_moving_track_errors():
    cell = track_cell()
    with pytest.raises(InputError, match="track_motion must be one of fixed, moving"):
        cell.ik_path(seam(1.0, 2.0, 3), track_motion="sliding")
    assert TRACK_WINDOW >= 3


def test_a_jump_of_the_table_breaks_the_path_even_where_the_arm_stays():
    # A whole turn of the table brings the part back where it was: the arm does not move, but
    # the table would turn 360 deg between two targets. It was one segment.
    cell = track_cell()
    q0 = np.radians([80, -80, 100, 10, 40, 20])
    T_W = cell.fk(q0, 3.0, 0.0, tool="torch", frame="part")
    th = np.array([-0.2, -0.15, -0.1, -0.1 + 2 * math.pi, -0.05 + 2 * math.pi])
    split = split_path(cell, T_W, "part", track=3.0, table=th, tool="torch")
    assert split.segments == [(0, 3), (3, 5)]
    assert [(b.index, b.kind) for b in split.breaks] == [(3, "table")]
    assert "target 4: the table turns by 360 deg from the previous target" in \
        split.breaks[0].message
    with pytest.raises(InputError, match="target 4: the table turns by 360 deg"):
        cell.ik_path(T_W, "part", track=3.0, table=th, tool="torch")
