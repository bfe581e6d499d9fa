"""Fast choice of the track value: closed forms, and equivalence with the sampled search."""

import numpy as np
import pytest

from robotcell import InputError, load_robot
from robotcell.cell.ik import choose_track_value
from robotcell.ik import TrackRobot, analytic_solver
from robotcell.ik.trackchoice import (
    arm_manipulability,
    choose_track,
    manipulability,
    scan_track,
    track_interval,
)
from robotcell.kinematics.transforms import make_pose, rot_x, rot_z

ARM = load_robot("kuka_kr16")


def kr16_track():
    return TrackRobot(ARM, make_pose(rot_z(0.3) @ rot_x(0.01), [0.1, 0.2, 0.45]),
                      np.array([1.0, 0.01, 0.0]), 0.0, 6.0)


def reachable_targets(track, n, seed):
    rng = np.random.default_rng(seed)
    q = np.column_stack([rng.uniform(track.lower, track.upper, n),
                         rng.uniform(track.arm.lower, track.arm.upper, (n, 6))])
    return track.fk(q)


@pytest.mark.parametrize("name", ["kuka_kr16", "abb_irb2400", "kuka_kr6_r700_sixx", "fanuc_m20ia"])
def test_closed_form_manipulability_equals_det_of_jacobian(name):
    arm = load_robot(name)
    q = np.random.default_rng(0).uniform(arm.lower, arm.upper, (500, 6))
    det = np.abs(np.linalg.det(arm.jacobian(q)))
    assert np.allclose(arm_manipulability(arm, q), det, rtol=0, atol=1e-12)
    if arm.coupling is None:  # the model's angles are the controller's
        assert np.allclose(manipulability(analytic_solver(arm).params, q), det, atol=1e-12)
    else:  # FANUC J2/J3 and the IRB 2400 parallelogram: J = J_model C
        assert set(arm.coupling.changed_axes()) & {1, 2}


@pytest.mark.parametrize("name", ["abb_irb2400", "fanuc_m20ia"])
def test_choice_for_coupled_arms_is_valid_and_as_good_as_the_sampled_search(name):
    arm = load_robot(name)
    track = TrackRobot(arm, make_pose(rot_z(0.2), [0.0, 0.1, 0.3]), np.array([1.0, 0.0, 0.0]),
                       0.0, 4.0)
    T = reachable_targets(track, 120, 7)
    old, new = track.ik(T), choose_track(track, T)
    ok_old = old.solutions.valid.any(-1)
    assert np.all(new.solutions.valid.any(-1)[ok_old])
    i, b = np.nonzero(new.solutions.valid)
    assert np.allclose(track.fk(new.solutions.q[i, b]), T[i], atol=1e-9)
    assert np.all(arm.within_limits(new.solutions.q[i, b, 1:]))
    ratio = new.manipulability[ok_old] / old.manipulability[ok_old]
    assert np.median(ratio) > 0.9999 and np.mean(ratio >= 0.99) >= 0.97


def test_closed_form_interval_contains_every_reachable_track_value():
    track = TrackRobot(ARM, make_pose(rot_z(0.3) @ rot_x(0.01), [0.1, 0.2, 0.45]),
                       np.array([1.0, 0.01, 0.0]), -10.0, 16.0)
    T = reachable_targets(kr16_track(), 40, 1)
    xs = np.linspace(-10.0, 16.0, 2601)
    sol = track.ik_at(np.broadcast_to(T[:, None], (40, xs.size, 4, 4)), xs)
    reach = np.any(sol.reachable, axis=-1)                               # (40, K)
    from robotcell.ik.trackchoice import _wrist_line
    pa, _, C0, w = _wrist_line(track, T, None)
    lo, hi = track_interval(pa, C0, w)
    inside = (xs >= lo[:, None]) & (xs <= hi[:, None])
    assert np.all(inside[reach])
    assert np.all(reach.any(axis=1))
    # not a trivial bound: the interval is a few metres of a 26 m track
    assert np.all(hi - lo < 5.0)


def test_choice_is_valid_and_as_good_as_the_sampled_search():
    track = kr16_track()
    T = reachable_targets(track, 300, 2)
    old = track.ik(T)
    new = choose_track(track, T)
    ok_old = old.solutions.valid.any(-1)
    ok_new = new.solutions.valid.any(-1)
    assert np.all(ok_new[ok_old])
    assert np.all((new.track >= track.lower) & (new.track <= track.upper))
    # every valid branch reproduces its target at the chosen track value
    q = new.solutions.q[new.solutions.valid]
    Tq = track.fk(q)
    Tt = np.broadcast_to(T[:, None], new.solutions.valid.shape + (4, 4))[new.solutions.valid]
    assert np.max(np.abs(Tq - Tt)) < 1e-9
    assert np.all(track.arm.within_limits(q[:, 1:]))
    # the score: |det J| of the best valid branch at the chosen value (m^3)
    ratio = new.manipulability[ok_old] / old.manipulability[ok_old]
    assert np.median(ratio) > 0.9999
    assert np.mean(ratio >= 0.99) >= 0.99
    assert np.mean(ratio >= 0.9999) >= 0.9
    assert np.mean(ratio > 1.0) >= 0.25  # often better: a finer search of the same criterion


def test_preferred_value_wins_within_ten_percent_of_the_best():
    track = kr16_track()
    T = reachable_targets(track, 50, 3)
    best = choose_track(track, T)
    near = choose_track(track, T, prefer=best.track + 0.3)
    assert np.all(near.manipulability >= 0.9 * best.manipulability - 1e-12)
    assert np.mean(np.abs(near.track - (best.track + 0.3)) < 0.3) > 0.8


def test_unreachable_target_has_no_valid_branch_and_no_interval():
    track = kr16_track()
    T = make_pose(np.eye(3), [3.0, 8.0, 0.5])
    choice = choose_track(track, T)
    assert choice.manipulability == 0 and not choice.solutions.valid.any()
    scan = scan_track(track, T[None])
    assert np.isnan(scan.lower[0]) and np.all(scan.manipulability == 0)


def test_ur_arm_falls_back_to_the_sampled_search():
    arm = load_robot("ur5e")
    track = TrackRobot(arm, np.eye(4), np.array([1.0, 0.0, 0.0]), 0.0, 2.0)
    T = reachable_targets(track, 5, 4)
    choice = choose_track_value(track, T, None)
    assert np.all(choice.solutions.valid.any(-1))
    with pytest.raises(InputError, match="ortho-parallel arm"):
        choose_track(track, T)


def test_errors():
    track = TrackRobot(ARM)
    with pytest.raises(InputError, match="finite track limits"):
        choose_track(track, np.eye(4))
    with pytest.raises(InputError, match="samples must be at least 3"):
        choose_track(kr16_track(), np.eye(4), samples=2)


def test_cell_ik_choice_matches_the_sampled_search_in_a_frame_on_the_table():
    from test_cellik import track_cell

    from robotcell.cell.ik import _track_robot
    from robotcell.kinematics.transforms import invert

    cell = track_cell()
    rng = np.random.default_rng(6)
    q = rng.uniform(cell.robot.lower, cell.robot.upper, (200, 6))
    th = rng.uniform(-3, 3, 200)
    T = cell.fk(q, track=rng.uniform(0.0, 6.0, 200), table=th, tool="torch", frame="part")
    sol = cell.ik(T, frame="part", table=th, tool="torch")
    T_L = invert(cell.track.T_world_L) @ cell.frame_pose("part", 0.0, th) @ T
    old = _track_robot(cell).ik(T_L, tool=cell.tools["torch"].T_F_TCP)
    ok_old = old.solutions.valid.any(-1)
    assert np.all(sol.valid.any(-1)[ok_old])
    i, b = np.nonzero(sol.valid)
    back = cell.fk(sol.q[i, b], track=sol.track[i], table=th[i], tool="torch", frame="part")
    assert np.allclose(back, T[i], atol=1e-9)
    assert np.all(cell.robot.within_limits(sol.q[i, b]))
    pa = analytic_solver(cell.robot).params
    m_new = np.where(sol.valid, np.nan_to_num(manipulability(pa, sol.q)), 0.0).max(-1)
    ratio = m_new[ok_old] / old.manipulability[ok_old]
    assert np.median(ratio) > 0.9999 and np.mean(ratio >= 0.99) >= 0.98
