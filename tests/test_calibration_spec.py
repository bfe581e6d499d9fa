"""One specification per procedure: the columns a procedure's table has are read, known and
written from :mod:`robotcell.calibration.spec` alone."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.calibration import spec
from robotcell.calibration.measurements import read_touch_table
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.studies.simulate import simulate

EXAMPLE = Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml"


@pytest.fixture(scope="module")
def touches():
    """Touches of the turntable in a cell whose robot stands on a track."""
    cell = Cell.load(EXAMPLE)
    return simulate(cell, "turntable", noise=1e-4, seed=4, tool=next(iter(cell.tools)))


def _without_track(monkeypatch):
    """The turntable procedure as it was before its column 'track' was added."""
    old = spec.SPECS["turntable"]
    monkeypatch.setitem(spec._SPECS, "turntable",
                        replace(old, columns=tuple(c for c in old.columns if c.name != "track")))


def test_a_column_added_to_a_spec_is_written_read_and_known(touches, monkeypatch, tmp_path,
                                                            capsys):
    robot = Cell.load(EXAMPLE).robot
    # With the column in the spec: simulate writes it, the reader reads it, nothing unknown.
    assert touches.columns()[0][-2:] == ["e1", "track"]
    table = touches.to_table()
    notes = []
    m = read_touch_table("turntable", table, "t.csv", robot, on_note=notes.append)
    np.testing.assert_allclose(m.track, touches.track, atol=1e-6)
    assert notes == []
    csv = tmp_path / "t.csv"
    touches.write_csv(csv)
    cell = tmp_path / "cell.yaml"
    Cell.load(EXAMPLE).save(cell)
    args = ("calibrate", "turntable", csv, "--cell", cell, "--tool", touches.tool)
    code, _, err = run(capsys, *args)
    assert code == 0 and "not used" not in err
    # The same procedure without it: not written, not read, named as unknown when given.
    _without_track(monkeypatch)
    assert "track" not in touches.columns()[0]
    m = read_touch_table("turntable", table, "t.csv", robot, on_note=notes.append)
    assert m.track is None
    assert notes == [("warning: t.csv: column(s) 'track' not used by the turntable calibration "
                      "and ignored; check the spelling")]
    code, _, err = run(capsys, *args)
    assert "warning: " + str(csv) + ": column(s) 'track' not used by this command" in err


def test_the_minimum_is_the_specs(monkeypatch, touches):
    """simulate and the estimators' count come from the spec, not from copies of it."""
    monkeypatch.setitem(spec._SPECS, "turntable",
                        replace(spec.SPECS["turntable"], minimum=7))
    cell = Cell.load(EXAMPLE)
    with pytest.raises(InputError, match="needs at least 7 table angles"):
        simulate(cell, "turntable", touches=6, tool=next(iter(cell.tools)))
    m = read_touch_table("turntable", touches.to_table(), "t.csv", cell.robot)
    with pytest.raises(InputError, match=r"t.csv: touches: 6 given, at least 7 needed"):
        m.check_count()
    with pytest.raises(InputError, match=r"touches: 6 given, at least 7 needed at different"):
        calibrate_turntable(m.axes[:, 0], m.tcp(cell.tools[touches.tool].T_F_TCP))
