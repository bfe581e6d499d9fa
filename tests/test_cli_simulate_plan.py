"""robotcell simulate | plan | demo through the CLI entry point: files, progress, refusals."""

import csv
import io
import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"


def rows(text):
    return list(csv.DictReader(io.StringIO(text)))


def test_simulate_to_stdout_and_file(tmp_path, capsys):
    code, out, err = run(capsys, "simulate", "turntable", "--cell", EXAMPLE, "--tool", "torch",
                         "--seed", "3", "--touches", "5", "--radius", "250")
    assert code == 0, err
    table = rows(out)
    assert len(table) == 5 and set(table[0]) == {"a1", "a2", "a3", "a4", "a5", "a6", "e1", "track"}
    assert "robotcell calibrate turntable FILE.csv" in err and "--height=-50" in err
    path = tmp_path / "t.csv"
    code, out2, err = run(capsys, "simulate", "turntable", "--cell", EXAMPLE, "--tool", "torch",
                          "--seed", "3", "--touches", "5", "--radius", "250", "-o", path)
    assert code == 0 and out2 == ""
    assert path.read_text() == out  # same seed, same file


def test_simulate_noise_changes_the_joints(capsys):
    def joints(noise, seed):
        code, out, _ = run(capsys, "simulate", "frame", "--cell", EXAMPLE, "--tool", "torch",
                           "--frame", "fixture", "--noise", noise, "--seed", seed)
        assert code == 0
        return np.array([[float(r[f"a{i}"]) for i in range(1, 7)] for r in rows(out)])

    exact = joints(0, 1)
    assert np.array_equal(exact, joints(0, 2))          # no noise: the seed does not matter
    assert not np.array_equal(joints(0.1, 1), exact)
    assert np.abs(joints(0.1, 1) - exact).max() < 0.5   # deg: a 0.1 mm touch-up error


@pytest.mark.parametrize("args, message", [
    (["simulate", "frame", "--tilt", "30"], r"--tilt does not apply to frame \(it is for tcp\)"),
    (["simulate", "tcp", "--frame", "fixture"], "--frame does not apply to tcp"),
    (["simulate", "tcp", "--noise", "-1"], "--noise must be a number of millimetres >= 0"),
    (["simulate", "tcp"], r"say which tool touches \(the cell has: pointer, torch\)"),
    (["simulate", "tcp", "--tool", "torch", "--point", "1,2"], "--point needs 3"),
    (["simulate", "track", "--tool", "torch", "--track", "100"],
     "the track procedure moves the track itself"),
    (["plan", "tcp", "--tool", "torch", "--noise", "0"], "--noise must be a positive number"),
    # a noise whose square underflows made the fit divide by zero (exit 1)
    (["plan", "tcp", "--tool", "torch", "--noise", "1e-300"],
     r"--noise must be a positive number of millimetres from 0\.001 \(1 um"),
    (["plan", "turntable", "--tool", "torch", "--max-size", "100"],
     "--max-size does not apply to turntable"),
    (["plan", "frame", "--tool", "torch", "--frame", "fixture", "--max-size", "10"],
     "--max-size 10 mm leaves no design; the smallest is 50 mm"),
    (["demo", "--noise", "0"], "--noise must be a positive number of millimetres"),
    (["demo", "--noise", "1e-300"], r"--noise must be a positive number of millimetres from 0\.001"),
])
def test_refusals(args, message, capsys):
    extra = [] if args[0] == "demo" else ["--cell", EXAMPLE]
    code, _, err = run(capsys, *args, *extra)
    assert code == 2
    assert re.search(message, err), err


def test_plan_table_best_design_monte_carlo_and_touches(tmp_path, capsys):
    path = tmp_path / "touches.csv"
    code, out, err = run(capsys, "plan", "tcp", "--cell", EXAMPLE, "--tool", "torch",
                         "--runs", "8", "--seed", "2", "-o", path)
    assert code == 0, err
    assert "<- best" in out and "best: tilt" in out
    assert ("predicted 1-sigma of the calibrated pose (relative to the flange, from its own "
            "touches only):") in out
    assert "Monte Carlo (8 simulated calibrations): RMS error" in out
    # Progress of both stages is shown on stderr.
    assert "predicting tcp designs" in err and "Monte Carlo, 8 runs" in err
    assert "robotcell calibrate tcp" in err
    touches = rows(path.read_text())
    assert len(touches) == 6 and [r["point"] for r in touches] == ["tcp"] * 4 + ["-x", "xy"]
