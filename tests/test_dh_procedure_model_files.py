"""Every writer of model files writes constants of the robot's own size: no length beyond 100 m.

A DH model of nearly parallel axes may put a common normal kilometres away, with ``d`` values
that cancel until the file's rounding leaves millimetres (docs/dh-procedure.md). The writers:
``robotcell dh from-urdf`` and ``dh convert`` (model files), ``robotcell identify -o`` with a
nominal model and without one (the start model then comes from the DH procedure), the cell file
(``Cell.save``, which ``robotcell calibrate`` uses; a positioner's DH axes live in it),
:func:`robotcell.save_robot`, and ``robotcell export --format urdf`` (the URDF, and a Universal
Robots arm's calibration file). Each file is read back and its largest number outside the
statistics is at most 1e5 (mm; angles in degrees are below it); the model files also move like
what they were written from.
"""

import math
import re
import shutil
from dataclasses import replace
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from identification_helpers import (
    configurations,
    measure,
    one_joint_rows,
    perturbed,
    truth_chain,
    write_csv,
)
from model_file_helpers import largest_number, read

import robotcell as rc
from robotcell.cell import Cell

ROOT = Path(__file__).resolve().parent.parent
URDF_DIR = resources.files("robotcell") / "robots" / "urdf"
LIMIT = 1e5  # mm: 100 m, the size of any real cell
EXACT = 1e-9


def moves_alike(a: rc.Robot, b: rc.Robot) -> bool:
    q = np.random.default_rng(3).uniform(-2, 2, (30, a.n_joints))
    return bool(np.abs(a.fk(q) - b.fk(q)).max() < EXACT)


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("name", ["ur5e.urdf", "kuka_kr6_r700_sixx.urdf"])
def test_dh_from_urdf(tmp_path, capsys, name, convention):
    out = tmp_path / "model.yaml"
    code, _, err = run(capsys, "dh", "from-urdf", URDF_DIR / name, "--convention", convention,
                       "-o", out)
    assert code == 0, err
    assert largest_number(read(out)) <= LIMIT
    # (random URDFs, nearly parallel axes among them: tests/test_dh_procedure_urdf_fuzz.py)


def test_dh_convert_and_save_robot_of_every_library_robot(tmp_path, capsys):
    for name in rc.list_robots():
        robot = rc.load_robot(name)
        target = "modified" if robot.convention == "standard" else "standard"
        out = tmp_path / f"{name}.yaml"
        code, _, err = run(capsys, "dh", "convert", name, "--to", target, "-o", out)
        assert code == 0, err
        assert largest_number(read(out)) <= LIMIT, name
        assert moves_alike(rc.load_robot(out), robot), name
        rc.save_robot(robot, out)
        assert largest_number(read(out)) <= LIMIT, name
        assert moves_alike(rc.load_robot(out), robot), name


def test_identify_with_a_nominal_model(tmp_path, capsys):
    rng = np.random.default_rng(21)
    nominal = rc.load_robot("kuka_kr16")  # parallel A2, A3: the identified model has a beta
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    write_csv(tmp_path / "tracker.csv", measure(ch, x, configurations(nominal, 40, rng), rng,
                                                0.02e-3))
    out = tmp_path / "identified.yaml"
    code, _, err = run(capsys, "identify", tmp_path / "tracker.csv", "--robot", "kuka_kr16",
                       "-o", out, "--accuracy", "0.02")
    assert code == 0, err
    data = read(out)
    assert largest_number(data) <= LIMIT
    assert any("beta" in j for j in data["joints"])


def test_identify_without_a_nominal_model_starts_from_the_dh_procedure(tmp_path, capsys):
    # PUMA 560: axes 2 and 3 parallel; the circle point analysis finds them a fraction of a
    # degree apart, and the DH procedure must not put their common normal kilometres away.
    rng = np.random.default_rng(22)
    nominal = rc.load_robot("puma560")
    ch, x = truth_chain(perturbed(nominal, rng), 1, False, rng)
    q = np.concatenate([one_joint_rows(nominal), configurations(nominal, 40, rng)])
    write_csv(tmp_path / "tracker.csv", measure(ch, x, q, rng, 0.02e-3))
    out = tmp_path / "arm.yaml"
    code, _, err = run(capsys, "identify", tmp_path / "tracker.csv", "-o", out, "--accuracy",
                       "0.02")
    assert code == 0, err
    assert largest_number(read(out)) <= LIMIT


def test_cell_files_as_saved_and_as_calibrate_writes_them(tmp_path, capsys):
    for example in ("cell_kr16_positioner.yaml", "cell_kr16_track_turntable.yaml"):
        Cell.load(ROOT / "examples" / example).save(tmp_path / example)
        assert largest_number(read(tmp_path / example)) <= LIMIT, example
    # calibrate positioner: the fitted DH axes of the positioner go into the cell file
    cell = tmp_path / "cell.yaml"
    shutil.copy(ROOT / "examples" / "cell_kr16_positioner.yaml", cell)
    csv = tmp_path / "touches.csv"
    code, _, err = run(capsys, "simulate", "positioner", "--cell", cell, "--noise", "0.05",
                       "--seed", "7", "--tool", "pointer", "-o", csv)
    assert code == 0, err
    code, _, err = run(capsys, "calibrate", "positioner", csv, "--cell", cell, "--tool",
                       "pointer", "--sigma", "0.05")
    assert code == 0, err
    assert "updated" in err and largest_number(read(cell)) <= LIMIT


def test_urdf_export_and_the_ur_calibration_file(tmp_path, capsys):
    nominal = rc.load_robot("ur5e")
    tilted = replace(nominal, ik_seed=nominal, joints=tuple(  # an identified UR5e: betas at
        replace(j, beta=math.radians(0.03) if i in (1, 2) else 0.0)  # its parallel axes
        for i, j in enumerate(nominal.joints)))
    rc.save_robot(tilted, tmp_path / "ur5e_identified.yaml")
    (tmp_path / "cell.yaml").write_text("name: ur_cell\nrobot:\n  model: ur5e\n"
                                        "  identified: ur5e_identified.yaml\n")
    code, _, err = run(capsys, "export", "--cell", tmp_path / "cell.yaml", "--format", "urdf",
                       "-o", tmp_path / "ur.urdf")
    assert code == 0, err
    assert largest_number(read(tmp_path / "ur_kinematics.yaml")) <= LIMIT * 1e-3  # metres
    xyz = re.findall(r'xyz="([^"]+)"', (tmp_path / "ur.urdf").read_text())
    assert xyz and max(abs(float(v)) for s in xyz for v in s.split()) <= LIMIT * 1e-3  # metres
