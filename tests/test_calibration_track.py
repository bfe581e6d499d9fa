"""Linear track calibration: what one unknown point determines, what known points add, refusals."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import IllPosedError, InputError
from robotcell.calibration.track import TRACK_AXES, calibrate_track, zero_roll_rotation

SIGMA = 1e-4  # touch noise per coordinate, m


class Track:
    """A synthetic robot on a track: L_Q_R, scale, carriage offset c, track axis of L."""

    def __init__(self, axis="x", rotvec=(0.01, -0.02, 0.03), scale=1.0008, offset=(0.0, 0.0, 0.0)):
        self.axis = axis
        self.d = TRACK_AXES[axis]
        self.Q = Rotation.from_rotvec(rotvec).as_matrix()
        self.scale = scale
        self.c = np.asarray(offset, dtype=float)

    @property
    def direction(self):
        return self.Q.T @ self.d

    def touches(self, ref_L, e, rng=None, sigma=SIGMA):
        """TCP positions in R of the fixed point ref_L (in L) at track positions e."""
        f = (np.asarray(ref_L) - self.c - np.outer(e, self.scale * self.d)) @ self.Q
        return f if rng is None else f + rng.normal(0.0, sigma, f.shape)


E = np.linspace(0.2, 2.2, 7)
REF = np.array([1.5, 0.8, 0.3])
REF2 = np.array([2.1, -0.6, 0.1])


def rot_error(Q_est, Q_true):
    return Rotation.from_matrix(Q_est @ Q_true.T).as_rotvec()


def test_unknown_point_gives_direction_scale_point_and_nothing_more():
    cell = Track()
    r = calibrate_track(E, cell.touches(REF, E))
    np.testing.assert_allclose(r.values["direction"], cell.direction, atol=1e-12)
    np.testing.assert_allclose(r.values["direction"], cell.Q[0], atol=1e-12)  # first row of L_Q_R
    assert r.values["scale"] == pytest.approx(cell.scale, abs=1e-12)
    np.testing.assert_allclose(r.values["point"], cell.Q.T @ REF, atol=1e-12)
    assert "T_L_R" not in r.values
    assert r.json_fields["rotation"] is None and r.json_fields["offset_mm"] is None
    assert any("about the track axis" in u for u in r.undetermined)
    assert r.max < 1e-12 and r.dof == 3 * len(E) - 6


def test_roll_about_the_track_axis_leaves_every_touch_unchanged():
    """Two cells differing by a roll about the track axis (and a point rotated with it) give the
    same touches, so no estimator can recover the roll from them."""
    a = Track()
    b = Track()
    roll = Rotation.from_rotvec(0.3 * a.d).as_matrix()
    b.Q = roll @ a.Q
    np.testing.assert_allclose(a.touches(REF, E), b.touches(roll @ REF, E), atol=1e-12)
    assert np.linalg.norm(rot_error(a.Q, b.Q)) == pytest.approx(0.3)
    # Two different carriage offsets with correspondingly moved points: again identical touches.
    c = Track(offset=(0.0, 0.01, -0.02))
    np.testing.assert_allclose(a.touches(REF, E), c.touches(REF + c.c, E), atol=1e-12)


@pytest.mark.parametrize("axis", ["x", "z"])
def test_zero_roll_convention_is_the_smallest_rotation(axis):
    cell = Track(axis=axis, rotvec=(0.01, -0.02, 0.03) if axis == "x" else (0.02, -1.5, 0.01))
    r = calibrate_track(E, cell.touches(REF, E), axis=axis, roll="zero")
    Q = r.values["T_L_R"][:3, :3]
    assert np.linalg.det(Q) == pytest.approx(1.0)
    np.testing.assert_allclose(Q @ r.values["direction"], cell.d, atol=1e-12)
    rotvec = Rotation.from_matrix(Q).as_rotvec()
    assert rotvec @ cell.d == pytest.approx(0.0, abs=1e-12)  # no rotation about the track axis
    assert rotvec @ r.values["direction"] == pytest.approx(0.0, abs=1e-12)
    assert r.json_fields["rotation_source"] == "convention: zero roll"
    assert any("zero-roll convention" in u for u in r.undetermined)


def test_zero_roll_refuses_a_reversed_track():
    with pytest.raises(IllPosedError, match="not unique"):
        zero_roll_rotation([-1.0, 0.0, 0.0], "x")


@pytest.mark.parametrize("axis", ["x", "z"])
def test_one_known_point_gives_the_rotation(axis):
    cell = Track(axis=axis)
    ref = np.array([0.9, 0.7, 0.4])
    r = calibrate_track(E, cell.touches(ref, E), references=[ref], axis=axis)
    np.testing.assert_allclose(rot_error(r.values["T_L_R"][:3, :3], cell.Q), 0.0, atol=1e-10)
    row = 0 if axis == "x" else 2
    np.testing.assert_allclose(r.values["direction"], cell.Q[row], atol=1e-10)
    assert r.values["scale"] == pytest.approx(cell.scale, abs=1e-10)
    assert r.json_fields["offset_mm"] is None and any("offset" in u for u in r.undetermined)


def test_two_known_points_give_rotation_and_carriage_offset():
    cell = Track(offset=(0.004, 0.002, -0.003))
    e2 = E[:4] + 0.05
    f = np.vstack([cell.touches(REF, E), cell.touches(REF2, e2)])
    point = np.r_[np.zeros(len(E), int), np.ones(len(e2), int)]
    r = calibrate_track(np.r_[E, e2], f, references=[REF, REF2], point=point)
    np.testing.assert_allclose(rot_error(r.values["T_L_R"][:3, :3], cell.Q), 0.0, atol=1e-10)
    np.testing.assert_allclose(r.values["T_L_R"][:3, 3], cell.c, atol=1e-10)
    np.testing.assert_allclose(r.json_fields["offset_mm"], cell.c * 1e3, atol=1e-7)
    assert r.undetermined == []


def monte_carlo(make, truth, trials=200, seed=0):
    rng = np.random.default_rng(seed)
    errs, sigmas = [], []
    for _ in range(trials):
        est, sig = make(rng)
        errs.append(est - truth)
        sigmas.append(sig)
    return np.std(errs, axis=0), np.mean(sigmas, axis=0)


def test_unknown_point_sigmas_match_monte_carlo():
    cell = Track()

    def run(rng):
        r = calibrate_track(E, cell.touches(REF, E, rng), sigma=SIGMA)
        return (np.r_[r.values["direction"][1:], r.values["scale"]],
                np.r_[r.sigma["direction"][1:], r.sigma["scale"]])

    spread, sigma = monte_carlo(run, np.r_[cell.direction[1:], cell.scale])
    np.testing.assert_allclose(spread / sigma, 1.0, atol=0.25)


def test_known_points_sigmas_match_monte_carlo():
    cell = Track(offset=(0.004, 0.002, -0.003))
    e2 = E[:4] + 0.05
    point = np.r_[np.zeros(len(E), int), np.ones(len(e2), int)]

    def run(rng):
        f = np.vstack([cell.touches(REF, E, rng), cell.touches(REF2, e2, rng)])
        r = calibrate_track(np.r_[E, e2], f, references=[REF, REF2], point=point,
                            sigma=SIGMA)
        T = r.values["T_L_R"]
        return (np.r_[rot_error(T[:3, :3], cell.Q), r.values["scale"], T[:3, 3]],
                np.r_[r.sigma["T_L_R_rotation"], r.sigma["scale"], r.sigma["T_L_R_position"]])

    truth = np.r_[np.zeros(3), cell.scale, cell.c]
    spread, sigma = monte_carlo(run, truth, seed=1)
    np.testing.assert_allclose(spread / sigma, 1.0, atol=0.25)


def test_straightness_and_outlier_are_reported():
    cell = Track()
    rng = np.random.default_rng(3)
    f = cell.touches(REF, E, rng)
    across = np.cross(cell.direction, [0.0, 0.0, 1.0])
    f[3] += 0.002 * across / np.linalg.norm(across)  # a 2 mm kink across the track at touch 4
    r = calibrate_track(E, f, sigma=SIGMA)
    assert int(np.argmax(r.json_fields["straightness_mm"])) == 3
    assert r.json_fields["straightness_mm"][3] > 1.0
    assert any(w.startswith("touch 4 is an outlier") for w in r.warnings)


def test_scale_warning_and_sigma_prior():
    cell = Track(scale=1.05)
    r = calibrate_track(E, cell.touches(REF, E), sigma=SIGMA)
    assert any("scale 1.05000" in w for w in r.warnings)
    assert r.noise_source == "prior" and r.sigma["scale"] > 0


def test_refusals():
    cell = Track()
    f = cell.touches(REF, E)
    with pytest.raises(InputError, match="at least 3 needed"):
        calibrate_track(E[:2], f[:2])
    e = np.full(4, 1.0)
    with pytest.raises(IllPosedError, match=r"all 4 touches are at the same track position "
                       r"\(1000.000 mm\), so the track direction and scale are not determined"):
        calibrate_track(e, cell.touches(REF, e))
    with pytest.raises(InputError, match="not in the track's length unit"):
        calibrate_track(E * 1e3, f)  # track values in mm passed as metres
    near_axis = np.array([0.8, 0.01, 0.0])
    r = calibrate_track(E, cell.touches(near_axis, E), references=[near_axis])
    assert any("only 10.0 mm from the track axis" in w for w in r.warnings)
    on_axis = np.array([0.8, 0.0, 0.0])
    with pytest.raises(IllPosedError, match="lies on the track axis.*at least 50 mm off"):
        calibrate_track(E, cell.touches(on_axis, E), references=[on_axis])
    pair = [REF, REF + [0.5, 0.0, 0.0]]
    with pytest.raises(IllPosedError, match="one line parallel to the track axis"):
        calibrate_track(E, f, references=pair, point=np.arange(len(E)) % 2)
    with pytest.raises(InputError, match="leave roll unset"):
        calibrate_track(E, f, references=[REF], roll="zero")
    with pytest.raises(InputError, match="say which one"):
        calibrate_track(E, f, references=[REF, REF2])
    with pytest.raises(InputError, match=r"point\(s\) 2 were never touched"):
        calibrate_track(E, f, references=[REF, REF2], point=np.zeros(len(E), int))
    with pytest.raises(InputError, match="track axis must be one of"):
        calibrate_track(E, f, axis="y")
    with pytest.raises(InputError, match="roll must be None or 'zero'"):
        calibrate_track(E, f, roll="level")
    with pytest.raises(InputError, match="NaN"):
        calibrate_track(np.r_[E[:-1], np.nan], f)
