"""A real public measurement set: a UR10 measured with a laser tracker and a 6D probe.

examples/identification/ipa_ur10_random_poses.csv: 62 rows of Series_C of
github.com/christianlandgraf/ipa-robot-accuracy (MIT licence; Landgraf et al., IEEE CASE 2021),
see examples/identification/LICENSE-ipa-robot-accuracy.txt and docs/identification.md.
"""

import json
from pathlib import Path

from cli_helpers import run

from robotcell import load_robot
from robotcell.identification import cross_validate, read_measurements

DATA = Path(__file__).resolve().parents[1] / "examples" / "identification"


def test_ur10_laser_tracker_before_after_and_cross_validated(tmp_path, capsys):
    csv, model = DATA / "ipa_ur10_random_poses.csv", DATA / "ur10_cb3.yaml"
    out = tmp_path / "ur10_identified.yaml"
    code, stdout, stderr = run(capsys, "identify", csv, "--robot", model, "--accuracy", "0.5",
                               "--angle-accuracy", "0.02", "--folds", "5", "--json", "-o", out)
    assert code == 0, stderr
    data = json.loads(stdout)
    # Measured figures (mm): nominal 0.88 RMS, identified 0.50; held out 0.91 -> 0.55.
    assert 0.8 < data["rms_before_mm"] < 1.0
    assert data["rms_after_mm"] < 0.6 * data["rms_before_mm"]
    cv = data["cross_validation"]
    assert 0.8 < cv["before_rms_mm"] < 1.0 and cv["after_rms_mm"] < 0.65 * cv["before_rms_mm"]
    assert cv["after_mean_mm"] < 0.65 * cv["before_mean_mm"]
    assert data["verdict"] in ("good", "check")
    # The identified UR10 is no longer exactly a UR-type arm: its IK is seeded by the nominal's.
    robot = load_robot(out)
    meas = read_measurements(csv)
    T = robot.fk(meas.q[1:6])  # row 1 is the straight-up pose, a wrist singularity
    sol = robot.ik(T)
    assert sol.valid.any(axis=-1).all() and sol.method == "ur"


def test_ur10_library_cross_validation_matches_the_cli():
    nominal = load_robot(DATA / "ur10_cb3.yaml")
    meas = read_measurements(DATA / "ipa_ur10_random_poses.csv")
    assert meas.n_rows == 62 and meas.rotations is not None
    s = cross_validate(nominal, meas, folds=5, point_sigma=0.5e-3).stats()
    assert s["after_rms_mm"] < 0.65 * s["before_rms_mm"]
