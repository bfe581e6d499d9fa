"""A calibration result read back from its JSON: ``CalibrationResult.from_json`` beside
``to_json``, the one reader of the report and of ``calibrate workpiece --turntable``."""

import json

import numpy as np
import pytest
from cli_helpers import run

from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.cell.calibrate import TurntablePose
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.kinematics.transforms import rot_z, transform_points

T_R_B = pose_from_vendor([2000, 900, 200, 90, 0.2, -0.1], "kuka")


def _turntable() -> CalibrationResult:
    rng = np.random.default_rng(11)
    theta = np.radians(np.arange(0.0, 360.0, 45.0))
    f = transform_points(T_R_B, rot_z(theta) @ [0.35, 0.0, 0.05])
    return calibrate_turntable(theta, f + rng.normal(0.0, 5e-5, f.shape), sigma=5e-5)


def test_to_json_from_json_round_trip():
    result = _turntable()
    data = json.loads(json.dumps(result.to_json()))
    back = CalibrationResult.from_json(data, "tt.json")
    assert json.dumps(back.to_json()) == json.dumps(data)
    # The quantities come back in SI, checked against the result itself, not its JSON.
    np.testing.assert_allclose(back.values["T_R_B"], result.values["T_R_B"], atol=1e-12)
    np.testing.assert_allclose(back.residuals, result.residuals, atol=1e-15)
    assert back.rms == pytest.approx(result.rms) and back.labels == result.labels
    np.testing.assert_allclose(back.sigma["T_R_B_position"], result.sigma["T_R_B_position"])
    assert back.noise_sigma == pytest.approx(result.noise_sigma)
    assert back.verdict.level == result.verdict.level
    # The turntable for a workpiece: the same pose and 1-sigma from the result and its JSON.
    given = TurntablePose.from_result(back, "tt.json")
    np.testing.assert_allclose(given.T[:3, :3], T_R_B[:3, :3], atol=1e-3)
    np.testing.assert_allclose(given.T, result.values["T_R_B"], atol=1e-12)
    sd = np.sqrt(np.diag(given.covariance))
    np.testing.assert_allclose(sd[:3], result.sigma["T_R_B_position"], rtol=1e-6)


def test_from_json_refuses_what_is_not_a_result():
    data = _turntable().to_json()
    with pytest.raises(InputError, match=r"x.json: not a workpiece result; pass the output of "
                                         r"CalibrationResult.to_json\(\)"):
        CalibrationResult.from_json(data, "x.json", "workpiece")
    with pytest.raises(InputError, match=r"x.json: not a calibration result \(missing rms_mm"):
        CalibrationResult.from_json({k: v for k, v in data.items() if k != "rms_mm"}, "x.json")
    bad = dict(data, T_R_B_covariance_mm_rad=[[1.0] * 6] * 5)
    with pytest.raises(InputError, match=r"'T_R_B_covariance_mm_rad' must be a 6x6 array of "
                                         r"finite numbers"):
        CalibrationResult.from_json(bad, "x.json")


def test_report_and_workpiece_read_a_result_alike(tmp_path, capsys):
    """One reader: a turntable JSON whose matrix is no rigid transform is refused by both
    commands with the same reason."""
    data = _turntable().to_json()
    data["matrix"][0][0] = 2.0
    tt = tmp_path / "tt.json"
    tt.write_text(json.dumps(data))
    wp = tmp_path / "wp.csv"
    wp.write_text("point,x,y,z,e1\norigin,2100,900,250,0\nx,2250,900,250,0\nxy,2100,1000,250,0\n")
    reason = "not a calibration result: 'matrix' is not a rigid transform"
    code, _, err = run(capsys, "report", tt, "-o", tmp_path / "r.html")
    assert code == 2 and reason in err
    code, _, err = run(capsys, "calibrate", "workpiece", wp, "--turntable", tt)
    assert code == 2 and reason in err
    assert "give the unchanged output of 'robotcell calibrate ... --json'" in err


def test_a_condition_number_written_as_null_reads_back_as_nan():
    """``to_json`` writes a number that is not finite as null; reading it back is no error."""
    data = json.loads(json.dumps(_turntable().to_json()))
    data["condition"] = None
    back = CalibrationResult.from_json(data, "tt.json")
    assert np.isnan(back.condition) and back.to_json()["condition"] is None


@pytest.mark.parametrize("matrix, match", [
    ([[2.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], "'turntable_matrix' is not a rigid"),
    ([[1, 2]], "'turntable_matrix' has the wrong type or size"),
])
def test_the_turntable_of_a_workpiece_result_is_checked_as_a_pose(matrix, match):
    data = {"procedure": "workpiece", "residuals_mm": [0.1], "rms_mm": 0.1, "max_mm": 0.1,
            "warnings": [], "turntable_matrix": matrix}
    with pytest.raises(InputError, match=match):
        CalibrationResult.from_json(data, "wp.json")
