"""Configuration flags (KUKA Status/Turn, ABB confdata) and choosing one solution."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robotcell.errors import InputError
from robotcell.ik.config import abb_confdata, arm_sides, kuka_status_turn
from robotcell.ik.limits import wrap_to_pi
from robotcell.ik.select import nearest, select_abb, select_kuka
from robotcell.ik.track import TrackRobot
from robotcell.robot.models import load_robot

D = np.radians


def test_kuka_flags_at_known_configurations():
    robot = load_robot("kuka_kr6_r700_sixx")
    # HOME: upper arm up, forearm forward (A3 = 90 >= phi), A5 = 0 (<= 0), A2 < 0.
    status, turn = kuka_status_turn(robot, D([0, -90, 90, 0, 0, 0]))
    assert (status, turn) == (2 + 4, 2)
    status, turn = kuka_status_turn(robot, D([-10, -80, 70, -20, 30, -40]))
    assert (status, turn) == (2, 1 + 2 + 8 + 32)
    # Overhead: upper arm leaning back far enough puts the wrist centre behind axis 1.
    status, _ = kuka_status_turn(robot, D([0, -150, 20, 0, 30, 0]))
    assert status & 1
    # Elbow bent the other way (A3 below phi ~ 5.5 deg for this arm).
    status, _ = kuka_status_turn(robot, D([0, -90, -30, 0, 30, 0]))
    assert not status & 2


def test_eight_branches_have_eight_kuka_statuses():
    robot = load_robot("kuka_kr16")
    rng = np.random.default_rng(1)
    q = rng.uniform(robot.lower, robot.upper, (2000, 6))
    sol = robot.ik(robot.fk(q))
    status, _ = kuka_status_turn(robot, sol.q)
    full = sol.reachable.all(axis=1)
    assert full.any()
    assert np.all(np.sort(status[full], axis=1) == np.arange(8))


def test_abb_confdata_known_values():
    robot = load_robot("abb_irb120")
    np.testing.assert_array_equal(abb_confdata(robot, np.zeros(6)), [0, 0, 0, 0])
    np.testing.assert_array_equal(abb_confdata(robot, D([100, 10, 10, -30, -20, 200])), [1, -1, 2, 1])
    # Forearm folded back behind the lower arm: cfx bit 1.
    assert abb_confdata(robot, D([0, 0, -100, 0, 30, 0]))[3] & 2


def test_select_kuka_returns_the_taught_configuration():
    robot = load_robot("kuka_kr6_r700_sixx")
    rng = np.random.default_rng(2)
    q = rng.uniform(robot.lower, robot.upper, (3000, 6))
    status, turn = kuka_status_turn(robot, q)
    sol = robot.ik(robot.fk(q))
    got, found = select_kuka(robot, sol, status, turn)
    assert found.mean() > 0.999
    np.testing.assert_allclose(got[found], q[found], atol=1e-6)  # exact angles, A6 turns included


def test_select_abb_returns_the_taught_configuration():
    robot = load_robot("abb_irb120")
    rng = np.random.default_rng(3)
    q = rng.uniform(robot.lower, robot.upper, (3000, 6))
    sol = robot.ik(robot.fk(q))
    got, found = select_abb(robot, sol, abb_confdata(robot, q))
    assert found.mean() > 0.999
    np.testing.assert_allclose(got[found], q[found], atol=1e-6)
    with pytest.raises(InputError, match=r"confdata must have 4 values"):
        select_abb(robot, sol, [0, 0, 0])


def test_flags_need_a_spherical_wrist():
    with pytest.raises(InputError, match="configuration flags are defined for arms with a spherical wrist"):
        kuka_status_turn(load_robot("ur5e"), np.zeros(6))
    with pytest.raises(InputError, match=r"q must have shape \(\.\.\., 6\)"):
        arm_sides(load_robot("abb_irb120"), np.zeros(5))


def test_nearest_with_turns_and_weights():
    robot = load_robot("ur5e")  # +-360 deg: every joint has two equivalents
    q = D([10, -80, 70, 20, 30, 40])
    sol = robot.ik(robot.fk(q))
    ref = q - np.array([0, 0, 0, 0, 0, 2 * math.pi]) + 0.01
    got, found, branch = nearest(robot, sol, ref)
    assert found and branch >= 0
    np.testing.assert_allclose(got, q - np.array([0, 0, 0, 0, 0, 2 * math.pi]), atol=1e-9)
    # Batched references.
    qs = np.stack([q, q + 0.1])
    sols = robot.ik(robot.fk(qs))
    got, found, _ = nearest(robot, sols, qs)
    np.testing.assert_allclose(got, qs, atol=1e-9)
    with pytest.raises(InputError, match=r"q_ref must have shape \(\.\.\., 6\)"):
        nearest(robot, sol, np.zeros(5))
    with pytest.raises(InputError, match="weights must be 6 non-negative numbers"):
        nearest(robot, sol, q, weights=[-1, 1, 1, 1, 1, 1])


def test_nearest_on_track_keeps_prismatic_axis():
    arm = load_robot("kuka_kr6_r700_sixx")
    track = TrackRobot(arm, lower=-1.0, upper=2.0)
    q = np.concatenate([[0.7], D([10, -80, 70, 20, 30, 40])])
    sol = track.ik_at(track.fk(q), 0.7)
    got, found, _ = nearest(track.as_robot(), sol, q)
    assert found
    np.testing.assert_allclose(wrap_to_pi(got - q), 0, atol=1e-9)


def test_nearest_reports_nothing_when_unreachable():
    robot = load_robot("abb_irb120")
    T = np.eye(4)
    T[0, 3] = 5.0
    got, found, branch = nearest(robot, robot.ik(T), np.zeros(6))
    assert not found and branch == -1 and np.isnan(got).all()
