"""Layout sweep: the grid, moving components, ranking, and the same result on any executor."""

import math
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

import robotcell.cli.progress as cli_progress
from robotcell import InputError
from robotcell.cell import Cell
from robotcell.io.targets import read_targets
from robotcell.studies.reach import reach_map
from robotcell.studies.sweep import apply_layout, read_layouts, sweep

EXAMPLES = Path(__file__).parents[1] / "examples"
CELL = EXAMPLES / "cell_kr16_track_turntable.yaml"
SEAM = EXAMPLES / "seam_part.csv"
GRID = {"robot": {"y": [-600, 0, 300]}, "turntable": {"a": {"from": 0, "to": 90, "steps": 2}}}


def small_sweep(executor=None):
    cell = Cell.load(CELL)
    T, table = (t := read_targets(SEAM)).poses, t.table
    return sweep(cell, T[::3], read_layouts(GRID), frame="part", tool="torch", table=table[::3],
                 executor=executor)


def test_grid_is_every_combination_in_si_units():
    layouts = read_layouts(GRID)
    assert len(layouts) == 6
    assert layouts[1].values == {"robot.y": -600.0, "turntable.a": 90.0}
    assert layouts[1].offsets["robot"] == pytest.approx((0, -0.6, 0, 0, 0, 0))
    assert layouts[1].offsets["turntable"] == pytest.approx((0, 0, 0, math.pi / 2, 0, 0))
    assert layouts[1].label == "robot.y=-600 turntable.a=90"


def test_apply_layout_moves_components_and_leaves_the_cell_alone():
    cell = Cell.load(CELL)
    lay = read_layouts({"robot": {"y": [100]}, "turntable": {"a": [90]}, "part": {"z": [50]}})[0]
    new = apply_layout(cell, lay)
    assert np.allclose(new.track.T_world_L[:3, 3] - cell.track.T_world_L[:3, 3], [0, 0.1, 0])
    # a turns the table root about its own z: origin and axis stay
    B0, B1 = cell.turntable.T_parent_B, new.turntable.T_parent_B
    assert np.allclose(B1[:3, 3], B0[:3, 3]) and np.allclose(B1[:3, 2], B0[:3, 2])
    assert np.isclose(B1[:3, 0] @ B0[:3, 1], 1.0)
    assert np.allclose(new.frames["part"].pose[:3, 3] - cell.frames["part"].pose[:3, 3],
                       [0, 0, 0.05])
    assert np.allclose(cell.track.T_world_L, Cell.load(CELL).track.T_world_L)
    # the moved cell is what the reach map of that layout sees
    q = np.array([[0.2, -1.3, 1.5, 0.3, 0.8, 0.1]])
    T = new.fk(q, track=2.0, table=0.4, tool="torch", frame="part")
    assert reach_map(new, T, frame="part", tool="torch", table=0.4).reachable[0]


def test_ranking_prefers_the_layout_that_reaches_more():
    ranked = small_sweep()
    best = ranked[0]
    assert best.fraction == 1.0 and best.layout.values == {"robot.y": 300.0, "turntable.a": 0.0}
    assert ranked[1].fraction == 1.0 and ranked[1].mean_score < best.mean_score
    far = [r for r in ranked if r.layout.values["robot.y"] == -600.0]
    assert all(r.fraction == 0.0 and r.mean_score == 0.0 for r in far)  # 1.6 m further away
    assert ranked[-1].fraction == 0.0
    keys = [r.key for r in ranked]
    assert keys == sorted(keys)


def _same(a, b):
    return ([r.index for r in a] == [r.index for r in b]
            and [(r.fraction, r.mean_score, r.min_score) for r in a]
            == [(r.fraction, r.mean_score, r.min_score) for r in b])


def test_serial_process_pool_and_dask_give_the_same_ranking():
    serial = small_sweep()
    with ProcessPoolExecutor(2) as ex:
        assert _same(small_sweep(ex), serial)
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        assert _same(small_sweep(client.get_executor()), serial)


def test_layout_errors():
    with pytest.raises(InputError, match="unknown axis 'w'"):
        read_layouts({"robot": {"w": [1]}})
    with pytest.raises(InputError, match="exactly the keys from, to, steps"):
        read_layouts({"robot": {"x": {"from": 0, "to": 1}}})
    with pytest.raises(InputError, match="steps must be a whole number"):
        read_layouts({"robot": {"x": {"from": 0, "to": 1, "steps": 0}}})
    with pytest.raises(InputError, match="values must be numbers"):
        read_layouts({"robot": {"x": ["near"]}})
    with pytest.raises(InputError, match="expected a mapping of components"):
        read_layouts({})
    cell = Cell.load(CELL)
    with pytest.raises(InputError, match="moves 'gantry', which the cell does not have"):
        sweep(cell, np.eye(4)[None], read_layouts({"gantry": {"x": [0]}}))


def test_cli_ranks_writes_csv_and_shows_progress(capsys, tmp_path, monkeypatch):
    lay = tmp_path / "layouts.yaml"
    lay.write_text("robot:\n  y: [-600, 0, 300]\nturntable:\n  a: {from: 0, to: 90, steps: 2}\n")
    out = tmp_path / "rank.csv"
    monkeypatch.setattr(cli_progress, "PROGRESS_AFTER", 0.0)
    code, stdout, err = run(capsys, "sweep", "--cell", CELL, "--targets", SEAM, "--layouts", lay,
                            "--frame", "part", "--tool", "torch", "--workers", "1", "-o", out)
    assert code == 0, err
    assert "all 6 layouts, scored on 36 targets" in stdout
    assert "robot.y=300" in stdout.splitlines()[3]
    assert "layouts" in err  # the progress bar
    lines = out.read_text().splitlines()
    assert lines[0] == ("rank,layout,robot.y,turntable.a,reachable_fraction,mean_score,"
                        "min_score")
    assert len(lines) == 7 and lines[1].split(",")[0] == "1"  # ranks are integers
    assert sorted(int(line.split(",")[1]) for line in lines[1:]) == list(range(6))
    # The count printed is the count listed.
    code, stdout, err = run(capsys, "sweep", "--cell", CELL, "--targets", SEAM, "--layouts", lay,
                            "--frame", "part", "--tool", "torch", "--workers", "1", "--top", "4")
    assert code == 0, err
    head, *table = stdout.splitlines()
    assert head.startswith("the best 4 of 6 layouts (--top N lists more, -o FILE writes all)")
    assert len(table) == 2 + 4


def test_cli_errors(capsys, tmp_path, monkeypatch):
    lay = tmp_path / "layouts.yaml"
    lay.write_text("robot:\n  y: [0]\n")
    args = ["sweep", "--cell", CELL, "--targets", SEAM, "--layouts", lay, "--frame", "part"]
    code, _, err = run(capsys, *args, "--workers", "0")
    assert code == 2 and "--workers must be at least 1" in err
    monkeypatch.setitem(sys.modules, "distributed", None)
    code, _, err = run(capsys, *args, "--scheduler", "tcp://127.0.0.1:1")
    assert code == 2 and "pip install 'robotcell[dask]'" in err
    code, _, err = run(capsys, "sweep", "--cell", CELL, "--targets", SEAM, "--layouts",
                       tmp_path / "none.yaml")
    assert code == 2 and "does not exist" in err


def test_cli_runs_on_a_dask_scheduler_by_address(capsys, tmp_path):
    distributed = pytest.importorskip("distributed")
    lay = tmp_path / "layouts.yaml"
    lay.write_text("robot:\n  y: [-600, 0, 300]\nturntable:\n  a: {from: 0, to: 90, steps: 2}\n")
    args = ["sweep", "--cell", CELL, "--targets", SEAM, "--layouts", lay, "--frame", "part",
            "--tool", "torch"]
    code, serial, err = run(capsys, *args, "--workers", "1")
    assert code == 0, err
    with distributed.LocalCluster(n_workers=1, processes=False, dashboard_address=None) as c:
        code, remote, err = run(capsys, *args, "--scheduler", c.scheduler_address)
    assert code == 0, err
    assert remote == serial


def test_reach_and_sweep_with_a_two_axis_positioner(capsys, tmp_path):
    from test_positioner import tilt_rotate

    cell = tilt_rotate()
    rng = np.random.default_rng(8)
    q = rng.uniform(cell.robot.lower, cell.robot.upper, (30, 6)) * 0.6
    v = np.column_stack([rng.uniform(-0.5, 0.5, 30), rng.uniform(-3, 3, 30)])
    T = cell.fk(q, table=v, tool="torch", frame="part")
    rm = reach_map(cell, T, frame="part", tool="torch", table=v)
    assert rm.reachable.all() and rm.table.shape == (30, 2) and np.allclose(rm.table, v)
    back = cell.fk(rm.q, table=rm.table, tool="torch", frame="part")
    assert np.allclose(back, T, atol=1e-9)
    with pytest.raises(InputError, match="give a positioner's axis values"):
        reach_map(cell, T, frame="part", tool="torch", table=None)
    layouts = read_layouts({"turntable": {"x": [0, 2000], "c": [0, 20]}})
    moved = apply_layout(cell, layouts[3])
    assert np.allclose(moved.turntable.chain.base[:3, 3] - cell.turntable.chain.base[:3, 3],
                       [2.0, 0, 0])
    ranked = sweep(cell, T, layouts, frame="part", tool="torch", table=v)
    assert ranked[0].index == 0 and ranked[0].fraction == 1.0    # as built: every target
    assert all(r.fraction < 1.0 for r in ranked if r.layout.values["turntable.x"] == 2000)
    from robotcell.report.reach import reach_html
    page = reach_html(rm, T[:, :3, 3], frame="part")
    assert "30 of 30 targets reachable" in page


def test_reach_cli_reads_and_writes_a_positioners_axes_as_fk_does(capsys, tmp_path):
    """reach takes a positioner's values in columns e1..en (deg) and writes them back under the
    same names, with track/table/a1..an as fk --cell and ik --cell name them."""
    import csv

    from test_positioner import tilt_rotate

    from robotcell.io.poseformats import pose_to_vendor

    cell = tilt_rotate()
    path = tmp_path / "cell.yaml"
    cell.save(path)
    rng = np.random.default_rng(9)
    q = rng.uniform(cell.robot.lower, cell.robot.upper, (6, 6)) * 0.6
    v = np.column_stack([rng.uniform(-0.5, 0.5, 6), rng.uniform(-3, 3, 6)])
    T = cell.fk(q, table=v, tool="torch", frame="part")
    targets = tmp_path / "t.csv"
    rows = np.column_stack([pose_to_vendor(T, "kuka"), np.degrees(v)])
    targets.write_text("x,y,z,a,b,c,e1,e2\n" + "\n".join(",".join(f"{x:.9f}" for x in r)
                                                          for r in rows) + "\n")
    out = tmp_path / "reach.csv"
    code, _, err = run(capsys, "reach", "--cell", path, targets, "--frame", "part", "--tool",
                       "torch", "-o", out)
    assert code == 0, err
    got = list(csv.DictReader(out.read_text().splitlines()))
    assert list(got[0])[3:12] == ["track", "e1", "e2", "branch", "a1", "a2", "a3", "a4", "a5"]
    assert np.allclose([[float(r["e1"]), float(r["e2"])] for r in got], np.degrees(v), atol=1e-6)
    code, back, err = run(capsys, "fk", "--cell", path, "--input", out, "--frame", "part",
                          "--tool", "torch")
    assert code == 0, err
    xyz = np.array([[float(x) for x in line.split(",")[:3]] for line in back.splitlines()[1:]])
    assert np.allclose(xyz, T[:, :3, 3] * 1e3, atol=1e-4)
    targets.write_text(targets.read_text().replace("e1,e2", "table,e2"))
    code, _, err = run(capsys, "reach", "--cell", path, targets, "--frame", "part")
    assert code == 2 and "column 'table' holds a turntable angle" in err


def test_sweep_writes_its_ranking(tmp_path):
    from robotcell.io.tables import read_csv

    cell = Cell.load(CELL)
    T, table = (t := read_targets(SEAM)).poses, t.table
    layouts = read_layouts({"robot": {"y": [0, 300]}})
    ranked = sweep(cell, T[:6], layouts, frame="part", tool="torch", table=table[:6],
                   output=tmp_path / "rank.csv")
    cols = read_csv(tmp_path / "rank.csv")
    assert list(cols["rank"]) == [1, 2] and list(cols["layout"]) == [r.index for r in ranked]
    assert sorted(cols["robot.y"]) == [0.0, 300.0]
    assert np.allclose(cols["reachable_fraction"], [r.fraction for r in ranked])
    # independently of the sweep: the best layout's fraction is the reach map of the moved cell
    best = apply_layout(cell, ranked[0].layout)
    assert cols["reachable_fraction"][0] == pytest.approx(
        reach_map(best, T[:6], "part", "torch", table[:6]).fraction)
