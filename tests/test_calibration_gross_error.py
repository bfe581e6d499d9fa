"""One gross error: the bad touch is named and left out, the clean ones are not flagged; a touch no
other checks keeps the verdict from GOOD.

With the touch accuracy stated, one touch 5 mm off used to pull the fit so far that most clean
touches were flagged too (track: 7 of 8 on average, turntable: 5.6 of 6). Each touch is now tested
with its leave-one-out residual; the bad touch, singled out by the others, is left out (or, when
two touches of one point disagree and nothing tells which is wrong, both are named and the result
graded poor). The others are then flagged at the 0.27 % rate: with 5 to 11 clean touches, 1.3 to
3 % of trials flag one more touch (measured: 98-99 % of trials flag at most the bad touch, for
every procedure). The test requires at most the bad touch flagged in 95 % of all 380 trials
(binomial, at a 2 % rate: 20 extra flags or more have a probability of 1e-4) and in 90 % of each
procedure's 80 (60 for the positioner; at 3 %, a probability of 0.3 %).
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from touch_helpers import gross_offset, retouched

from robotcell.calibration.frame import frame_3point
from robotcell.calibration.track import calibrate_track
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.calibration.workpiece import calibrate_workpiece
from robotcell.cell import Cell
from robotcell.cell import calibrate as cellcal
from robotcell.identification.positioner import calibrate_positioner
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points
from robotcell.studies.simulate import simulate

NOISE = 1e-4
GROSS = 5e-3
TRIALS = {"track": 80, "turntable": 80, "frame": 80, "workpiece": 80, "positioner": 60}
T_R_B = make_pose(Rotation.from_rotvec([0.02, -0.01, 0.7]).as_matrix(), [1.2, 0.3, 0.4])
T_FRAME = make_pose(Rotation.from_rotvec([0.1, -0.2, 0.6]).as_matrix(), [1.2, -0.3, 0.5])
Q = Rotation.from_rotvec([0.01, -0.02, 0.03]).as_matrix()
REFS = np.array([[1.5, 0.8, 0.3], [2.1, -0.6, 0.1]])
E = np.tile(np.linspace(0.0, 1.5, 4), 2)
POINT = np.repeat([0, 1], 4)
THETA = np.radians([0.0, 60.0, 130.0, 200.0, 270.0, 320.0])
ROLES = ["origin", "origin", "x", "x", "xy", "xy"]
LOCAL = np.array([[0, 0, 0], [0, 0, 0], [0.3, 0, 0], [0.15, 0, 0], [0.1, 0.2, 0], [0.25, 0.1, 0]])
POSITIONER = Cell.load("examples/cell_kr16_positioner.yaml").turntable.chain
GRID = np.radians([[t, r] for t in (-30.0, 0.0, 30.0) for r in (0.0, 90.0, 180.0, 270.0)])


def track(f):
    return calibrate_track(E, f, references=REFS, point=POINT, sigma=NOISE)


def turntable(f):
    return calibrate_turntable(THETA, f, sigma=NOISE)


def frame(f):
    return frame_3point(f, ROLES, NOISE)


WP_THETA = np.radians([10.0, 100.0, 200.0, 250.0, 310.0, 35.0])


def workpiece(f):
    return calibrate_workpiece(WP_THETA, f, ROLES, T_R_B, sigma=NOISE)


def positioner(f):
    return calibrate_positioner(GRID, f, nominal=POSITIONER, sigma=NOISE).result


CLEAN = {
    "track": (track, (REFS[POINT] - np.outer(E, [1, 0, 0])) @ Q),
    "turntable": (turntable, transform_points(T_R_B, np.einsum("nij,j->ni", rot_z(THETA),
                                                               [0.3, 0, 0]))),
    "frame": (frame, transform_points(T_FRAME, LOCAL)),
    "workpiece": (workpiece, transform_points(T_R_B, np.einsum(
        "nij,nj->ni", rot_z(WP_THETA), transform_points(T_FRAME @ make_pose(np.eye(3), [
            -1.0, 0.4, -0.3]), LOCAL)))),
    "positioner": (positioner, (POSITIONER.fk(GRID, np.eye(4)) @ [0.2, 0.0, 0.0, 1.0])[:, :3]),
}


def test_one_gross_touch_is_named_and_leaves_the_clean_ones_alone():
    alone = {}
    for name, (calibrate, clean) in CLEAN.items():
        rng = np.random.default_rng(list(CLEAN).index(name))
        alone[name] = named = 0
        for _ in range(TRIALS[name]):
            offset, bad = gross_offset(rng, len(clean), GROSS)
            r = calibrate(clean + rng.normal(0.0, NOISE, clean.shape) + offset)
            flagged = set(r.outliers) | set(r.excluded)
            alone[name] += flagged <= {bad}
            named += bad in flagged | set(r.disagreeing)
            assert r.verdict.level != "good" or not (flagged or r.disagreeing)
        assert alone[name] >= 0.9 * TRIALS[name], (name, alone[name])
        # A 5 mm error is 50 touch sigmas: named (alone, or as one of two touches that
        # disagree) unless it lies along a direction the touch does not measure (an x touch's
        # error along X, an xy touch's in the XY plane).
        assert named >= 0.8 * TRIALS[name], (name, named)
    assert sum(alone.values()) >= 0.95 * sum(TRIALS.values()), alone


def test_the_bad_touch_is_left_out_and_the_result_says_so():
    calibrate, clean = CLEAN["turntable"]
    rng = np.random.default_rng(7)
    f = clean + rng.normal(0.0, NOISE, clean.shape)
    f[4] += [GROSS, 0.0, 0.0]
    r = calibrate(f)
    assert r.excluded == [4] and r.outliers == []
    clean_fit = calibrate_turntable(np.delete(THETA, 4), np.delete(f, 4, axis=0),
                                    sigma=NOISE)
    np.testing.assert_allclose(r.values["T_R_B"], clean_fit.values["T_R_B"], atol=1e-9)
    assert r.rms < 2 * NOISE and r.residual_norms[4] > 4e-3  # against the others' fit
    assert "touch 5 is an outlier at 3 sigma" in r.warnings[0] and "left out" in r.warnings[0]
    assert "left out of the result (outliers; see the warnings): 5" in r.summary()
    v = r.verdict
    assert v.level == "check" and "touch(es) 5 left out as outlier(s): re-touch them" in v.reasons
    assert r.to_json()["excluded"] == ["5"]


def test_a_gross_error_that_cannot_be_left_out_is_poor():
    """Two gross errors: leaving one out does not explain the rest, so both are kept, and a
    touch beyond 3 sigma of three times the accuracy makes the result poor."""
    calibrate, clean = CLEAN["turntable"]
    f = clean + np.random.default_rng(8).normal(0.0, NOISE, clean.shape)
    f[[1, 4]] += [[0.0, GROSS, 0.0], [GROSS, 0.0, 0.0]]
    r = calibrate(f)
    assert r.excluded == [] and r.gross
    assert r.verdict.level == "poor" and any("cannot be computed without them" in m
                                             for m in r.verdict.reasons)


# -- the tool orientation from single touches ---------------------------------------------------
EXAMPLE = Cell.load("examples/cell_kr16_track_turntable.yaml")
TCP_DESIGN = simulate(EXAMPLE, "tcp", noise=0.0, tool="pointer")


def tcp_trials(rng, design, bad_row, sigma, trials=40):
    """Verdicts and tool rotation errors (deg) with a 5 mm error on row ``bad_row``."""
    tool = EXAMPLE.tools["pointer"].T_F_TCP
    out = []
    for _ in range(trials):
        offset = np.zeros((len(design.q), 3))
        v = rng.normal(size=3)
        offset[bad_row] = GROSS * v / np.linalg.norm(v)
        r = cellcal.tcp(None, retouched(design, EXAMPLE, tool, rng, NOISE, offset),
                        robot=EXAMPLE.robot, sigma=sigma).result
        angle = Rotation.from_matrix(r.values["T_F_TCP"][:3, :3] @ tool[:3, :3].T).magnitude()
        out.append((r.verdict, math.degrees(angle), r))
    return out


@pytest.mark.parametrize("sigma", [NOISE, None], ids=["sigma-stated", "default-accuracy"])
def test_a_5_mm_error_on_the_single_minus_x_touch_never_gives_good(sigma):
    """The tool direction rests on the single -x touch (and its rotation about X on the single xy
    touch): nothing checks them, so the verdict is at most CHECK, naming the touch to repeat."""
    assert TCP_DESIGN.roles == ["tcp"] * 4 + ["-x", "xy"]
    runs = tcp_trials(np.random.default_rng(3), TCP_DESIGN, 4, sigma)
    assert all(v.level != "good" for v, _, _ in runs)
    assert max(a for _, a, _ in runs) > 1.0  # the error is real: degrees of tool rotation
    v, _, r = runs[0]
    assert r.unchecked == [4, 5] and any(
        "line 6 (-x), line 7 (xy) decide part of the result alone" in m for m in v.reasons)


def test_repeated_orientation_touches_are_tested_and_may_be_good():
    """Touched twice, the -x and xy touches check each other: clean touches can be GOOD, and a
    5 mm error on one of them is flagged and never GOOD."""
    from dataclasses import replace

    rows = [0, 1, 2, 3, 4, 4, 5, 5]
    twice = replace(TCP_DESIGN, q=TCP_DESIGN.q[rows], roles=[TCP_DESIGN.roles[i] for i in rows])
    rng = np.random.default_rng(4)
    tool = EXAMPLE.tools["pointer"].T_F_TCP
    clean = [cellcal.tcp(None, retouched(twice, EXAMPLE, tool, rng, NOISE), robot=EXAMPLE.robot,
                         sigma=NOISE).result for _ in range(10)]
    assert all(r.unchecked == [] for r in clean)
    assert sum(r.verdict.level == "good" for r in clean) >= 8
    runs = tcp_trials(rng, twice, 4, NOISE)
    assert all(v.level != "good" for v, _, _ in runs)
    # Named: alone, or with its twin as two touches that disagree (nothing tells which is wrong).
    assert sum(4 in r.outliers + r.excluded + r.disagreeing for _, _, r in runs) >= 0.9 * len(runs)
