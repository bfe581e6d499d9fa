"""``robotcell report`` checks the result it renders as strictly as ``calibrate`` checks what it
writes: a known procedure, finite numbers, lengths a calibration can measure, and a ``matrix``
that is a rigid transform. Anything else exits with status 2 naming the field, and writes no
page (before, a matrix scaled by 2 or an unknown procedure was rendered with "verdict good", and
1e308 in ``matrix`` ended in an unexpected exit).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from cli_helpers import run

from robotcell.calibration.turntable import calibrate_turntable
from robotcell.kinematics.transforms import check_pose, rot_z


@pytest.fixture(scope="module")
def result() -> dict:
    rng = np.random.default_rng(4)
    theta = np.radians([0.0, 60.0, 130.0, 200.0, 270.0, 320.0])
    p = (rot_z(theta) @ [0.3, 0.0, 0.05]) + [2.0, 0.9, 0.2] + rng.normal(0, 5e-5, (6, 3))
    return calibrate_turntable(theta, p).to_json()


def _changed(data: dict, key: str, value: object) -> dict:
    out = json.loads(json.dumps(data))
    if key == "matrix-scaled":
        m = np.array(out["matrix"])
        m[:3, :3] *= 2.0
        out["matrix"] = m.tolist()
    elif key == "matrix-translation":
        out["matrix"][1][3] = value
    else:
        out[key] = value
    return out


@pytest.mark.parametrize("key, value, match", [
    ("matrix-scaled", None, ("'matrix' is not a rigid transform (R orthonormal, det R = 1): "
                            "rotation part is not orthonormal")),
    ("matrix-translation", 1e308, "'matrix' holds a translation beyond 1e+15 mm"),
    ("procedure", "tool-magic", "'procedure' 'tool-magic' is none robotcell calibrates"),
    ("radius_mm", float("nan"), "'radius_mm' is not a finite number"),
    ("sigma", {"T_R_B_position_mm": [0.1, float("inf"), 0.1]},
     "'sigma.T_R_B_position_mm[1]' is not a finite number"),
    ("tilt_deg", 10 ** 400, "'tilt_deg' is not a finite number"),
    ("rms_mm", 1e300, "'rms_mm' holds a length beyond 1e+15 mm"),
    ("rotation", [[1, 0, 0], [0, 1, 0], [0, 0, -1]],
     ("'rotation' is not a proper rotation (orthonormal, det = 1): rotation part has determinant "
     "-1")),
])
def test_a_result_calibrate_would_not_write_is_refused(tmp_path, capsys, result, key, value,
                                                       match):
    path = tmp_path / "r.json"
    path.write_text(json.dumps(_changed(result, key, value)))
    code, out, err = run(capsys, "report", path, "-o", tmp_path / "r.html")
    assert code == 2 and out == ""
    assert f"error: {path}: not a calibration result: {match}" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json"]


def test_the_unchanged_result_is_rendered(tmp_path, capsys, result):
    path = tmp_path / "r.json"
    path.write_text(json.dumps(result))
    code, out, err = run(capsys, "report", path, "-o", tmp_path / "r.html")
    assert code == 0 and out.startswith("GOOD"), err
    assert (tmp_path / "r.html").stat().st_size > 1000


def test_check_pose_refuses_absurd_entries_without_a_warning():
    ok, reasons = check_pose(np.full((4, 4), 1e300))
    assert not ok and "last row" in reasons[0]
    T = np.eye(4)
    T[:3, :3] = 1e300
    ok, reasons = check_pose(T)
    assert not ok and "not orthonormal" in reasons[0]
