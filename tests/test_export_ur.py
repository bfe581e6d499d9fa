"""The UR calibration file of an arm identified with axis scales (docs/export.md, "The UR
description's calibration file"): written without them, and the export says so."""

import math
import re
from dataclasses import replace

import numpy as np
from cli_helpers import run

from robotcell import load_robot, save_robot
from robotcell.export.ur import axis_scale, scale_left_out, ur_kinematics
from robotcell.kinematics.coupling import Coupling

SCALE = np.array([1.0, 1.0 + 3e-4, 1.0 - 2e-4, 1.0, 1.0, 1.0])


def _identified_ur5e(scale: np.ndarray | None):
    """A UR5e as identified: link constants off by up to 0.5 mm and 0.05 deg (the last link's
    held, as an identification does), Hayati's beta on the parallel axes, and axis scales as
    ``identify --scale`` writes them (a coupling)."""
    nominal = load_robot("ur5e")
    rng = np.random.default_rng(5)
    joints = tuple(replace(j, a=j.a + rng.uniform(-5e-4, 5e-4), d=j.d + rng.uniform(-5e-4, 5e-4),
                           alpha=j.alpha + math.radians(rng.uniform(-0.05, 0.05)),
                           beta=math.radians(rng.uniform(-0.05, 0.05)) if i in (1, 2) else 0.0)
                   if i < 5 else j for i, j in enumerate(nominal.joints))
    coupling = None if scale is None else Coupling(np.diag(scale))
    return replace(nominal, name="ur5e_identified", joints=joints, coupling=coupling,
                   ik_seed=nominal)


def _export(tmp_path, capsys, arm):
    save_robot(arm, tmp_path / "arm.yaml")
    (tmp_path / "cell.yaml").write_text("name: ur_cell\nrobot:\n  model: ur5e\n"
                                        "  identified: arm.yaml\n")
    return run(capsys, "export", "--cell", tmp_path / "cell.yaml", "--format", "urdf", "-o",
               tmp_path / "ur.urdf")


def test_an_arm_identified_with_scales_gets_the_file_of_its_geometry_and_a_warning(tmp_path,
                                                                                 capsys):
    arm = _identified_ur5e(SCALE)
    code, _out, err = _export(tmp_path, capsys, arm)
    assert code == 0, err
    assert "wrote " + str(tmp_path / "ur_kinematics.yaml") in err
    text = (tmp_path / "ur_kinematics.yaml").read_text()
    arm = load_robot(tmp_path / "arm.yaml")  # as the cell reads it
    assert text == ur_kinematics(replace(arm, coupling=None))  # the geometry, without the scales
    warning = next(line for line in err.splitlines() if line.startswith("warning: "))
    assert ("the UR calibration file cannot hold the identified arm's axis scales (axis 2 "
            "x1.000300, axis 3 x0.999800; identify --scale)") in warning
    assert "identify without --scale" in warning
    # the distance it states is the one between the two arms
    worst = float(re.search(r"up to ([0-9.]+) mm", warning).group(1))
    q = np.random.default_rng(1).uniform(arm.lower, arm.upper, (500, 6))
    d = np.linalg.norm(arm.fk(q)[:, :3, 3] - replace(arm, coupling=None).fk(q)[:, :3, 3], axis=-1)
    assert 0.5 * worst < d.max() * 1e3 <= 1.05 * worst
    assert worst > 1.0  # 3e-4 of up to 360 deg of axis 2 at 0.8 m reach: not a rounding


def test_an_arm_without_scales_gets_no_warning(tmp_path, capsys):
    code, _out, err = _export(tmp_path, capsys, _identified_ur5e(None))
    assert code == 0 and "warning" not in err, err
    assert (tmp_path / "ur_kinematics.yaml").exists()


def test_only_a_coupling_that_scales_axes_is_a_scale():
    arm = _identified_ur5e(SCALE)
    assert np.array_equal(axis_scale(arm), SCALE)
    assert axis_scale(_identified_ur5e(None)) is None and scale_left_out(arm.ik_seed) is None
    C = np.diag(SCALE)
    C[2, 1] = 1.0
    assert axis_scale(replace(arm, coupling=Coupling(C))) is None
