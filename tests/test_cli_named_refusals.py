"""Inputs that ended in an unexplained exit ("error: unexpected ...", status 1) are refused with
status 2 and a message naming the option or value at fault (README, "Files and exit status").

Each case is one the fuzzing of the CLI found: a ``|``-separated CSV, absurd option values
(``--sigma 1e-300``, ``--accuracy 1e-300``, ``--j23-factor 1e308``, ``--seed -1``, ``--height
-1e300``, ``--noise 1e300``), a layouts file whose range ends are not numbers. Option ranges are
checked where the option is parsed.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import load_robot
from robotcell.cell import Cell
from robotcell.io.tables import write_csv
from robotcell.studies.simulate import simulate

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"
POSITIONER = ROOT / "examples" / "cell_kr16_positioner.yaml"


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("files")
    shutil.copy(EXAMPLE, d / "cell.yaml")
    shutil.copy(POSITIONER, d / "positioner.yaml")
    simulate(Cell.load(EXAMPLE), "tcp", seed=2, tool="pointer").write_csv(d / "tcp.csv")
    simulate(Cell.load(EXAMPLE), "turntable", seed=2, tool="pointer").write_csv(d / "table.csv")
    simulate(Cell.load(POSITIONER), "positioner", seed=2, tool="pointer").write_csv(d / "p.csv")
    (d / "bar.csv").write_text((d / "p.csv").read_text().replace(",", "|"))
    (d / "tab.csv").write_text((d / "p.csv").read_text().replace(",", "\t"))
    shutil.copy(ROOT / "examples" / "seam_part.csv", d / "seam.csv")
    (d / "layouts.yaml").write_text("robot:\n  y: {from: {}, to: 300, steps: 2}\n")
    robot = load_robot("kuka_kr16")
    q = np.random.default_rng(5).uniform([-60, -100, 40, -90, -60, -90],
                                         [60, -50, 110, 90, 60, 90], (30, 6))
    xyz = robot.fk(np.radians(q))[:, :3, 3] * 1e3
    write_csv(d / "tracker.csv", [f"a{i}" for i in range(1, 7)] + list("xyz"), np.hstack([q, xyz]))
    return d


CASES = [
    (["calibrate", "positioner", "bar.csv", "--cell", "positioner.yaml", "--tool", "pointer"],
     "bar.csv: the header is one column 'a1|a2|a3|a4|a5|a6|e1|e2', its names separated by '|'"),
    (["calibrate", "positioner", "tab.csv", "--cell", "positioner.yaml", "--tool", "pointer"],
     "its names separated by tabs"),
    (["calibrate", "tcp", "tcp.csv", "--cell", "cell.yaml", "--name", "pointer", "--sigma",
      "1e-300"], "--sigma must be a positive number of millimetres from 0.001"),
    (["calibrate", "turntable", "table.csv", "--cell", "cell.yaml", "--tool", "pointer",
      "--height", "-1e300"], "--height must be a number of millimetres within +-100000"),
    (["identify", "tracker.csv", "--robot", "kuka_kr16", "--accuracy", "1e-300"],
     "--sigma must be a positive number of mm from 0.0001 to 1000, got 1e-300"),
    (["identify", "tracker.csv", "--robot", "kuka_kr16", "--angle-accuracy", "1e300"],
     "--angle-sigma must be a positive number of deg from 0.0001 to 1000"),
    (["identify", "tracker.csv", "--robot", "kuka_kr16", "--j23-factor", "1e308"],
     "--j23-factor must be a finite number from -10 to 10"),
    (["identify", "--propose", "20", "--seed", "-1", "--robot", "kuka_kr16"],
     "Invalid value for '--seed': -1 is not in the range x>=0"),
    (["demo", "--seed", "-1", "-o", "demo"], "Invalid value for '--seed': -1 is not in the range"),
    (["sweep", "--cell", "cell.yaml", "--targets", "seam.csv", "--layouts", "layouts.yaml",
      "--frame", "part", "--tool", "torch", "--workers", "1"],
     "layouts.yaml: robot.y: from and to must be numbers, got [{}, 300]"),
    (["simulate", "frame", "--cell", "cell.yaml", "--tool", "pointer", "--frame", "fixture",
      "--noise", "1e300"], "--noise must be a number of millimetres >= 0, at most 1000"),
]


@pytest.mark.parametrize("args, match", CASES)
def test_named_refusal_instead_of_an_unexpected_exit(files, tmp_path, monkeypatch, capsys,
                                                     args, match):
    for f in files.iterdir():
        shutil.copy(f, tmp_path / f.name)
    monkeypatch.chdir(tmp_path)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    code, out, err = run(capsys, *args)
    assert code == 2 and "unexpected" not in err and "Traceback" not in out + err
    assert match in err and err.count("error:") == 1, err
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_csv_of_text_columns_only_names_the_missing_columns(tmp_path, capsys):
    path = tmp_path / "t.csv"
    path.write_text("remark,where\nfirst,table\nsecond,floor\n")
    code, _, err = run(capsys, "calibrate", "positioner", path, "--cell", POSITIONER, "--tool",
                       "pointer")
    assert code == 2 and "needs TCP positions as columns x, y, z" in err
