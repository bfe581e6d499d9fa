"""Touch-based 2-axis positioner calibration on the identification engine."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from identification_helpers import perturbed

from robotcell.errors import InputError
from robotcell.identification.chain import Chain
from robotcell.identification.positioner import _geometry, calibrate_positioner
from robotcell.kinematics.transforms import make_pose, rot_y, rot_z
from robotcell.robot.robot import Joint, Robot

NOISE = 0.05e-3
#: A tilt-rotate positioner: tilt about a horizontal axis, the table 250 mm along the rotate axis.
NOMINAL = Robot(
    name="positioner", convention="standard",
    joints=(Joint("revolute", a=0.0, alpha=-math.pi / 2, d=0.0, name="tilt"),
            Joint("revolute", a=0.0, alpha=0.0, d=0.25, name="rotate")),
    base=make_pose(rot_y(math.pi / 2), [0.0, 0.0, 0.0]),
)
GRID = np.radians([[t, r] for t in (-30.0, 0.0, 30.0, 60.0) for r in (0.0, 90.0, 180.0, 270.0)])


def _truth(rng):
    root = make_pose(rot_z(math.radians(20.0)) @ rot_y(math.pi / 2), [1.5, 0.3, 0.7])
    ch = Chain(perturbed(NOMINAL, rng), 1, False, root, np.eye(4))
    x = ch.values.copy()
    x[ch.target_params[0]] = [0.3, 0.05, 0.0]
    return ch, x


def test_positioner_geometry_and_robot():
    rng = np.random.default_rng(31)
    ch, x = _truth(rng)
    f = ch.predict(x, GRID)[0][:, 0] + rng.normal(0, NOISE, (len(GRID), 3))
    for nominal in (NOMINAL, None):  # None: circle point analysis of the grid
        cal = calibrate_positioner(GRID, f, nominal=nominal, sigma=NOISE)
        # X_B: along -z_tilt x z_rotate as the nominal's DH writes it, else +.
        truth = _geometry(SimpleNamespace(_chain=ch), x, 1.0 if nominal is None else -1.0)
        v, s = cal.result.values, cal.result.sigma
        for key in ("normal_length", "axis_angle", "tilt_zero", "rotate_zero", "radius"):
            assert abs(v[key] - float(truth[key])) <= 4 * s[key], key
        assert np.allclose(v["tilt_axis"], truth["tilt_axis"], atol=4 * s["tilt_axis"].max())
        assert abs(math.degrees(v["axis_angle"]) - 90.0) < 0.5
        # The robot: base is the root pose in R, tool the reference point.
        p = cal.robot.fk(GRID)[:, :3, 3]
        assert np.sqrt(np.mean(np.sum((p - ch.predict(x, GRID)[0][:, 0]) ** 2, axis=1))) < 2 * NOISE
        assert cal.robot.n_joints == 2
        assert cal.result.procedure == "positioner-2axis"
        assert "T_R_B_position_mm" in cal.result.to_json()["sigma"]


def test_positioner_sigma_matches_monte_carlo():
    # Errors consistent with the reported 1-sigma within 25 %: the spread of (estimate - truth) /
    # sigma over seeded trials has a standard deviation between 0.75 and 1.25.
    rng = np.random.default_rng(32)
    ch, x = _truth(rng)
    clean = ch.predict(x, GRID)[0][:, 0]
    truth = _geometry(SimpleNamespace(_chain=ch), x, -1.0)
    keys = ("normal_length", "axis_angle", "tilt_zero", "rotate_zero", "radius")
    z = {k: [] for k in keys + ("tilt_axis_y", "origin_y")}
    for _ in range(120):
        cal = calibrate_positioner(GRID, clean + rng.normal(0, NOISE, clean.shape), nominal=NOMINAL,
                                   sigma=NOISE)
        v, s = cal.result.values, cal.result.sigma
        for k in keys:  # angles compared on the circle (the zero may lie near 180 deg)
            z[k].append(math.remainder(v[k] - float(truth[k]), 2 * math.pi) / s[k])
        z["tilt_axis_y"].append((v["tilt_axis"][1] - truth["tilt_axis"][1]) / s["tilt_axis"][1])
        z["origin_y"].append((v["T_R_B"][1, 3] - truth["origin"][1]) / s["T_R_B_position"][1])
    for k, vals in z.items():
        assert 0.75 <= np.std(vals) <= 1.25, (k, np.std(vals))


def test_positioner_refuses_bad_input():
    with pytest.raises(InputError, match=r"shape \(N, 2\)"):
        calibrate_positioner(np.zeros((4, 3)), np.zeros((4, 3)))
    bad = Robot(name="one", joints=(Joint("revolute"),))
    with pytest.raises(InputError, match="2-joint nominal"):
        calibrate_positioner(GRID, np.zeros((16, 3)), nominal=bad)
