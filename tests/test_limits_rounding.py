"""Every limit check counts a value at a limit up to rounding (1e-14 beyond it) as inside.

A value that lies exactly at a limit comes out of a computation with a rounding error of a few
units in the last place; the checks allow ``LIMIT_TOL`` (1e-12 rad or m) beyond a limit and no
more (a value 1e-9 beyond is outside).
"""

import math
from dataclasses import replace

import numpy as np
import pytest
from test_cellik import track_cell
from test_positioner import tilt_rotate

from robotcell import InputError, load_robot
from robotcell.ik import (
    IKSolutions,
    abb_confdata,
    kuka_status_turn,
    nearest,
    select_abb,
    select_kuka,
)
from robotcell.ik.limits import JointFolder, shift_into_interval
from robotcell.kinematics.coupling import Coupling

ROUNDING = 1e-14   # what a computation at a limit can be off by
BEYOND = 1e-9      # clearly outside


def with_limits(robot, j, lower, upper):
    """``robot`` with joint ``j`` limited to [lower, upper] (rad, m)."""
    joints = list(robot.joints)
    joints[j] = replace(joints[j], lower=lower, upper=upper)
    return replace(robot, joints=tuple(joints))


def test_the_tolerance_is_rounding_not_motion():
    from robotcell.kinematics.bounds import LIMIT_TOL

    assert 1e-14 < LIMIT_TOL <= 1e-12


@pytest.mark.parametrize("side", [-1, 1])
def test_robot_limits(side):
    robot = load_robot("kuka_kr16")
    q = np.zeros((3, 6))
    limit = robot.upper[2] if side > 0 else robot.lower[2]
    q[:, 2] = limit + side * np.array([0.0, ROUNDING, BEYOND])
    assert robot.within_limits(q).tolist() == [True, True, False]
    assert robot.within_limits(q, tol=0.0).tolist() == [True, False, False]


def test_interaction_limits():
    c = Coupling(np.eye(6), interaction=[[0, 1, 1, 0, 0, 0]], interaction_lower=[-1.0],
                 interaction_upper=[1.0])
    q = np.zeros((2, 6))
    q[:, 1], q[:, 2] = 0.5, 0.5 + np.array([ROUNDING, BEYOND])
    assert c.within_interaction(q).tolist() == [True, False]


def test_track_turntable_and_positioner_limits():
    cell = track_cell()
    t, b = cell.track, cell.turntable
    assert cell.track.within_limits([t.upper + ROUNDING, t.lower - ROUNDING]).all()
    assert not cell.track.within_limits(t.upper + BEYOND)
    assert cell.turntable.within_limits([b.upper + ROUNDING, b.lower - ROUNDING]).all()
    assert not cell.turntable.within_limits(b.upper + BEYOND)
    pos = tilt_rotate().turntable
    pos = replace(pos, chain=with_limits(pos.chain, 0, -1.0, 1.0))
    assert pos.within_limits([[1.0 + ROUNDING, 0.0], [-1.0 - ROUNDING, 0.0]]).all()
    assert not pos.within_limits([1.0 + BEYOND, 0.0])


def test_two_pi_equivalents_at_a_limit_stay():
    lo, hi = -math.pi / 6, math.pi / 6
    assert shift_into_interval(np.array(lo - ROUNDING), lo, hi) == lo - ROUNDING
    assert shift_into_interval(np.array(hi + ROUNDING), lo, hi) == hi + ROUNDING
    assert np.isnan(shift_into_interval(np.array(hi + BEYOND), lo, hi))
    # a joint of +-400 deg keeps a value at its limit and does not turn it by 2 pi
    fold = JointFolder([-math.radians(400)], [math.radians(400)])
    q = np.array([[-math.pi - ROUNDING], [math.pi / 2]])
    assert fold(q).all() and q[0, 0] == -math.pi - ROUNDING
    fold = JointFolder([-0.5], [0.5])
    q = np.array([[0.5 + ROUNDING], [0.5 + BEYOND]])
    assert fold(q).tolist() == [True, False]


def test_analytic_ik_returns_a_value_at_its_limit_as_valid():
    robot = load_robot("kuka_kr16")
    T = robot.fk(np.radians([30, -80, 100, 20, 40, 60]))
    sol = robot.ik(T)
    a1 = sol.q[sol.valid, 0]
    a1 = a1[np.isclose(a1, math.radians(30))]
    limited = with_limits(robot, 0, -1.0, float(a1.max()) - ROUNDING)
    again = limited.ik(T)
    assert np.isclose(again.q[again.valid, 0], math.radians(30)).sum() == a1.size
    limited = with_limits(robot, 0, -1.0, float(a1.max()) - BEYOND)
    assert not np.isclose(limited.ik(T).q[limited.ik(T).valid, 0], math.radians(30)).any()


def test_selection_at_a_limit():
    robot = with_limits(load_robot("kuka_kr16"), 3, -0.5, 0.5)
    q = np.array([[0.1, -1.4, 1.5, 0.5 + ROUNDING, 0.6, 0.2]])
    sols = IKSolutions(q[None], np.array([[True]]), np.array([[True]]), "opw", np.zeros((1, 1)))
    got, found, _ = nearest(robot, sols, q[0])
    assert found.all() and got[0, 3] == q[0, 3]
    status, turn = kuka_status_turn(robot, q[0])
    got, found = select_kuka(robot, sols, status, turn)
    assert found.all() and got[0, 3] == q[0, 3]
    got, found = select_abb(robot, sols, abb_confdata(robot, q[0]))
    assert found.all() and got[0, 3] == q[0, 3]


def test_cell_ik_at_the_track_limit():
    cell = track_cell()
    e = cell.track.upper + ROUNDING
    T = cell.fk([0.1, -1.4, 1.5, 0.3, 0.6, 0.2], track=cell.track.upper, tool="torch")
    assert cell.ik(T, track=e, tool="torch").valid.any()
    assert not cell.ik(T, track=cell.track.upper + BEYOND, tool="torch").valid.any()


def test_simulated_positioner_values_at_the_limits():
    from robotcell.studies.simulate import simulate

    cell = tilt_rotate()
    cell.turntable = replace(cell.turntable, chain=with_limits(cell.turntable.chain, 0, -0.5, 0.5))
    touches = simulate(cell, "positioner", noise=0.0, seed=1, tool="torch",
                       tilts=[-0.5 - ROUNDING, 0.0, 0.5 + ROUNDING])
    assert len(touches.q) == 12
    with pytest.raises(InputError, match=r"tilt value\(s\) 28.6479 deg are outside the axis limits"):
        simulate(cell, "positioner", noise=0.0, seed=1, tool="torch", tilts=[0.0, 0.5 + 1e-6])
