"""False alarms of the outlier flag: 0.27 % per touch at 3 sigma, for every procedure.

Each residual is standardised by its own variance (the touch's leverage and the degrees of
freedom the fit spends; ``robotcell.calibration.fitting.touch_statistics``), so on clean data a
touch is flagged with the 3-sigma probability 0.27 % when the stated ``--sigma`` is the touch
noise. Two seeded Monte Carlo checks per procedure:

1. At the procedure's own Jacobian (taken from a real calibration), 60,000 or more touches of
   clean noise through the linearised fit: the rate lies within a factor 1.5 of 0.27 %. With
   about 160 expected flags, the bounds are more than 4 standard deviations away, so the test
   fails only when the standardisation is wrong.
2. The full procedure (nonlinear fit, the warnings a technician reads) on about 1,000 touches of
   clean data: at most the 99.9 % binomial quantile for a rate of 1.5 x 0.27 % (11 flags). This
   ties the warnings to part 1; a gross error (such as the 1.65 % of a 4-touch TCP before this
   standardisation, 16 expected flags) fails it. Measured on 6,000 touches per case, the full
   procedures flag 0.17 % to 0.42 %.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import binom

import robotcell.calibration.frame as frame_mod
import robotcell.calibration.tcp as tcp_mod
import robotcell.calibration.track as track_mod
import robotcell.calibration.turntable as turntable_mod
import robotcell.calibration.workpiece as workpiece_mod
from robotcell.calibration.fitting import touch_statistics
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points

RATE = 0.0027  # the documented false-alarm rate per touch (3 sigma)
NOISE = 1e-4
TCP = np.array([0.01, -0.02, 0.2])
PIVOT = np.array([1.1, 0.2, 0.5])
R_TOOL = Rotation.from_euler("zyx", [10, -80, 5], degrees=True).as_matrix()
T_FRAME = make_pose(Rotation.from_rotvec([0.1, -0.2, 0.6]).as_matrix(), [1.2, -0.3, 0.5])
Q = Rotation.from_rotvec([0.01, -0.02, 0.03]).as_matrix()
REF = np.array([1.5, 0.8, 0.3])
T_R_B = make_pose(Rotation.from_rotvec([0.02, -0.01, 0.7]).as_matrix(), [1.2, 0.3, 0.4])


def noisy(rng, p):
    return p + rng.normal(0.0, NOISE, p.shape)


#: Tilts of the tool between touches: about 35 degrees about 8 axes.
TILTS = 0.6 * np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0.7, 0.7, 0],
                        [-0.7, 0.7, 0], [0.7, -0.7, 0], [-0.7, -0.7, 0]])


def flange(rng, n, tool_points):
    """Flange poses putting each tool point (in the flange) on PIVOT, noise on the touch."""
    down = Rotation.from_euler("y", 90, degrees=True)
    tilt = TILTS[np.arange(n) % 8] + rng.normal(0.0, 0.05, (n, 3))
    R = (Rotation.from_rotvec(tilt) * down).as_matrix()
    p = noisy(rng, np.broadcast_to(PIVOT, (n, 3))) - np.einsum("nij,nj->ni", R, tool_points)
    return np.array([make_pose(Ri, pi) for Ri, pi in zip(R, p)])


def tcp(n):
    def make(rng, prior):
        return tcp_mod.calibrate_tool(flange(rng, n, np.tile(TCP, (n, 1))), sigma=prior)
    return make


def tcp_abc(rng, prior):
    axis = TCP - np.outer([0.06, 0.1], R_TOOL[:, 0])
    plane = TCP + np.array([[0.02, 0.07], [0.05, 0.04]]) @ R_TOOL[:, :2].T
    return tcp_mod.calibrate_tool(flange(rng, 5, np.tile(TCP, (5, 1))), flange(rng, 2, axis),
                                  flange(rng, 2, plane), sigma=prior)


LOCAL = np.array([[0, 0, 0]] * 2 + [[0.3, 0, 0], [0.15, 0, 0], [0.1, 0.2, 0], [0.25, 0.1, 0]])
ROLES = ["origin", "origin", "x", "x", "xy", "xy"]


def frame_3point(rng, prior):
    return frame_mod.frame_3point(noisy(rng, transform_points(T_FRAME, LOCAL)), ROLES, prior)


NOMINAL = np.array([[0, 0, 0], [0.4, 0, 0], [0, 0.3, 0], [0.4, 0.3, 0.05], [0.2, 0.1, 0.2],
                    [0.1, 0.3, 0.1]])


def frame_npoint(rng, prior):
    return frame_mod.frame_npoint(noisy(rng, transform_points(T_FRAME, NOMINAL)), NOMINAL, prior)


def external_tcp(roles):
    local = np.array([{"tcp": [0, 0, 0], "x": [0.08, 0, 0], "xy": [0.03, 0.07, 0]}[r]
                      for r in roles], dtype=float)

    def make(rng, prior):
        return frame_mod.calibrate_external_tcp(noisy(rng, transform_points(T_FRAME, local)), roles, prior)
    return make


E = np.linspace(0.0, 2.0, 6)


def track(rng, prior):
    return track_mod.calibrate_track(E, noisy(rng, (REF - np.outer(E, [1, 0, 0])) @ Q),
                                     sigma=prior)


REF2 = np.array([2.1, -0.6, 0.1])


def track_references(rng, prior):
    """Two known points, alternately touched: rotation, scale and carriage offset."""
    k = np.arange(len(E)) % 2
    r = np.array([REF, REF2])[k]
    return track_mod.calibrate_track(E, noisy(rng, (r - np.outer(E, [1, 0, 0])) @ Q),
                                     references=[REF, REF2], point=k, sigma=prior)


THETA = np.radians([0.0, 60.0, 130.0, 200.0, 270.0, 320.0])


def turntable(rng, prior):
    f = transform_points(T_R_B, np.einsum("nij,j->ni", rot_z(THETA), [0.3, 0, 0]))
    return turntable_mod.calibrate_turntable(THETA, noisy(rng, f), sigma=prior)


def workpiece(rng, prior):
    T_B_W = make_pose(Rotation.from_euler("z", 0.5).as_matrix(), [0.05, -0.08, 0.06])
    on_table = transform_points(T_B_W, LOCAL[[0, 2, 4, 1, 3, 5]])
    roles = ["origin", "x", "xy"] * 2
    theta = np.radians([10.0, 100.0, 200.0, 250.0, 310.0, 35.0])
    f = transform_points(T_R_B, np.einsum("nij,nj->ni", rot_z(theta), on_table))
    return workpiece_mod.calibrate_workpiece(theta, noisy(rng, f), roles, T_R_B,
                                             sigma=prior)


PROCEDURES = {
    "tcp-4": (tcp_mod, tcp(4)),
    "tcp-8": (tcp_mod, tcp(8)),
    "tcp-abc-2point": (tcp_mod, tcp_abc),
    "external-tcp": (frame_mod, external_tcp(["tcp"] * 4)),
    "external-tcp-oriented": (frame_mod, external_tcp(["tcp"] * 4 + ["x", "xy"])),
    "frame-3point": (frame_mod, frame_3point),
    "frame-npoint": (frame_mod, frame_npoint),
    "track": (track_mod, track),
    "track-references": (track_mod, track_references),
    "turntable": (turntable_mod, turntable),
    "workpiece": (frame_mod, workpiece),
}


def captured_fit(monkeypatch, module, make, rng, prior):
    """Run one real calibration and return the least-squares fit it made."""
    fits = []
    real = module.fit

    def spy(*args, **kwargs):
        fits.append(real(*args, **kwargs))
        return fits[-1]

    monkeypatch.setattr(module, "fit", spy)
    make(rng, prior)
    monkeypatch.setattr(module, "fit", real)
    return fits[-1]


@pytest.mark.parametrize("name", list(PROCEDURES))
def test_false_alarm_rate_per_touch(name, monkeypatch):
    module, make = PROCEDURES[name]
    prior = NOISE
    rng = np.random.default_rng(2 * list(PROCEDURES).index(name))
    # 1. Linearised fit at the procedure's Jacobian, many touches.
    res = captured_fit(monkeypatch, module, make, rng, prior)
    J = res.jacobian
    n = len(res.residuals)
    trials = max(60_000 // n, 1)
    U = np.linalg.svd(J, full_matrices=False)[0]
    e = np.einsum("nij,tnj->tni", res.measured, rng.normal(0.0, NOISE, (trials, n, 3)))
    e = e.reshape(trials, -1)
    r = (e - (e @ U) @ U.T).reshape(trials, n, 3)
    p = touch_statistics(J, r, prior, measured=res.measured)[0]
    testable = np.isfinite(p)
    # A touch that alone fixes a direction (the single x and xy touches of an oriented external
    # TCP) is absorbed by the fit and cannot be tested; most touches of every design can.
    assert testable.mean() >= 0.6
    rate = np.mean(p[testable] < RATE)
    assert RATE / 1.5 < rate < RATE * 1.5, (name, rate)
    # 2. The full procedure, counting the warnings it prints.
    flagged = touches = 0
    while touches < 1000:
        result = make(rng, prior)
        flagged += sum("is an outlier at 3 sigma" in w for w in result.warnings)
        touches += len(result.residuals)
    assert flagged <= binom.ppf(0.999, touches, 1.5 * RATE), (name, flagged, touches)
