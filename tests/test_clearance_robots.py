"""Clearance between the robots of a cell: a crafted pass of two torches 10 mm apart flagged at
its segment against point-to-segment geometry, 200 mm passing, and the errors users meet."""

import numpy as np
import pytest

from robotcell.cell import Cell, cell_from_dict
from robotcell.clearance import Body, LinkModel, clearance_between
from robotcell.clearance.bodies import BodiesFile
from robotcell.errors import InputError

pytest.importorskip("coal")

TOOL = np.eye(4)
TOOL[2, 3] = 0.3                     # a straight torch 300 mm along the flange's z
LINKS = LinkModel(radius=0.05, tool_radius=0.02)


def _cell(gap=0.0):
    """Robot a at the origin; robot b facing it, 1.8 m from a's torch plus ``gap`` and the
    torches' radii (where b reaches along its torch's axis)."""
    x = 1000 + 1800 + (gap + 2 * LINKS.tool_radius) * 1e3
    return cell_from_dict({"name": "two", "robots": {
        "a": {"model": "kuka_kr16"},
        "b": {"model": "kuka_kr16", "frame": {"x": x, "y": 0, "z": 0, "a": 180, "b": 0,
                                               "c": 0}}}})


def _segment_distance(p, a, b):
    """Distance of point p from segment ab, by projection (independent of the library)."""
    ab = b - a
    t = np.clip(np.dot(p - a, ab) / max(np.dot(ab, ab), 1e-300), 0.0, 1.0)
    return np.linalg.norm(p - (a + t * ab))


def _joints(robot, T):
    """Joint values reaching the TCP poses ``T`` (robot base, tool TOOL) on one branch."""
    sol = robot.ik(T, TOOL)
    q = [sol.q[0][np.flatnonzero(sol.valid[0])[0]]]
    for k in range(1, len(T)):
        ok = np.flatnonzero(sol.valid[k])
        q.append(sol.q[k][ok[np.argmin(np.linalg.norm(sol.q[k][ok] - q[-1], axis=1))]])
    return np.array(q)


def _pass(cell, n=11):
    """Robot a holds its torch straight down at (1, 0, 0.5) m; robot b's torch points at it
    and its tip runs along y at 150 mm above a's tip, the cell's gap from a's torch (capsule
    to capsule); y = 0, the closest place, lies in the middle of segment 5 -> 6."""
    T_a = np.diag([1.0, -1.0, -1.0, 1.0])
    T_a[:3, 3] = [1.0, 0.0, 0.5]
    q_a = np.repeat(_joints(cell.for_robot("a").robot, T_a[None]), n, axis=0)
    y = np.linspace(-0.44, 0.36, n)
    T_b = np.tile(np.eye(4), (n, 1, 1))
    T_b[:, :3, :3] = [[0, 0, 1], [0, -1, 0], [1, 0, 0]]      # z at a, in b's base (turned 180)
    T_b[:, :3, 3] = np.column_stack([np.full(n, 1.8), -y,
                                     np.full(n, 0.65)])
    q_b = _joints(cell.for_robot("b").robot, T_b)
    return q_a, q_b


def test_two_torches_passing_10_mm_apart_are_flagged_at_their_segment_and_200_mm_passes():
    for gap, flagged in ((0.010, True), (0.200, False)):
        cell = _cell(gap)
        q_a, q_b = _pass(cell)
        got = clearance_between(cell, {"a": q_a, "b": q_b}, tools={"a": TOOL, "b": TOOL},
                                bodies=BodiesFile(links=LINKS),
                                motion={"a": "joint", "b": "linear"}, step=0.005)
        seg = got.per_segment()
        if flagged:
            assert np.argmin(seg) == 5 and seg[5] == pytest.approx(gap, abs=1e-3)
            assert got.pair[np.argmin(got.distance)] == ("a.tool", "b.tool")
            assert np.all(np.delete(seg, 5) > gap + 0.01)
        else:
            assert seg.min() > 0.19
        # every sample where the torches are the closest pair: tip of b's torch against the
        # segment of a's torch, less both radii
        a = cell.for_robot("a")
        T_F = a.robot.fk(q_a[0], np.eye(4))
        A0, A1 = T_F[:3, 3], (T_F @ TOOL)[:3, 3]
        b = cell.for_robot("b")
        tip = (b.T_world_R @ b.robot.fk(q_b, TOOL))[:, :3, 3]
        torches = np.array([p == ("a.tool", "b.tool") for p in got.pair])
        assert torches.sum() > 10
        for k in np.flatnonzero(torches):
            i = min(int(got.position[k]), len(tip) - 2)
            f = got.position[k] - i
            p = tip[i] * (1 - f) + tip[i + 1] * f                 # b moves linearly
            want = _segment_distance(p, A0, A1) - 2 * LINKS.tool_radius
            assert got.distance[k] == pytest.approx(want, abs=1e-6)


def test_each_robot_is_checked_against_the_parts_too():
    cell = _cell(0.2)
    q_a, q_b = _pass(cell, n=3)
    ball = Body("ball", "sphere", (0.05,), "world", np.eye(4))
    ball.pose[:3, 3] = [1.0, 0.0, 0.5 - 0.02 - 0.05 - 0.03]      # 30 mm under a's torch tip
    got = clearance_between(cell, {"a": q_a, "b": q_b}, tools={"a": TOOL, "b": TOOL},
                            bodies=BodiesFile((ball,), LINKS))
    assert got.minimum == pytest.approx(0.03, abs=1e-6)
    assert got.pair[np.argmin(got.distance)] == ("a.tool", "ball")
    ignored = BodiesFile((ball,), LINKS, (("tool", "ball"),))      # every robot's torch
    again = clearance_between(cell, {"a": q_a, "b": q_b}, tools={"a": TOOL, "b": TOOL},
                              bodies=ignored)
    assert ("a.tool", "ball") not in again.pair and again.minimum > 0.03


def test_the_example_cell_of_two_robots_on_a_positioner_is_checked():
    cell = Cell.load("examples/cell_two_robots_positioner.yaml")
    q = np.radians([[0, -90, 90, 0, 45, 0], [10, -80, 95, 0, 50, 0]])
    plate = Body("plate", "cylinder", (0.4, 0.03), "plate", np.eye(4))
    got = clearance_between(cell, {"kuka": q, "abb": q}, track={"kuka": [1.0, 1.2]},
                            table=np.radians([[0, 0], [10, 20]]),
                            tools={"kuka": "torch", "abb": "torch"},
                            bodies=BodiesFile((plate,)))
    assert np.all(np.isfinite(got.distance)) and got.per_point().shape == (2,)
    assert all(p[0].split(".")[0] in ("kuka", "abb") for p in got.pair)


@pytest.mark.parametrize("call, match", [
    (lambda c: clearance_between(c, {"c": np.zeros((2, 6))}), r"no robot 'c'.*a, b"),
    (lambda c: clearance_between(c, {"a": np.zeros((2, 6)), "b": np.zeros((3, 6))}),
     r"as many points each: a 2, b 3"),
    (lambda c: clearance_between(c, {"a": np.zeros((2, 5))}), r"shape \(N, 6\)"),
    (lambda c: clearance_between(c, {}), r"at least one robot"),
    (lambda c: clearance_between(c, {"a": np.zeros((2, 6))}, bodies=BodiesFile(
        (Body("grip", "sphere", (0.05,), "flange"),))), r"'a\.flange', 'b\.flange'"),
])
def test_bad_calls_name_the_cause(call, match):
    with pytest.raises(InputError, match=match):
        call(_cell())


def test_a_part_held_by_a_robots_flange_moves_with_it_and_is_named_by_it():
    cell = _cell(0.2)
    q_a, q_b = _pass(cell, n=3)
    grip = Body("grip", "sphere", (0.03,), "a.flange", np.eye(4))
    grip.pose[:3, 3] = [0, 0, 0.3]                               # at a's torch tip
    tip = (cell.for_robot("a").robot.fk(q_a[0], TOOL))[:3, 3]
    ball = Body("ball", "sphere", (0.05,), "world", np.eye(4))
    ball.pose[:3, 3] = tip - [0, 0, 0.03 + 0.05 + 0.04]         # 40 mm under the held sphere
    near = clearance_between(cell, {"a": q_a, "b": q_b}, tools={"a": TOOL, "b": TOOL},
                             bodies=BodiesFile((grip, ball), LINKS, (("tool", "*"),)))
    assert near.minimum == pytest.approx(0.04, abs=1e-6)
    assert near.pair[np.argmin(near.distance)] == ("a.grip", "ball")


def test_a_part_on_a_robots_base_moves_with_its_track():
    cell = Cell.load("examples/cell_two_robots_positioner.yaml")
    q = np.radians([[0, -90, 90, 0, 45, 0]] * 2)
    post = Body("post", "sphere", (0.02,), "kuka", np.eye(4))       # 1 m above the carriage
    post.pose[:3, 3] = [0, 0, 1.0]
    only = BodiesFile((post,), LINKS, (("*", "post"),))
    for track in (0.5, 2.0):
        got = clearance_between(cell, {"kuka": q, "abb": q}, track={"kuka": track},
                                tools={"kuka": "torch", "abb": "torch"},
                                bodies=BodiesFile((post,), LINKS))
        assert np.isfinite(got.minimum)
        assert np.all(np.isinf(clearance_between(
            cell, {"kuka": q}, track={"kuka": track}, bodies=only).distance))
    near = [clearance_between(cell, {"kuka": q}, track={"kuka": t}, tools={"kuka": "torch"},
                              bodies=BodiesFile((post,), LINKS)).minimum for t in (0.5, 2.0)]
    assert near[0] == pytest.approx(near[1], abs=1e-9)     # the post rides with the carriage
