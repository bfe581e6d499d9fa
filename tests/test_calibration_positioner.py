"""The 2-axis positioner calibrates like every other procedure.

It used to flag 0.62 % of clean touches (an approximate test of its own, ignoring the stated
accuracy), to assume 0.1 mm without ``--sigma`` against the documented 0.5 mm, to count a flagged
touch twice, and in half of the seeds on the example cell to write the same motion the other way
round (root X turned by 180 deg about the tilt axis, the twist of the tilt link negated,
``rotate_zero`` -180 deg).
"""

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import binom

from robotcell.calibration.fitting import touch_statistics
from robotcell.cell import Cell
from robotcell.cell import calibrate as cellcal
from robotcell.identification.positioner import calibrate_positioner, nearest_writing
from robotcell.kinematics.transforms import make_pose, rot_z
from robotcell.studies.simulate import simulate

NOISE = 1e-4
RATE = 0.0027
EXAMPLE = "examples/cell_kr16_positioner.yaml"
CHAIN = Cell.load(EXAMPLE).turntable.chain
GRID = np.radians([[t, r] for t in (-30.0, 0.0, 30.0) for r in (0.0, 90.0, 180.0, 270.0)])
POINTS = (CHAIN.fk(GRID, np.eye(4)) @ [0.2, 0.0, 0.0, 1.0])[:, :3]


def test_clean_touches_are_flagged_at_the_three_sigma_rate():
    """0.27 % +- 0.1 %: at the positioner's own Jacobian (a real calibration's), 6,000 trials of
    the 3 x 4 grid (72,000 touches; the rate's standard deviation is 0.019 %, so the band is 5
    of them wide on each side), then 60 full calibrations (720 touches) at most the 99.9 %
    binomial quantile of 1.5 times the rate."""
    rng = np.random.default_rng(11)
    res = calibrate_positioner(GRID, POINTS + rng.normal(0.0, NOISE, POINTS.shape),
                               nominal=CHAIN, sigma=NOISE).result
    J = res.fit.jacobian
    Q = np.linalg.qr(J)[0]
    e = rng.normal(0.0, NOISE, (6000, J.shape[0]))
    r = (e - (e @ Q) @ Q.T).reshape(6000, -1, 3)
    p = touch_statistics(J, r, NOISE)[0]
    rate = np.mean(p < RATE)
    assert abs(rate - RATE) < 0.001, rate
    flagged = 0
    for _ in range(60):
        out = calibrate_positioner(GRID, POINTS + rng.normal(0.0, NOISE, POINTS.shape),
                                   nominal=CHAIN, sigma=NOISE).result
        flagged += len(out.outliers) + len(out.excluded) + len(out.disagreeing)
    assert flagged <= binom.ppf(0.999, 60 * len(GRID), 1.5 * RATE)


def test_default_accuracy_and_one_count_per_flagged_touch():
    rng = np.random.default_rng(12)
    f = POINTS + rng.normal(0.0, NOISE, POINTS.shape)
    plain = calibrate_positioner(GRID, f, nominal=CHAIN).result
    assert plain.noise_source == "default" and plain.noise_sigma == 0.5e-3
    assert plain.accuracy_source == "default" and plain.residual_sigma < 3 * NOISE
    f[5] += [0.004, -0.003, 0.0]
    out = calibrate_positioner(GRID, f, nominal=CHAIN, sigma=NOISE).result
    assert out.excluded == [5] and out.outliers == []
    assert sum("outlier" in w for w in out.warnings) == 1
    reasons = out.verdict.reasons
    assert "touch(es) 6 left out as outlier(s): re-touch them" in reasons
    assert not any("2 touch(es)" in m or "flagged as outlier" in m for m in reasons)


def test_result_in_the_nominal_conventions_over_20_seeds():
    """On the example cell the axes nearly intersect (their common normal is a few hundredths
    of a millimetre, in a direction set by the noise): the result takes the nominal's side."""
    cell = Cell.load(EXAMPLE)
    nominal = cell.turntable
    for seed in range(20):
        touches = simulate(cell, "positioner", noise=NOISE, seed=seed, tool="pointer")
        out = cellcal.positioner(cell, touches.to_table(), tool="pointer", sigma=NOISE,
                                 nominal=cellcal.NominalAccuracy(1e-6, 1e-6))
        chain = out.cell.turntable.chain
        turn = Rotation.from_matrix(chain.base[:3, :3] @ nominal.chain.base[:3, :3].T)
        assert math.degrees(turn.magnitude()) < 1.0, seed
        reported = Rotation.from_matrix(out.result.values["T_world_B"][:3, :3]
                                        @ nominal.T_parent_root[:3, :3].T)
        assert math.degrees(reported.magnitude()) < 1.0, seed
        assert abs(math.degrees(out.result.values["rotate_zero"])) < 1.0, seed
        for j, n in zip(chain.joints, nominal.chain.joints):
            assert abs(math.degrees(math.remainder(j.alpha - n.alpha, 2 * math.pi))) < 1.0
            assert abs(math.degrees(math.remainder(j.theta - n.theta, 2 * math.pi))) < 1.0


def test_nearest_writing_changes_no_pose():
    """The other writings of the same chain (root turned about its Z, the tilt link's frame
    turned by 180 deg) move every frame alike; the nearest is the nominal's."""
    j1, j2 = CHAIN.joints
    phi = 2.5
    other = replace(CHAIN, base=CHAIN.base @ make_pose(rot_z(phi), np.zeros(3)), joints=(
        replace(j1, theta=j1.theta - phi + math.pi, a=-j1.a, alpha=-j1.alpha),
        replace(j2, theta=j2.theta - math.pi)))
    q = np.random.default_rng(13).uniform(-3.0, 3.0, (50, 2))
    np.testing.assert_allclose(other.fk(q), CHAIN.fk(q), atol=1e-12)
    back = nearest_writing(other, CHAIN)
    np.testing.assert_allclose(back.fk(q), CHAIN.fk(q), atol=1e-12)
    np.testing.assert_allclose(back.base, CHAIN.base, atol=1e-12)
    for j, n in zip(back.joints, CHAIN.joints):
        assert math.remainder(j.theta - n.theta, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
        assert j.alpha == pytest.approx(n.alpha, abs=1e-12) and j.a == pytest.approx(n.a)
