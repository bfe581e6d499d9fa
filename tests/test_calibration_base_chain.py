"""Uncertainty of items calibrated in the world by a robot without a track: its base turns the
tool's error into the world, and a base placed with a recorded uncertainty (robot-to-robot)
adds its own.

The physics of a cell does not change when the world is turned: turning the robot and the
turntable together by ``G`` must turn the stated covariance of the turntable (and of a frame in
the world, and of a positioner's root) by ``blkdiag(R_G, R_G)``, touch for touch. Seeded Monte Carlo (200 trials, as in
``tests/test_calibration_chain.py``): with the robot turned 60 deg in the world the spread of
(error / reported 1-sigma) lies in 0.8-1.25 for every component; and with the robot's base
placed with a recorded uncertainty and each trial's true base drawn from it, the frame in the
world states that uncertainty too (leaving the base out, the spread is above 2).
"""

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from touch_helpers import pose_error, retouched

from robotcell.cell import Cell, Provenance
from robotcell.cell import calibrate as cellcal
from robotcell.cell.calibrate.chain import perturbed
from robotcell.studies.simulate import simulate

NOISE = 1e-4
TRIALS = 200
EXAMPLE = "examples/cell_kr16_track_turntable.yaml"


def _turn(angle_deg: float) -> np.ndarray:
    G = np.eye(4)
    G[:3, :3] = Rotation.from_euler("zyx", [angle_deg, 5.0, -3.0], degrees=True).as_matrix()
    G[:3, 3] = [0.4, -0.2, 0.1]
    return G


def _fixed(G: np.ndarray = np.eye(4)) -> Cell:
    """The example cell with the robot fixed at track 2.5 m, robot and turntable moved by G."""
    track_cell = Cell.load(EXAMPLE)
    tt = track_cell.turntable
    return replace(track_cell, track=None, T_world_R=G @ track_cell.frame_pose("robot", track=2.5),
                   turntable=replace(tt, T_parent_B=G @ tt.T_parent_B))


def _covariance(result, key):
    return result.estimates[key].sources.covariance


@pytest.mark.parametrize("angle", [90.0, -140.0])
def test_a_robot_turned_in_the_world_states_the_turned_uncertainty(angle):
    G = _turn(angle)
    plain, turned = _fixed(), _fixed(G)
    tool = plain.tools["pointer"].T_F_TCP
    tcp_design = simulate(plain, "tcp", noise=0.0, tool="pointer")
    designs = {"turntable": simulate(plain, "turntable", noise=0.0, tool="pointer"),
               "frame": simulate(plain, "frame", noise=0.0, tool="pointer", frame="fixture")}
    A = np.kron(np.eye(2), G[:3, :3])
    for cell in (plain, turned):
        rng = np.random.default_rng(5)
        t = cellcal.tcp(cell, retouched(tcp_design, plain, tool, rng, NOISE), "pointer",
                        sigma=NOISE)
        tt = cellcal.turntable(t.cell, retouched(designs["turntable"], plain, tool, rng, NOISE),
                               tool="pointer", sigma=NOISE, height=-0.05)
        fr = cellcal.frame(t.cell, retouched(designs["frame"], plain, tool, rng, NOISE),
                           "fixture", parent="world", tool="pointer", sigma=NOISE)
        if cell is plain:
            expected = {"T_world_B": A @ _covariance(tt.result, "T_world_B") @ A.T,
                        "T_R_W": A @ _covariance(fr.result, fr.value) @ A.T}
        else:
            got = {"T_world_B": _covariance(tt.result, "T_world_B"),
                   "T_R_W": _covariance(fr.result, fr.value)}
    for key in expected:
        scale = np.sqrt(np.outer(np.diag(expected[key]), np.diag(expected[key])))
        np.testing.assert_allclose(got[key] / scale, expected[key] / scale, atol=1e-6,
                                   err_msg=key)


def test_a_turntable_touched_by_a_turned_robot_states_an_honest_sigma():
    plain, cell = _fixed(), _fixed(_turn(60.0))  # the same touches: robot and table turned
    tool = cell.tools["pointer"].T_F_TCP
    tcp_design = simulate(plain, "tcp", noise=0.0, tool="pointer")
    tt_design = simulate(plain, "turntable", noise=0.0, tool="pointer")
    rng = np.random.default_rng(11)
    z = []
    for _ in range(TRIALS):
        t = cellcal.tcp(cell, retouched(tcp_design, cell, tool, rng, NOISE), "pointer",
                        sigma=NOISE)
        r = cellcal.turntable(t.cell, retouched(tt_design, cell, tool, rng, NOISE),
                              tool="pointer", sigma=NOISE, height=-0.05).result
        z.append(pose_error(r.values["T_world_B"], cell.turntable.T_parent_B)
                 / np.r_[r.sigma["T_world_B_position"], r.sigma["T_world_B_rotation"]])
    spread = np.sqrt(np.mean(np.square(z), axis=0))
    assert np.all((spread > 0.8) & (spread < 1.25)), np.round(spread, 3)


#: The recorded 1-sigma of the placed base: 0.5 mm and 0.05 deg per axis.
BASE_SIGMA = np.r_[np.full(3, 5e-4), np.full(3, np.radians(0.05))]


def _placed(cell: Cell, T_world_R: np.ndarray) -> Cell:
    prov = Provenance.now("robot-to-robot")
    prov = replace(prov, sources={"robot-to-robot": np.diag(BASE_SIGMA)})
    return replace(cell, robots={cell.robot_name: replace(
        cell.robots[cell.robot_name], T_world_R=T_world_R, base_provenance=prov)})


@pytest.mark.parametrize("with_base", [True, False])
def test_a_frame_in_the_world_carries_the_recorded_uncertainty_of_the_robots_base(with_base):
    truth = _fixed()
    tool = truth.tools["pointer"].T_F_TCP
    tcp_design = simulate(truth, "tcp", noise=0.0, tool="pointer")
    design = simulate(truth, "frame", noise=0.0, tool="pointer", frame="fixture")
    rng = np.random.default_rng(17)
    z = []
    for _ in range(TRIALS):
        recorded = perturbed(truth.T_world_R, rng.normal(0.0, BASE_SIGMA))
        cell = _placed(truth, recorded) if with_base else replace(truth, T_world_R=recorded)
        cell = cellcal.tcp(cell, retouched(tcp_design, truth, tool, rng, NOISE), "pointer",
                           sigma=NOISE).cell
        done = cellcal.frame(cell, retouched(design, truth, tool, rng, NOISE), "fixture",
                             parent="world", tool="pointer", sigma=NOISE)
        r = done.result
        z.append(pose_error(r.values[done.value], truth.frames["fixture"].pose)
                 / np.r_[r.sigma[f"{done.value}_position"], r.sigma[f"{done.value}_rotation"]])
    spread = np.sqrt(np.mean(np.square(z), axis=0))
    if with_base:
        assert np.all((spread > 0.8) & (spread < 1.25)), np.round(spread, 3)
        assert "base" in done.inputs
        assert "robot-to-robot" in done.provenance.sources
    else:  # a base without a recorded uncertainty is exact: its error is not stated
        assert np.max(spread) > 2.0, np.round(spread, 3)
        assert "base" not in done.inputs


def test_a_positioner_touched_by_a_turned_robot_states_the_turned_uncertainty():
    plain = Cell.load("examples/cell_kr16_positioner.yaml")
    G = _turn(90.0)
    pos = plain.turntable
    turned = replace(plain, T_world_R=G @ plain.T_world_R,
                     turntable=replace(pos, chain=pos.chain.with_base(G @ pos.chain.base)))
    tool = plain.tools["pointer"].T_F_TCP
    designs = {k: simulate(plain, k, noise=0.0, tool="pointer") for k in ("tcp", "positioner")}
    covariance = {}
    for name, cell in (("plain", plain), ("turned", turned)):
        rng = np.random.default_rng(5)
        t = cellcal.tcp(cell, retouched(designs["tcp"], plain, tool, rng, NOISE), "pointer",
                        sigma=NOISE)
        done = cellcal.positioner(t.cell, retouched(designs["positioner"], plain, tool, rng,
                                                    NOISE), tool="pointer", sigma=NOISE)
        covariance[name] = _covariance(done.result, "T_world_B")
    A = np.kron(np.eye(2), G[:3, :3])
    expected = A @ covariance["plain"] @ A.T
    scale = np.sqrt(np.outer(np.diag(expected), np.diag(expected)))
    np.testing.assert_allclose(covariance["turned"] / scale, expected / scale, atol=1e-6)
