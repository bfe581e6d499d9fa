"""Calibrating into a cell from Python (``robotcell.cell.calibrate``) and its CLI caller.

The CLI's ``calibrate ... --cell`` and the library call on the same measurements write the same
cell file, byte for byte, and print the same JSON result.
"""

import json

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell, Frame, Provenance, cell_to_dict
from robotcell.cell import calibrate as cellcal
from robotcell.cli.terms import CLI_TERMS
from robotcell.errors import InputError, terms
from robotcell.io.tables import read_csv
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points
from robotcell.studies.demo import demo_cells
from robotcell.studies.simulate import simulate

STAMP = "2026-01-02T03:04:05+00:00"


@pytest.fixture
def fixed_time(monkeypatch):
    """Provenance.now stamps every calibration with the same time, so files compare byte-wise."""
    def now(cls, source, rms_mm=None, note=""):
        return cls(source=source, time=STAMP, rms_mm=rms_mm, note=note)

    monkeypatch.setattr(Provenance, "now", classmethod(now))


# procedure, CLI arguments besides the file, library keywords, simulation keywords
STEPS = [
    ("tcp", ["--name", "torch"], {"name": "torch"}, {"tool": "torch"}),
    ("track", ["--tool", "torch"], {"tool": "torch"}, {"tool": "torch"}),
    ("turntable", ["--tool", "torch"], {"tool": "torch"}, {"tool": "torch"}),
    ("workpiece", ["--tool", "torch", "--name", "part"], {"tool": "torch", "name": "part"},
     {"tool": "torch", "frame": "part"}),
    ("frame", ["--tool", "torch", "--name", "fixture"], {"tool": "torch", "name": "fixture"},
     {"tool": "torch", "frame": "fixture"}),
]


def test_cli_cell_results_equal_the_library_call_byte_for_byte(tmp_path, capsys, fixed_time):
    truth, nominal = demo_cells()
    truth.frames["fixture"] = Frame(np.array(truth.frames["part"].pose), parent="world", number=2)
    nominal.update_frame("fixture", truth.frames["fixture"].pose, Provenance(), parent="world",
                         number=2)
    (tmp_path / "cli").mkdir()
    (tmp_path / "lib").mkdir()
    cli_file, lib_file = tmp_path / "cli" / "cell.yaml", tmp_path / "lib" / "cell.yaml"
    nominal.save(cli_file)
    nominal.save(lib_file)
    rng = np.random.default_rng(5)
    for procedure, args, lib_kw, sim_kw in STEPS:
        touches = simulate(truth, procedure, noise=1e-4, seed=rng, **sim_kw)
        csv = tmp_path / f"{procedure}.csv"
        touches.write_csv(csv)
        code, out, err = run(capsys, "calibrate", procedure, csv, "--cell", cli_file, "--json",
                             *args, *touches.options)
        assert code == 0, err
        before = Cell.load(lib_file)
        content = cell_to_dict(before)
        call = getattr(cellcal, procedure)
        with terms(CLI_TERMS):  # the library's messages in the command line's words
            got = call(before, read_csv(csv), source=str(csv), file=csv,
                       **lib_kw, **touches.keywords())
            got.cell.save(lib_file)
            assert cli_file.read_bytes() == lib_file.read_bytes(), procedure
            assert json.loads(out) == got.result.to_json(), procedure
        assert f"updated {cli_file}: {got.item}" in err
        assert all(note in err for note in (n.replace("cell 'demo_kr16_track_turntable'",
                                                       str(cli_file))
                                            for n in got.notes + got.update_notes))
        assert got.provenance.source == procedure and got.provenance.time == STAMP
        # the cell given is not changed: the result is a new cell
        assert got.cell is not before and cell_to_dict(before) == content
        assert cell_to_dict(got.cell) != content
    # independently of the library call: the cell the command wrote is the simulated truth
    cal = Cell.load(cli_file)
    assert np.linalg.norm(cal.tools["torch"].T_F_TCP[:3, 3] - truth.tools["torch"].T_F_TCP[:3, 3]) \
        < 1e-3
    for name in ("part", "fixture"):
        assert np.linalg.norm(cal.frame_pose(name)[:3, 3] - truth.frame_pose(name)[:3, 3]) < 2e-3
    kept = [sorted(p.name for p in (tmp_path / d).glob("cell.yaml.*.bak")) for d in ("cli", "lib")]
    assert kept[0] == kept[1] and kept[0]
    for name in kept[0]:
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "lib" / name).read_bytes()


def test_library_call_returns_a_new_cell_and_leaves_the_given_one(tmp_path):
    truth, nominal = demo_cells()
    touches = simulate(truth, "tcp", noise=1e-4, seed=2, tool="torch")
    old = nominal.tools["torch"].T_F_TCP.copy()
    got = cellcal.tcp(nominal, touches.to_table(), "torch", time=STAMP)
    assert np.array_equal(nominal.tools["torch"].T_F_TCP, old)
    assert nominal.tools["torch"].provenance.source == "nominal"
    tool = got.cell.tools["torch"]
    assert np.linalg.norm(tool.T_F_TCP[:3, 3] - truth.tools["torch"].T_F_TCP[:3, 3]) < 1e-3
    prov = tool.provenance
    assert (prov.source, prov.time, prov.rms_mm, prov.note) == (
        "tcp", STAMP, got.result.rms * 1e3, f"{len(touches.q)} touches from measurements")
    # A table, not a file: nothing to repeat it from; named by the item and the time.
    assert prov.measurements is None and prov.id == f"tools.torch {STAMP}"
    # Its uncertainty is recorded for the next steps, as the result reports it.
    cov = sum(f @ f.T for f in prov.sources.values())
    np.testing.assert_allclose(np.sqrt(np.diag(cov)), np.r_[got.result.sigma["tcp"], got.result.sigma[
        "T_F_TCP_rotation"]], rtol=1e-9)
    assert got.item == "tool 'torch'" and tool.number == 1 and tool.mass == 3.2


def test_library_without_a_name_or_a_cell_writes_nothing():
    truth, nominal = demo_cells()
    touches = simulate(truth, "turntable", noise=1e-4, seed=3, tool="torch")
    got = cellcal.turntable(nominal, touches.to_table(), tool="torch")
    assert got.cell is not None and "T_world_B" in got.result.values
    tcp = simulate(truth, "tcp", noise=1e-4, seed=3, tool="torch")
    plain = cellcal.tcp(None, {k: v for k, v in tcp.to_table().items()}, robot=nominal.robot)
    assert plain.cell is None and plain.item == "" and "T_F_TCP" in plain.result.values


def test_workpiece_takes_the_turntable_result_and_propagates_its_uncertainty():
    truth, nominal = demo_cells()
    rng = np.random.default_rng(4)
    tt = cellcal.turntable(nominal, simulate(truth, "turntable", noise=1e-4, seed=rng,
                                             tool="torch").to_table(), tool="torch",
                           height=-0.05, sigma=1e-4)
    wp_touches = simulate(truth, "workpiece", noise=1e-4, seed=rng, tool="torch", frame="part")
    with_tt = cellcal.workpiece(tt.cell, wp_touches.to_table(), "part", tool="torch",
                                turntable=tt.result, sigma=1e-4)
    from_cell = cellcal.workpiece(tt.cell, wp_touches.to_table(), "part", tool="torch",
                                  sigma=1e-4)
    cov = tt.result.estimates["T_world_B"].covariance
    T = tt.result.values["T_world_B"]

    def bare(T):  # the turntable as a pose and a covariance only, as its JSON file gives it
        return cellcal.workpiece(tt.cell, wp_touches.to_table(), "part", tool="torch",
                                 sigma=1e-4, turntable=cellcal.TurntablePose(T, cov, "world"))

    same, apart = bare(T), bare(T @ make_pose(np.eye(3), [1e-5, 0.0, 0.0]))
    # The cell records the turntable's uncertainty (sources shared with the torch included):
    # from the cell or from the result, the workpiece carries the same.
    assert not any("turntable" in n for n in with_tt.notes + from_cell.notes)
    s_with = np.linalg.norm(with_tt.result.sigma["T_B_W_position"])
    np.testing.assert_allclose(np.linalg.norm(from_cell.result.sigma["T_B_W_position"]), s_with,
                               rtol=1e-9)
    # A bare pose that is the cell's turntable is taken with the cell's sources.
    np.testing.assert_allclose(np.linalg.norm(same.result.sigma["T_B_W_position"]), s_with,
                               rtol=1e-9)
    # The torch's error moved the turntable and the workpiece touches alike, and largely
    # cancels in T_B_W: another turntable's covariance, taken as independent of the torch
    # (nothing says what it shares), gives the workpiece a larger uncertainty.
    assert any("differs from the one in" in n for n in apart.notes)
    assert np.linalg.norm(apart.result.sigma["T_B_W_position"]) > 1.5 * s_with
    assert with_tt.cell.frames["part"].parent == "turntable"


def test_library_errors_name_the_cause():
    truth, nominal = demo_cells()
    table = simulate(truth, "tcp", noise=1e-4, seed=2, tool="torch").to_table()
    with pytest.raises(InputError, match=r"measurements: column 'track' \(track position of each "
                                         r"touch\) needs a cell \(parameter cell\)"):
        cellcal.frame(None, {**table, "track": np.ones(len(table["a1"])) * 1000,
                             "point": ["origin"] * len(table["a1"])}, robot=nominal.robot)
    with pytest.raises(InputError, match=r"give a cell or a robot, not both"):
        cellcal.tcp(nominal, table, robot=nominal.robot)
    n = len(table["a1"])
    with pytest.raises(InputError, match=rf"the columns have different lengths \[1, {n}\]"):
        cellcal.tcp(nominal, {**table, "point": ["tcp"]})
    with pytest.raises(InputError, match=r"tool 'torch' names a tool of a cell, but no cell"):
        cellcal.frame(None, table, tool="torch", robot=nominal.robot)
    bare = Cell(robot=nominal.robot, robot_model="kuka_kr16")
    with pytest.raises(InputError, match=r"cell 'cell' has no turntable; add a 'turntable'"):
        cellcal.turntable(bare, table)
    with pytest.raises(InputError, match=r"cell 'cell' has no track to calibrate"):
        cellcal.track(bare, table, roll="zero")


def test_joint_value_touches_in_a_cell_with_tools_need_the_tool_said():
    """Without --tool the touches would be the flange's: refused, not a 'poor' fit to a bad cell."""
    truth, nominal = demo_cells()
    table = simulate(truth, "turntable", noise=1e-4, seed=3, tool="torch").to_table()
    with pytest.raises(InputError, match=r"touches given as joint values: say which tool "
                                         r"touched, tool=NAME \(the cell has: torch\), or "
                                         r"tool=numpy.eye\(4\) for the bare flange"):
        cellcal.turntable(nominal, table)
    flange = cellcal.turntable(nominal, table, tool=np.eye(4))  # said: the bare flange
    assert flange.result.verdict.level == "poor"  # and the flange did not touch: the fit says so


def test_notes_reach_on_note_before_a_refusal():
    truth, nominal = demo_cells()
    table = simulate(truth, "tcp", noise=1e-4, seed=2, tool="torch").to_table()
    rows = [0, 0, 1]  # a copied line: two of the three orientations are the same
    short = {k: (np.asarray(v)[rows] if isinstance(v, np.ndarray) else [v[i] for i in rows])
             for k, v in table.items()}
    seen = []
    with pytest.raises(InputError, match=r"flange orientations of the touches are too similar"):
        cellcal.tcp(nominal, short, "torch", on_note=seen.append)
    assert len(seen) == 1 and seen[0].startswith("note: measurements: line 2, line 3 are "
                                                 "identical")


def test_library_messages_name_parameters_and_the_command_line_its_options(tmp_path, capsys):
    """The same refusal names the Python parameter from the library and the option from the
    command line."""
    truth, nominal = demo_cells()
    touches = simulate(truth, "track", noise=1e-4, seed=6, tool="torch")
    table = touches.to_table()
    table["point"] = np.ones(len(table["e1"]))
    lib = r"column 'point' names reference points, but no references was given"
    with pytest.raises(InputError, match=lib):
        cellcal.track(None, table, robot=nominal.robot, tool=nominal.tools["torch"].T_F_TCP)
    with terms(CLI_TERMS), pytest.raises(InputError, match=lib.replace("references", "--reference")):
        cellcal.track(None, table, robot=nominal.robot, tool=nominal.tools["torch"].T_F_TCP)
    del table["point"]
    result = cellcal.track(None, table, robot=nominal.robot, roll="zero",
                           tool=nominal.tools["torch"].T_F_TCP, sigma=1e-4).result
    assert "(references)" in result.next_step and "--" not in result.next_step
    assert "as given (sigma)" in result.summary()
    csv = tmp_path / "track.csv"
    touches.write_csv(csv)
    code, _, err = run(capsys, "calibrate", "track", csv, "--robot", "kuka_kr16", "--roll",
                       "zero")
    assert code == 2 and lib.replace("references", "--reference") in err


def test_external_tcp_is_a_cell_calibration_call():
    """A fixed TCP from touches of a robot-held pointer: the truth recovered, as the command."""
    rng = np.random.default_rng(7)
    T_R_X = make_pose(rot_z(0.4), [1.2, -0.3, 0.6])
    local = np.array([[0, 0, 0]] * 4 + [[0.08, 0, 0], [0.03, 0.07, 0]])
    p = transform_points(T_R_X, local) * 1e3 + rng.normal(scale=0.02, size=(6, 3))
    table = {"x": p[:, 0], "y": p[:, 1], "z": p[:, 2], "point": ["tcp"] * 4 + ["x", "xy"]}
    out = cellcal.external_tcp(None, table, sigma=2e-5)
    np.testing.assert_allclose(out.result.values["T_R_TCP"], T_R_X, atol=2e-3)
    assert out.cell is None and out.value == "T_R_TCP"
    with pytest.raises(InputError, match=r"measurements: column 'track' \(track position of each "
                                         r"touch\) is not used by the external-tcp calibration"):
        cellcal.external_tcp(None, {**table, "track": np.zeros(6)})
