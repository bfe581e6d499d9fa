"""Reachability map: library and ``robotcell reach``."""

import base64
import csv
import math
import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import InputError
from robotcell.cell import Cell
from robotcell.io.targets import read_targets
from robotcell.studies.reach import LIMIT_REF, manipulability_scale, reach_map

EXAMPLES = Path(__file__).parents[1] / "examples"
CELL = EXAMPLES / "cell_kr16_track_turntable.yaml"
SEAM = EXAMPLES / "seam_part.csv"


def test_reach_map_of_the_example_seam_reproduces_every_target():
    cell = Cell.load(CELL)
    T, table = (t := read_targets(SEAM)).poses, t.table
    rm = reach_map(cell, T, frame="part", tool="torch", table=table)
    assert rm.reachable.all()
    back = cell.fk(rm.q, track=rm.track, table=rm.table, tool="torch", frame="part")
    assert np.allclose(back, T, atol=1e-9)
    assert np.all(cell.robot.within_limits(rm.q))
    assert np.all((rm.track >= cell.track.lower) & (rm.track <= cell.track.upper))
    assert np.allclose(rm.track_margin, np.minimum(rm.track - cell.track.lower,
                                                   cell.track.upper - rm.track))
    gap = np.minimum(rm.q - cell.robot.lower, cell.robot.upper - rm.q).min(axis=1)
    assert np.allclose(rm.limit_margin, gap)
    det = np.abs(np.linalg.det(cell.robot.jacobian(rm.q, tool=cell.tools["torch"].T_F_TCP)))
    assert np.allclose(rm.manipulability, det)
    expect = (np.minimum(1, det / manipulability_scale(cell.robot))
              * np.minimum(1, gap / LIMIT_REF))
    assert np.allclose(rm.score, expect)
    assert np.all((rm.score > 0) & (rm.score <= 1))


def test_unreachable_targets_score_zero_and_have_no_axis_values():
    cell = Cell.load(CELL)
    T = np.tile(np.eye(4), (3, 1, 1))
    T[:, :3, 3] = [[3.0, 0.0, 1.2], [3.0, 9.0, 1.0], [50.0, 0.0, 1.0]]  # reachable, beside, beyond
    rm = reach_map(cell, T, tool="torch")
    assert rm.reachable.tolist() == [True, False, False]
    assert np.all(np.isnan(rm.q[1:])) and np.all(rm.score[1:] == 0)
    assert rm.branch[1] == -1 and np.isnan(rm.track[1])
    assert rm.fraction == pytest.approx(1 / 3)
    # at a given track position only that one is tried
    rm = reach_map(cell, T[:1], tool="torch", track=0.0)
    assert not rm.reachable[0] and rm.track[0] == 0.0


def test_cli_writes_csv_and_a_self_contained_html_map(capsys, tmp_path):
    out = tmp_path / "reach.csv"
    code, _, err = run(capsys, "reach", "--cell", CELL, SEAM, "--frame", "part", "--tool",
                       "torch", "-o", out)
    assert code == 0, err
    assert "36 of 36 targets reachable" in err
    rows = list(csv.DictReader(out.read_text().splitlines()))
    assert len(rows) == 36
    # Columns keep their types: integers as integers, booleans as true/false.
    assert [r["target"] for r in rows[:3]] == ["0", "1", "2"]
    assert {r["reachable"] for r in rows} == {"true"} and rows[0]["branch"] in map(str, range(8))
    cell = Cell.load(CELL)
    T, table = (t := read_targets(SEAM)).poses, t.table
    rm = reach_map(cell, T, frame="part", tool="torch", table=table)
    assert float(rows[5]["track"]) == pytest.approx(rm.track[5] * 1e3, abs=1e-6)
    assert float(rows[5]["a2"]) == pytest.approx(math.degrees(rm.q[5, 1]), abs=1e-6)
    assert float(rows[5]["table"]) == pytest.approx(math.degrees(table[5]), abs=1e-6)
    # The axis columns are those of fk --cell: the map goes back to the targets.
    code, _, err = run(capsys, "fk", "--cell", CELL, "--input", out, "--frame", "part",
                       "--tool", "torch", "-o", tmp_path / "back.csv")
    assert code == 0, err
    back = list(csv.DictReader((tmp_path / "back.csv").read_text().splitlines()))
    seam = list(csv.DictReader(SEAM.read_text().splitlines()))
    for k in "xyz":  # fk writes X,Y,Z; the seam has x,y,z (mm)
        assert [float(b[k.upper()]) for b in back] == pytest.approx([float(t[k]) for t in seam],
                                                                    abs=1e-4)
    page = (tmp_path / "reach.html").read_text()
    assert "36 of 36 targets reachable" in page and "<img" in page
    png = base64.b64decode(re.search(r'data:image/png;base64,([^"]+)"', page).group(1))
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_cli_errors(capsys, tmp_path):
    bad = tmp_path / "t.csv"
    bad.write_text("x,y,z\n1,2,3\n")
    code, _, err = run(capsys, "reach", "--cell", CELL, bad)
    assert code == 2 and "missing column(s) a, b, c" in err
    typo = tmp_path / "typo.csv"
    typo.write_text(SEAM.read_text().replace("table", "tabel"))
    code, _, err = run(capsys, "reach", "--cell", CELL, typo, "--frame", "part", "--tool", "torch")
    assert code == 0 and "warning: " in err and "'tabel' (did you mean 'table'?)" in err
    code, _, err = run(capsys, "reach", "--cell", CELL, SEAM, "--frame", "part", "--track", "9000")
    assert code == 0 and "warning: track position 9000 mm is outside the track limits" in err
    code, _, err = run(capsys, "reach", "--cell", CELL, SEAM, "--frame", "robot")
    assert code == 2 and "moves with the track" in err
    with pytest.raises(InputError, match="unknown frame"):
        reach_map(Cell.load(CELL), np.eye(4)[None], frame="nowhere")


def test_chosen_table_angle_reaches_and_scores_at_least_as_well_as_zero(capsys, tmp_path):
    cell = Cell.load(CELL)
    rng = np.random.default_rng(5)
    q = rng.uniform(cell.robot.lower, cell.robot.upper, (40, 6)) * 0.7
    T = cell.fk(q, track=rng.uniform(1.5, 4.5, 40), table=rng.uniform(-3, 3, 40), tool="torch",
                frame="part")
    chosen = reach_map(cell, T, frame="part", tool="torch", table=None)
    at_zero = reach_map(cell, T, frame="part", tool="torch", table=0.0)
    assert chosen.reachable.sum() > at_zero.reachable.sum()
    assert np.all(chosen.score >= at_zero.score - 1e-12)  # 0 is one of the candidate angles
    ok = chosen.reachable
    back = cell.fk(chosen.q[ok], track=chosen.track[ok], table=chosen.table[ok], tool="torch",
                   frame="part")
    assert np.allclose(back, T[ok], atol=1e-9)
    deg = np.degrees(chosen.table)
    assert np.allclose(np.round(deg / 10) * 10, deg, atol=1e-9)  # one of the 36 candidates
    with pytest.raises(InputError, match="needs a turntable"):
        reach_map(Cell(robot=cell.robot, robot_model="kuka_kr16"), T[:1], table=None)
    code, _, err = run(capsys, "reach", "--cell", CELL, SEAM, "--frame", "part",
                       "--choose-table")
    assert code == 2 and "leave it out to --choose-table" in err


def test_progress_in_blocks_gives_the_same_map(capsys, tmp_path, monkeypatch):
    import robotcell.cli.progress as cli_progress
    from robotcell.studies import reach

    cell = Cell.load(CELL)
    T, table = (t := read_targets(SEAM)).poses, t.table
    whole = reach_map(cell, T, frame="part", tool="torch", table=table)
    monkeypatch.setattr(reach, "BLOCK", 10)
    calls = []
    blocks = reach_map(cell, T, frame="part", tool="torch", table=table,
                       progress=lambda d, n: calls.append((d, n)))
    assert calls == [(10, 36), (20, 36), (30, 36), (36, 36)]
    for name in ("reachable", "q", "track", "table", "score", "branch"):
        assert np.array_equal(getattr(blocks, name), getattr(whole, name), equal_nan=True)
    monkeypatch.setattr(cli_progress, "PROGRESS_AFTER", 0.0)
    code, _, err = run(capsys, "reach", "--cell", CELL, SEAM, "--frame", "part", "--tool",
                       "torch", "-o", tmp_path / "r.csv")
    # what it assumed, then the bar (plain text off a terminal)
    assert code == 0 and err.split("\n", 1)[1].startswith("targets")


def test_write_reach_map_is_the_reach_command_as_one_call(tmp_path, capsys):
    from robotcell.io.tables import read_csv
    from robotcell.report.reach import write_reach_map

    cell = Cell.load(CELL)
    T, table = (t := read_targets(SEAM)).poses, t.table
    rm = write_reach_map(cell, T, tmp_path / "lib.csv", tmp_path / "lib.html", frame="part",
                         tool="torch", table=table)
    cols = read_csv(tmp_path / "lib.csv")
    # the file holds the map: every target reached, and at its axis values the TCP is on it
    assert np.all(rm.reachable) and list(cols["reachable"]) == ["true"] * len(T)
    q = np.radians(np.column_stack([cols[f"a{i}"] for i in range(1, 7)]))
    back = cell.fk(q, cols["track"] * 1e-3, np.radians(cols["table"]), "torch", "part")
    assert np.abs(back[:, :3, 3] - T[:, :3, 3]).max() < 1e-7  # the file has 1e-6 deg, mm
    assert (tmp_path / "lib.html").read_text().startswith("<!DOCTYPE html>")
    code, _, err = run(capsys, "reach", "--cell", CELL, SEAM, "--frame", "part", "--tool",
                       "torch", "-o", tmp_path / "cli.csv")
    assert code == 0, err
    assert (tmp_path / "cli.csv").read_bytes() == (tmp_path / "lib.csv").read_bytes()
