"""``calibrate external-tcp --cell``: the robot and the reference tool come from the cell, the
tool's recorded uncertainty is part of the result's 1-sigma, and the cell file is not changed."""

from __future__ import annotations

import json

import numpy as np
from cli_helpers import run
from test_calibration_chain import NOISE, cells, external_touches
from touch_helpers import retouched

from robotcell.cell import calibrate as cellcal
from robotcell.io.poseformats import pose_to_vendor
from robotcell.studies.simulate import simulate


def _kuka(T):
    """X, Y, Z (mm), A, B, C (deg) of a pose."""
    return pose_to_vendor(T, "kuka")


def test_external_tcp_with_a_cell_carries_its_tools_error_and_writes_nothing(tmp_path, capsys):
    _, fixed = cells()
    rng = np.random.default_rng(3)
    tool = fixed.tools["pointer"].T_F_TCP
    design = simulate(fixed, "tcp", noise=0.0, tool="pointer")
    calibrated = cellcal.tcp(fixed, retouched(design, fixed, tool, rng, NOISE), "pointer",
                             sigma=NOISE).cell
    cell_file = tmp_path / "cell.yaml"
    calibrated.save(cell_file)
    before = cell_file.read_bytes()
    touches, _ = external_touches(fixed, rng)
    table = retouched(touches, fixed, tool, rng, NOISE)
    csv = tmp_path / "gun.csv"
    names = list(table)
    rows = zip(*(table[k] for k in names))
    csv.write_text(",".join(names) + "\n" + "\n".join(
        ",".join(str(v) if isinstance(v, str) else f"{float(v):.9f}" for v in r) for r in rows)
        + "\n", encoding="utf-8")

    code, out, err = run(capsys, "calibrate", "external-tcp", csv, "--cell", cell_file,
                         "--tool", "pointer", "--sigma", NOISE * 1e3, "--json")
    assert code == 0, err
    assert cell_file.read_bytes() == before
    got = json.loads(out)
    lib = cellcal.external_tcp(calibrated, csv, tool="pointer", sigma=NOISE)
    assert lib.inputs == ("tools.pointer",)
    assert np.allclose(got["sigma"]["T_R_TCP_position_mm"],
                       lib.result.sigma["T_R_TCP_position"] * 1e3, rtol=1e-6)
    # Without the cell, the same touches with the same tool as numbers: the touches' own part
    # only, smaller than with the recorded error of the tool.
    code, out, err = run(capsys, "calibrate", "external-tcp", csv, "--robot", "kuka_kr16",
                         "--tool", ",".join(f"{v:.9f}" for v in _kuka(tool)), "--sigma",
                         NOISE * 1e3, "--json")
    assert code == 0, err
    alone = np.array(json.loads(out)["sigma"]["T_R_TCP_position_mm"])
    assert np.all(np.array(got["sigma"]["T_R_TCP_position_mm"]) > alone)


def test_external_tcp_refuses_robot_beside_cell(tmp_path, capsys):
    _, fixed = cells()
    cell_file = tmp_path / "cell.yaml"
    fixed.save(cell_file)
    (tmp_path / "gun.csv").write_text("x,y,z\n1,2,3\n", encoding="utf-8")
    code, _, err = run(capsys, "calibrate", "external-tcp", tmp_path / "gun.csv", "--cell",
                       cell_file, "--robot", "kuka_kr16")
    assert code == 2 and "--robot and --cell both give the robot model" in err
