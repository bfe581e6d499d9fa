"""``robotcell calibrate cell``: every calibrated item of a cell re-estimated in one fit from all the
touch files its calibrations recorded."""

import json
import shutil
from dataclasses import replace

import numpy as np
import pytest
from cli_helpers import run
from touch_helpers import pose_error

from robotcell.cell import Cell, Provenance
from robotcell.cell import calibrate as cellcal
from robotcell.errors import InputError
from robotcell.kinematics.transforms import make_pose
from robotcell.studies.simulate import simulate

NOISE = 1e-4
EXAMPLE = "examples/cell_kr16_track_turntable.yaml"
STAMP = "2026-01-02T03:04:05+00:00"
#: procedure, simulate keywords, calibrate-into-the-cell keywords
STEPS = [("tcp", {"tool": "pointer"}, {"name": "pointer"}),
         ("track", {"tool": "pointer"}, {"tool": "pointer"}),
         ("turntable", {"tool": "pointer"}, {"tool": "pointer"}),
         ("workpiece", {"tool": "pointer", "frame": "part"}, {"tool": "pointer", "name": "part"}),
         ("frame", {"tool": "pointer", "frame": "fixture"}, {"tool": "pointer", "name": "fixture"})]


@pytest.fixture
def fixed_time(monkeypatch):
    def now(cls, source, rms_mm=None, note="", **fields):
        return cls(source=source, time=STAMP, rms_mm=rms_mm, note=note, **fields)

    monkeypatch.setattr(Provenance, "now", classmethod(now))


def truth_items(cell):
    return {"tools.pointer": cell.tools["pointer"].T_F_TCP, "track": cell.track.T_L_R0,
            "turntable": cell.turntable.T_parent_B, "frames.part": cell.frames["part"].pose,
            "frames.fixture": cell.frames["fixture"].pose}


def chain_of_calibrations(tmp_path, truth, start, seed, steps=STEPS):
    """Every procedure simulated in ``truth`` and calibrated in turn into ``start``, from files."""
    rng = np.random.default_rng(seed)
    cell = start
    for procedure, sim, kw in steps:
        touches = simulate(truth, procedure, noise=NOISE, seed=rng, **sim)
        csv = tmp_path / f"{procedure}.csv"
        touches.write_csv(csv)
        cell = getattr(cellcal, procedure)(cell, str(csv), sigma=NOISE, **kw,
                                           **touches.keywords()).cell
    return cell


def test_whole_cell_is_within_3_sigma_and_never_less_certain_than_the_chain(tmp_path):
    """All procedures of the example cell, calibrated in turn with the touch accuracy stated,
    then fitted together: each quantity (origin and rotation of each item, 30 in all) within
    3 sigma of the truth, and every 1-sigma at most the chain's (the whole fit uses every touch
    for every item; it is the chain's own estimate where a touch says nothing more)."""
    truth = Cell.load(EXAMPLE)
    cell = chain_of_calibrations(tmp_path, truth, truth, seed=3)
    out = cellcal.calibrate_cell(cell)
    assert set(out.items) == set(truth_items(truth)) and out.iterations <= 5
    assert out.verdict.level != "poor" and len(out.steps) == 5
    for change in out.changes:
        z = pose_error(change.after, truth_items(truth)[change.key]) / change.sigma[:6]
        assert np.all(np.abs(z) < 3.0), (change.key, np.round(z, 2))
        # (to 1 %: the chain and the whole fit linearise at slightly different values)
        assert np.all(change.sigma <= change.sigma_before * 1.01), change.key
        written = out.cell  # the file gets the fitted values and their uncertainty
        prov = {"tools.pointer": written.tools["pointer"], "track": written.track,
                "turntable": written.turntable, "frames.part": written.frames["part"],
                "frames.fixture": written.frames["fixture"]}[change.key].provenance
        cov = sum(f @ f.T for f in prov.sources.values())
        np.testing.assert_allclose(np.sqrt(np.diag(cov)), change.sigma, rtol=1e-9)
    # The tool gains most: the track, turntable and frame touches were taken with it.
    tool = next(c for c in out.changes if c.key == "tools.pointer")
    assert np.linalg.norm(tool.sigma[:3]) < 0.8 * np.linalg.norm(tool.sigma_before[:3])
    # Fitted again, nothing moves.
    again = cellcal.calibrate_cell(out.cell)
    assert all(np.max(np.abs(c.change_sigmas)) < 1e-3 for c in again.changes)


def test_a_recalibrated_tool_moves_the_turntable_measured_with_it(tmp_path):
    """The track and the turntable were touched with a pointer whose drawing is 1.5 mm off; the
    pointer is then calibrated. Fitting the whole cell carries the correction to the track and
    the turntable: the turntable moves onto the truth, by about what the pointer moved."""
    truth = Cell.load(EXAMPLE)
    off = replace(truth, tools={**truth.tools, "pointer": replace(
        truth.tools["pointer"], T_F_TCP=truth.tools["pointer"].T_F_TCP
        @ make_pose(np.eye(3), [1.2e-3, -0.7e-3, 0.6e-3]))})
    steps = [STEPS[1], STEPS[2], STEPS[0]]  # track and turntable with the drawing's pointer
    cell = chain_of_calibrations(tmp_path, truth, off, seed=4, steps=steps)
    T_before = cell.turntable.T_parent_B
    assert np.linalg.norm(pose_error(T_before, truth.turntable.T_parent_B)[:3]) > 0.8e-3
    out = cellcal.calibrate_cell(cell)
    tt = next(c for c in out.changes if c.key == "turntable")
    assert np.linalg.norm(tt.change[:3]) > 0.8e-3 and np.max(np.abs(tt.change_sigmas)) > 3
    z = pose_error(tt.after, truth.turntable.T_parent_B) / tt.sigma[:6]
    assert np.all(np.abs(z) < 3.0), np.round(z, 2)
    np.testing.assert_allclose(out.cell.turntable.T_parent_B, tt.after, atol=1e-12)
    # About the turntable calibrated again with the fitted pointer and track, within its 1-sigma
    # (the whole fit also refines the pointer from the turntable's own touches).
    again = cellcal.turntable(out.cell, str(tmp_path / "turntable.csv"), tool="pointer",
                              sigma=NOISE, height=-0.05).result.values["T_world_B"]
    assert np.all(np.abs(pose_error(again, tt.after)) < tt.sigma[:6])


def test_missing_or_changed_touch_files_are_named(tmp_path, capsys):
    truth = Cell.load(EXAMPLE)
    cell = chain_of_calibrations(tmp_path, truth, truth, seed=5, steps=STEPS[:3])
    path = tmp_path / "cell.yaml"
    cell.save(path)
    (tmp_path / "track.csv").write_text((tmp_path / "track.csv").read_text() + "\n")
    (tmp_path / "turntable.csv").unlink()
    with pytest.raises(InputError, match=r"track: touch file .*track.csv has changed since the "
                                         r"calibration \(checksum differs\); turntable: touch "
                                         r"file .*turntable.csv is missing"):
        cellcal.calibrate_cell(Cell.load(path))
    before = path.read_bytes()
    code, _, err = run(capsys, "calibrate", "cell", "--cell", path)
    assert code == 2 and "track.csv has changed" in err and "turntable.csv is missing" in err
    assert path.read_bytes() == before
    code, _, err = run(capsys, "calibrate", "cell", "--cell", EXAMPLE)
    assert code == 2 and "records no calibration with its touch file" in err
    code, _, err = run(capsys, "calibrate", "cell")
    assert code == 2 and "needs --cell CELL.yaml" in err


def test_cli_writes_what_the_library_returns(tmp_path, capsys, fixed_time):
    truth = Cell.load(EXAMPLE)
    cell = chain_of_calibrations(tmp_path, truth, truth, seed=6, steps=STEPS[:3])
    cli_file, lib_file = tmp_path / "cli.yaml", tmp_path / "lib.yaml"
    cell.save(cli_file)
    shutil.copy(cli_file, lib_file)
    code, out, err = run(capsys, "calibrate", "cell", "--cell", cli_file, "--json")
    assert code == 0, err
    got = cellcal.calibrate_cell(Cell.load(lib_file))
    got.cell.save(lib_file)
    assert cli_file.read_bytes() == lib_file.read_bytes()
    j = json.loads(out)
    assert j == json.loads(json.dumps(got.to_json()))
    assert [i["item"] for i in j["items"]] == ["tools.pointer", "track", "turntable"]
    # independently of the library call: the items the command wrote are the simulated truth
    cal = Cell.load(cli_file)
    assert np.linalg.norm(cal.tools["pointer"].T_F_TCP[:3, 3]
                          - truth.tools["pointer"].T_F_TCP[:3, 3]) < 1e-3
    assert np.linalg.norm(cal.turntable.T_parent_B[:3, 3] - truth.turntable.T_parent_B[:3, 3]) \
        < 2e-3
    assert f"updated {cli_file}: 3 item(s) fitted with the whole cell" in err
    code, out, _ = run(capsys, "calibrate", "cell", "--cell", cli_file)
    assert code == 0 and "changes (|position| mm" in out and out.splitlines()[-1].startswith(
        "verdict: ")
    assert out.startswith("calibration: the whole cell, 3 calibrations fitted together (")


def test_summary_counts_one_calibration_in_the_singular(tmp_path):
    truth = Cell.load(EXAMPLE)
    cell = chain_of_calibrations(tmp_path, truth, truth, seed=8, steps=STEPS[:1])
    first = cellcal.calibrate_cell(cell).summary().splitlines()[0]
    assert first.startswith("calibration: the whole cell, 1 calibration fitted (")


def test_positioner_cell(tmp_path):
    """A positioner is fitted with the tool it was touched with; its chain keeps the nominal's
    conventions."""
    cell = Cell.load("examples/cell_kr16_positioner.yaml")
    steps = [("tcp", {"tool": "pointer"}, {"name": "pointer"}),
             ("positioner", {"tool": "pointer"}, {"tool": "pointer"})]
    got = chain_of_calibrations(tmp_path, cell, cell, seed=7, steps=steps)
    out = cellcal.calibrate_cell(got)
    assert out.items == ("tools.pointer",) and out.verdict.level != "poor"
    chain, nominal = out.cell.turntable.chain, cell.turntable.chain
    q = np.radians([[20.0, 45.0], [-30.0, 200.0]])
    np.testing.assert_allclose(chain.fk(q)[:, :3, 3], nominal.fk(q)[:, :3, 3], atol=1e-3)
    assert np.allclose([j.alpha for j in chain.joints], [j.alpha for j in nominal.joints],
                       atol=0.01)
