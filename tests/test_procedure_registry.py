"""The registry of calibration procedures: one descriptor each, the built-in ones and one added by
this file alone, which ``simulate`` and ``calibrate`` then run like the others."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import InputError
from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.resultcheck import malformed
from robotcell.calibration.spec import SPECS, TableSpec
from robotcell.cell import Cell
from robotcell.cell import calibrate as cellcal
from robotcell.cell.calibrate.common import Notes
from robotcell.cell.calibrate.simulation import DOWN, Touches, candidate_tracks, reach, tool_name
from robotcell.cell.calibrate.touches import read_touches, tool_transform
from robotcell.cell.kinematics import robot_pose, tool_pose
from robotcell.cli import calibrate as cli_calibrate
from robotcell.kinematics.transforms import make_pose, transform_points
from robotcell.studies.plan import DESIGNS
from robotcell.studies.simulate import PROCEDURES as SIMULATED
from robotcell.studies.simulate import simulate

CELL_FILE = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
NOISE = 1e-4

# -- a toy procedure: a fixed point in the robot base, touched several times -----------------------
POINT_R = np.array([1.1, 0.0, 0.3])
SPEC = TableSpec("toy-point", "tcp", minimum=3, counted="touches of the point")


def toy_calibrate(cell, measurements, *, context=None, **keywords):
    """The point: the mean of the touches (TCP positions in the robot base)."""
    ctx = cellcal.CalibrationContext.of(context, **keywords)
    notes = Notes(ctx.on_note)
    m = read_touches(SPEC, measurements, ctx.source, ctx.arm(cell), notes.one)
    m.check_count()
    p = m.tcp(tool_transform(cell, ctx.tool, m))
    centre = p.mean(axis=0)
    s = ctx.sigma or 5e-4
    n = len(p)
    result = CalibrationResult("toy-point", {"point": centre}, {"point": np.full(3, s / n**0.5)},
                               p - centre, 1.0, 3 * (n - 1), s, "prior", labels=m.labels(),
                               points=p, touch_sigma=s, accuracy_source="stated")
    return cellcal.CellCalibration(result, notes=tuple(notes), value="point")


def toy_simulate(cell, rng, noise, tool, track, touches=5):
    """The point touched ``touches`` times, the robot at one track position."""
    name = tool_name(cell, tool)

    def targets(E):
        return make_pose(DOWN[None, None], transform_points(robot_pose(cell, E), POINT_R)[:, :, None])

    q, _ = reach(cell, targets, candidate_tracks(cell, track, touches), tool_pose(cell, name),
                 [f"touch {i + 1}" for i in range(touches)], rng, noise)
    return Touches("toy-point", q, None, None, None, truth={"point": POINT_R}, tool=name,
                   noise=noise, track_column=False)


TOY = cellcal.Procedure("toy-point", "a fixed point in the robot base", SPEC, toy_calibrate,
                        simulate=toy_simulate)


@pytest.fixture
def toy():
    cellcal.register(TOY)
    yield TOY
    cellcal.unregister("toy-point")


# -- the built-in procedures -----------------------------------------------------------------------
def test_the_registry_holds_each_procedure_once_with_its_table():
    assert list(cellcal.PROCEDURES) == list(SPECS) == [
        "tcp", "frame", "external-tcp", "track", "turntable", "workpiece", "positioner"]
    for name, proc in cellcal.PROCEDURES.items():
        assert proc.spec is SPECS[name]
        assert all(cellcal.for_result(r) is proc for r in proc.results)
    assert cellcal.for_result("frame-npoint").name == "frame"
    assert cellcal.for_result("positioner-2axis").name == "positioner"
    assert cellcal.for_result("tool-magic") is None


def test_the_positioner_is_a_procedure_like_the_others():
    # what each command takes from the registry: calibrate cell repeats every procedure that
    # writes an item of the cell, the positioner's chain included; simulate and plan
    writes = [n for n, p in cellcal.PROCEDURES.items() if p.item]
    assert writes == ["tcp", "frame", "track", "turntable", "workpiece", "positioner"]
    assert list(cellcal.having(lambda p: p.repeat)) == writes
    assert list(SIMULATED) == writes
    assert list(DESIGNS) == ["tcp", "frame", "track", "turntable", "workpiece"]
    assert cellcal.procedure("positioner").calibrate is cellcal.positioner


def test_the_views_and_reports_register_what_they_draw():
    import robotcell.report.calibration
    import robotcell.view.calibration  # noqa: F401 - registers the scenes

    scenes = cellcal.having(lambda p: p.scene)
    assert list(scenes) == ["tcp", "track", "turntable", "positioner"]
    assert list(cellcal.having(lambda p: p.figure_frames)) == ["workpiece"]


def test_an_unknown_procedure_is_refused_naming_the_known_ones():
    with pytest.raises(InputError, match="unknown procedure 'laser'; choose from tcp, frame, "
                                         "external-tcp, track"):
        cellcal.procedure("laser")
    with pytest.raises(InputError, match="unknown procedure 'external-tcp'; choose from tcp, "
                                         "frame, track, turntable, workpiece, positioner$"):
        simulate(Cell.load(CELL_FILE), "external-tcp")


# -- the shared keywords ---------------------------------------------------------------------------
def test_the_shared_keywords_are_one_context_or_its_fields():
    cell = Cell.load(CELL_FILE)
    t = simulate(cell, "turntable", noise=NOISE, seed=3, tool="pointer")
    ctx = cellcal.CalibrationContext(tool="pointer", sigma=NOISE, time="2024-01-01T00:00:00")
    a = cellcal.turntable(cell, t.to_table(), height=0.02, context=ctx)
    b = cellcal.turntable(cell, t.to_table(), height=0.02, tool="pointer", sigma=NOISE,
                          time="2024-01-01T00:00:00")
    c = cellcal.turntable(cell, t.to_table(), height=0.02, context=ctx.of(ctx, tool="torch"),
                          tool="pointer")  # a keyword over the context
    for other in (b, c):
        np.testing.assert_array_equal(a.result.values["T_world_B"],
                                      other.result.values["T_world_B"])
        assert (a.provenance.id, a.provenance.options) == (other.provenance.id,
                                                           other.provenance.options)
    with pytest.raises(TypeError, match="unexpected keyword argument 'sigma_mm'"):
        cellcal.turntable(cell, t.to_table(), sigma_mm=0.1)


def test_the_tcp_procedure_refuses_a_tool():
    cell = Cell.load(CELL_FILE)
    t = simulate(cell, "tcp", noise=NOISE, seed=3, tool="torch")
    with pytest.raises(InputError, match="tool is not used by the tcp procedure"):
        cellcal.tcp(cell, t.to_table(), "torch", tool="pointer")


# -- a procedure registered here -------------------------------------------------------------------
def test_a_procedure_registered_in_a_test_is_simulated_and_calibrated(toy):
    cell = Cell.load(CELL_FILE)
    assert "toy-point" in SIMULATED and "toy-point" in SPECS
    touches = simulate(cell, "toy-point", noise=NOISE, seed=7, tool="pointer")
    header, rows = touches.columns()
    assert header == ["a1", "a2", "a3", "a4", "a5", "a6"] and len(rows) == 5
    out = cellcal.procedure("toy-point").calibrate(cell, touches.to_table(), tool="pointer",
                                                    sigma=NOISE)
    err = np.linalg.norm(out.result.values["point"] - POINT_R)
    assert err < 4 * NOISE
    # its results are known to the reader of results, as the built-in ones
    assert malformed(out.result.to_json()) is None


def test_a_procedure_registered_in_a_test_runs_on_the_command_line(toy, tmp_path, capsys):
    cell = tmp_path / "cell.yaml"
    shutil.copy(CELL_FILE, cell)
    touches = tmp_path / "toy.csv"
    code, _, err = run(capsys, "simulate", "toy-point", "--cell", cell, "--tool", "pointer",
                       "--seed", 5, "-o", touches)
    assert code == 0, err
    assert f"robotcell calibrate toy-point {touches} --cell" in err
    code, out, err = run(capsys, "calibrate", "toy-point", touches, "--cell", cell,
                         "--tool", "pointer", "--sigma", 0.1, "--json")
    assert code == 0, err
    result = json.loads(out)
    assert result["procedure"] == "toy-point"
    assert result["verdict"]["level"] == "good"
    code, out, _ = run(capsys, "calibrate", "--help")
    assert "toy-point" in out and "A fixed point in the robot base" in out


def test_a_procedure_is_registered_once():
    with pytest.raises(InputError, match="a procedure named 'tcp' is registered already"):
        cellcal.register(cellcal.procedure("tcp"))
    taken = TableSpec("toy-frame", "tcp", results=("frame-3point",))
    with pytest.raises(InputError, match="results named frame-3point are written by another"):
        cellcal.register(cellcal.Procedure("toy-frame", "x", taken, toy_calibrate))
    assert "toy-frame" not in cellcal.PROCEDURES and "toy-frame" not in SPECS
    with pytest.raises(InputError, match="procedure 'toy' has the table of 'toy-point'"):
        cellcal.register(cellcal.Procedure("toy", "x", SPEC, toy_calibrate))


def test_a_registered_command_that_cannot_be_imported_fails_loudly(monkeypatch, capsys):
    monkeypatch.setitem(cli_calibrate.REGISTERED, "ghost", "robotcell.cli.no_such_module:ghost")
    code, _, err = run(capsys, "calibrate", "ghost", "touches.csv")
    assert code == 1
    assert ("the command registered as 'robotcell.cli.no_such_module:ghost' cannot be loaded"
            in err)
    code, _, err = run(capsys, "calibrate", "--help")
    assert code == 1 and "robotcell.cli.no_such_module" in err
